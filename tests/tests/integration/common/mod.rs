//! What the stability tests share: environment maps written as EXR files and loaded the way a
//! user's would be, and the suite's materials.

use glam::Vec3;
use host_std::light::environment::{EnvSource, Environment, Placement};
use host_std::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use sampler_core::brdf::{CarPaint, Lambert, Phong, RoughConductor};

/// Writes an equal-area `n`×`n` EXR whose texel (x, y) is `f(x, y)`, and builds it.
pub fn env_from(name: &str, n: usize, f: impl Fn(usize, usize) -> [f32; 3] + Sync) -> Environment {
    // Removed (with the file) when this returns: the environment is in memory by then.
    let dir = tempfile::Builder::new().prefix("ppis-stability-").tempdir().unwrap();
    let path = dir.path().join(format!("{name}.exr"));
    exr::prelude::write_rgb_file(&path, n, n, |x, y| {
        let c = f(x, y);
        (c[0], c[1], c[2])
    })
    .unwrap();
    Environment::build(&EnvSource::File(path), Placement::default()).unwrap()
}

/// Every built-in BRDF at its extremes: albedo 0 and 1, GGX α = 1e-4…1, Phong n = 1…1e6, car paint.
pub fn materials() -> Vec<(&'static str, Bsdf)> {
    vec![
        ("lambert ρ=1", Bsdf::Diffuse(Lambert::new(Vec3::ONE))),
        ("lambert ρ=0", Bsdf::Diffuse(Lambert::new(Vec3::ZERO))),
        ("ggx α=1e-4", Bsdf::Conductor(RoughConductor::new(1e-4, Vec3::ONE))),
        ("ggx α=1e-3", Bsdf::Conductor(RoughConductor::new(1e-3, Vec3::ONE))),
        ("ggx α=1", Bsdf::Conductor(RoughConductor::new(1.0, Vec3::ONE))),
        ("phong n=1", Bsdf::Phong(Phong::new(Vec3::splat(0.3), Vec3::splat(0.6), 1.0))),
        ("phong n=1e4", Bsdf::Phong(Phong::new(Vec3::ZERO, Vec3::ONE, 1e4))),
        ("phong n=1e6", Bsdf::Phong(Phong::new(Vec3::ZERO, Vec3::ONE, 1e6))),
        ("carpaint", Bsdf::CarPaint(CarPaint::default())),
    ]
}

/// A unit sphere of `bsdf` alone, seen from `dir` (8×8 pixels, the sphere fills the frame).
pub fn sphere_scene(bsdf: Bsdf, dir: Vec3) -> Scene {
    let up = if dir.cross(Vec3::Y).length() < 1e-3 { Vec3::Z } else { Vec3::Y };
    Scene {
        name: "sphere".into(),
        camera: CameraSpec {
            origin: dir * 4.0,
            target: Vec3::ZERO,
            up,
            fov_y_deg: 10.0,
            width: 8,
            height: 8,
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
