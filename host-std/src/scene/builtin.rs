//! The embedded default scene (no files needed): spheres of the four built-in material kinds —
//! Lambert, glossy GGX, very sharp GGX, car paint — on a grey ground plane under the built-in
//! sky with its sun.

use crate::light::environment::{EnvSource, Placement};
use crate::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use sampler_core::brdf::{CarPaint, Lambert, RoughConductor};
use sampler_core::glam::Vec3;

/// Equal-area resolution of the built-in sky: 1024² keeps the 0.53° sun at ~6 texels.
pub const SKY_LEVEL: u32 = 10;

/// The built-in scene.
pub fn scene() -> Scene {
    let material = |bsdf| Material::new(bsdf, false);
    let materials = vec![
        material(Bsdf::Diffuse(Lambert::new(Vec3::new(0.8, 0.45, 0.3)))),
        material(Bsdf::Conductor(RoughConductor::new(0.15, Vec3::new(0.95, 0.8, 0.55)))),
        material(Bsdf::Conductor(RoughConductor::new(0.01, Vec3::splat(0.95)))),
        material(Bsdf::CarPaint(CarPaint::default())),
        material(Bsdf::Diffuse(Lambert::new(Vec3::splat(0.45)))),
    ];
    let sphere =
        |x: f32, m: usize| Object { shape: Shape::Sphere { center: Vec3::new(x, 0.5, 0.0), radius: 0.5 }, material: m };
    let objects = vec![
        sphere(-1.8, 0),
        sphere(-0.6, 1),
        sphere(0.6, 2),
        sphere(1.8, 3),
        Object {
            shape: Shape::Rectangle {
                p0: Vec3::new(-500.0, 0.0, -500.0),
                e1: Vec3::new(0.0, 0.0, 1000.0),
                e2: Vec3::new(1000.0, 0.0, 0.0),
            },
            material: 4,
        },
    ];
    Scene {
        name: "default".into(),
        camera: CameraSpec {
            origin: Vec3::new(0.0, 1.6, 5.5),
            target: Vec3::new(0.0, 0.45, 0.0),
            up: Vec3::Y,
            fov_y_deg: 36.0,
            width: 640,
            height: 360,
            pixel_aspect: 1.0,
            near_clip: 1e-3,
        },
        objects,
        materials,
        env: Some((EnvSource::Sky { level: SKY_LEVEL }, Placement::default())),
        lights: Vec::new(),
        hide_emitters: false,
    }
}
