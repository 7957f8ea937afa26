//! The benchmark's workloads: the repository's scenes (docs/scenes/, spheres over a ground
//! rectangle), a displaced sphere of over 100k triangles built here, and realistic rays for
//! each — camera rays through every pixel of a 256×256 view and shadow rays from their hits in
//! cosine-distributed directions about the normal, started where the renderer starts them.

use host_std::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use host_std::trace::bvh::Bvh;
use host_std::trace::camera::Camera;
use sampler_core::brdf::Lambert;
use sampler_core::glam::Vec3;
use std::f32::consts::PI;
use std::path::Path;

/// Shadow rays per camera-ray hit.
pub const SHADOWS_PER_HIT: usize = 4;

/// A ray as origin, unit direction and the interval it is tested over.
#[derive(Clone, Copy)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
    pub t_min: f32,
}

/// One workload: a scene, its hierarchy and its rays.
pub struct Case {
    pub name: String,
    pub bvh: Bvh,
    pub camera: Vec<Ray>,
    pub shadow: Vec<Ray>,
}

impl Case {
    fn new(name: &str, mut scene: Scene) -> Case {
        scene.camera.width = 256;
        scene.camera.height = 256;
        let bvh = Bvh::build(&scene);
        let camera = camera_rays(&scene.camera);
        let shadow = shadow_rays(&bvh, &camera);
        Case { name: name.into(), bvh, camera, shadow }
    }
}

/// The scenes of docs/scenes/ that the comparison with Mitsuba uses, and the mesh.
pub fn cases() -> Vec<Case> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes");
    let mut out: Vec<Case> = ["studio", "s1_forest_spheres", "s2_courtyard_glossy", "s3_sunset_sharp"]
        .iter()
        .map(|name| {
            let scene = host_std::scene::json::load(&dir.join(format!("{name}.json"))).expect("scene in docs/scenes");
            Case::new(name, scene)
        })
        .collect();
    out.push(Case::new("mesh100k", displaced_sphere_scene(225, 224)));
    out
}

/// A sphere of radius ~1 on a lat-long grid of `rings` × `segments` quads, its radius displaced
/// by a few octaves of waves, standing on a ground rectangle and seen like the studio scene.
pub fn displaced_sphere_scene(rings: u32, segments: u32) -> Scene {
    let radius = |theta: f32, phi: f32| {
        1.0 + 0.08 * (7.0 * theta).sin() * (9.0 * phi).sin()
            + 0.03 * (23.0 * theta).sin() * (19.0 * phi).cos()
            + 0.01 * (61.0 * theta + 47.0 * phi).sin()
    };
    let center = Vec3::new(0.0, 1.1, 0.0);
    let mut positions = Vec::new();
    for i in 0..=rings {
        let theta = PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = 2.0 * PI * j as f32 / segments as f32;
            let dir = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            positions.push(center + dir * radius(theta, phi % (2.0 * PI)));
        }
    }
    let at = |i: u32, j: u32| i * (segments + 1) + j;
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    let mesh = Shape::Mesh {
        positions: positions.into(),
        triangles: triangles.into(),
        normals: Box::new([]),
        uvs: Box::new([]),
    };
    let ground = Shape::Rectangle {
        p0: Vec3::new(-20.0, 0.0, -20.0),
        e1: Vec3::new(0.0, 0.0, 40.0),
        e2: Vec3::new(40.0, 0.0, 0.0),
    };
    let material = Material::new(Bsdf::Diffuse(Lambert::new(Vec3::splat(0.5))), false);
    let camera = CameraSpec {
        origin: Vec3::new(0.0, 1.6, 5.0),
        target: Vec3::new(0.0, 0.9, 0.0),
        up: Vec3::Y,
        fov_y_deg: 35.0,
        width: 256,
        height: 256,
        ..host_std::scene::builtin::scene().camera
    };
    Scene {
        name: "mesh100k".into(),
        camera,
        objects: vec![Object { shape: mesh, material: 0 }, Object { shape: ground, material: 0 }],
        materials: vec![material],
        ..host_std::scene::builtin::scene()
    }
}

/// A ray through every pixel centre.
fn camera_rays(spec: &CameraSpec) -> Vec<Ray> {
    let camera = Camera::new(spec);
    let mut out = Vec::with_capacity((camera.width * camera.height) as usize);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let d = camera.direction(x as f32 + 0.5, y as f32 + 0.5);
            out.push(Ray { o: camera.origin, d, t_min: camera.near_clip });
        }
    }
    out
}

/// `SHADOWS_PER_HIT` cosine-distributed directions about the normal (on the viewer's side) at
/// each camera ray's hit, from the hit offset along that normal as the renderer does.
fn shadow_rays(bvh: &Bvh, camera: &[Ray]) -> Vec<Ray> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        // splitmix64: a fixed, reproducible stream.
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut out = Vec::new();
    for ray in camera {
        let Some(hit) = bvh.intersect(ray.o, ray.d, ray.t_min, f32::INFINITY) else { continue };
        let n = if hit.normal.dot(ray.d) > 0.0 { -hit.normal } else { hit.normal };
        let origin = hit.point + n * (1e-4 * (1.0 + hit.point.abs().max_element()));
        let (t, b) = n.any_orthonormal_pair();
        for _ in 0..SHADOWS_PER_HIT {
            let (u1, u2) = (next(), next());
            let (r, phi) = (u1.sqrt(), 2.0 * PI * u2);
            let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
            let d = (t * local.x + b * local.y + n * local.z).normalize();
            out.push(Ray { o: origin, d, t_min: 0.0 });
        }
    }
    out
}
