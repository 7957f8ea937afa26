//! Scenes shared by the integration tests.

use host_std::plan::{Method, Settings};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use sampler_core::glam::Vec3;

/// One sphere of `bsdf` filling a 96×96 view (about the smallest image whose `auto` pilot fits
/// its share of a one-material render), with no environment of its own.
pub fn pilot_sphere(bsdf: Bsdf) -> Scene {
    Scene {
        name: "pilot".into(),
        camera: CameraSpec {
            origin: Vec3::new(0.0, 0.0, 4.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 10.0,
            width: 96,
            height: 96,
            pixel_aspect: 1.0,
            near_clip: 1e-3,
        },
        objects: vec![Object { shape: Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, material: 0 }],
        materials: vec![Material::new(bsdf, false)],
        env: None,
        lights: Vec::new(),
        hide_emitters: true,
    }
}

/// Render settings of `method` at `spp` samples and `shading_points` per pixel, seeded by
/// `seed`: each material's per-lobe K, shadows on, no progress bar.
pub fn settings(method: Method, spp: usize, shading_points: usize, seed: u64) -> Settings {
    Settings {
        method,
        spp,
        shading_points,
        brdf_samples: BrdfSamples::PerLobe,
        seed,
        progress: false,
        shadows: true,
        lights: Default::default(),
    }
}
