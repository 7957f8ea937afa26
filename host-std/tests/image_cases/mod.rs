//! The pinned images: a 64-bit hash of every pixel's f32 bits and of the render's counters, per
//! method on the default scene (every method of `Method::ALL`), for the JSON-scene path, for a
//! mesh that makes the hierarchy a tree, and for `auto` with its pilot, all at a fixed seed on 2
//! threads. `integration/image_hashes.rs` checks them as the build runs them, `portable_paths.rs`
//! with the portable paths in place of the AVX2 ones: a restructuring must leave every hash as
//! it is, on both.
//!
//! A change that is *meant* to alter images (a new estimator, another seed derivation…) fails
//! there; then run
//!
//! ```text
//! cargo test --release -p host-std --test integration image_hashes -- --nocapture
//! ```
//!
//! and replace [`EXPECTED`] with the table the failure prints, saying in the commit why the
//! images changed.

use super::common;
use host_std::light::environment::Environment;
use host_std::plan::Method;
use host_std::plan::{Rendered, Settings, render};
use host_std::scene::builtin;
use host_std::scene::{Bsdf, Object, Scene, Shape};
use host_std::trace::bvh::Bvh;
use sampler_core::brdf::Lambert;
use sampler_core::glam::Vec3;

/// (case, hash of the pixels and counters).
pub const EXPECTED: &[(&str, u64)] = &[
    ("default/product", 0xbad0af4f0cb678bb),
    ("default/wavelet", 0x20d106cd11c0d586),
    ("default/env", 0x04c5c1670b871a1c),
    ("default/brdf", 0xa4a5ea5abfd493c1),
    ("default/mis", 0x6efd0a4f0655961e),
    ("default/product-mis", 0x5eaf575eb18d5388),
    ("default/ris", 0x917260c9705cb60b),
    ("default/two-stage", 0x0de22621b956bfb7),
    ("default/two-level", 0x3ca8f671241ecd42),
    ("default/two-level-mis", 0xd08d72c696013662),
    ("default/sis", 0xd5fd282a7d493f4b),
    ("default/lightcuts", 0xee84e2a10fe97911),
    ("default/plane-product", 0x81339015e8f2c3a2),
    ("default/auto", 0x6efd0a4f0655961e),
    ("default/product-mis unshadowed", 0x56a425e45970ef58),
    ("twins.json/product-mis", 0xed4c68c7e41705cd),
    ("twins.json/mis", 0x82b3f564e1a71984),
    ("twins.json/auto", 0x189226778194f1bd),
    ("torus/mis", 0x286c2f79a393f82d),
    ("torus/product-mis", 0xa76e6e3c71808c6b),
    ("torus/auto", 0x286c2f79a393f82d),
    ("sphere/auto with pilot", 0x9162f013cf9bf3d1),
];

/// FNV-1a over 64-bit words.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn word(&mut self, w: u64) {
        for b in w.to_le_bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

fn hash(image: &Rendered) -> u64 {
    let mut h = Fnv::new();
    h.word(image.width as u64);
    h.word(image.height as u64);
    for p in &image.pixels {
        for c in p {
            h.word(u64::from(c.to_bits()));
        }
    }
    for counter in [image.shading_points, image.shadow_rays, image.camera_rays, image.non_finite] {
        h.word(counter);
    }
    for r in &image.pilot {
        h.word(r.material as u64);
        h.word(r.pixels as u64);
        h.word(r.chosen as u64);
        h.word(r.rule.map_or(u64::MAX, |r| r as u64));
        for s in &r.scores {
            h.word(s.map_or(u64::MAX, f64::to_bits));
        }
    }
    h.0
}

fn settings(method: Method, spp: usize, shading_points: usize) -> Settings {
    common::settings(method, spp, shading_points, 11)
}

fn rendered(scene: &Scene, env: &Environment, s: &Settings) -> Rendered {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let bvh = pool.install(|| Bvh::build(scene));
    let h = env.hierarchy();
    pool.install(|| render(scene, &bvh, Some(&h), s))
}

/// Every case's hash, rendered now.
pub fn cases() -> Vec<(String, u64)> {
    let mut out = Vec::new();
    // Every method on the default scene, under its own sky.
    let mut scene = builtin::scene();
    scene.camera.width = 48;
    scene.camera.height = 32;
    let (source, placement) = scene.env.clone().unwrap();
    let sky = Environment::build(&source, placement).unwrap();
    for method in Method::ALL {
        out.push((format!("default/{method}"), hash(&rendered(&scene, &sky, &settings(method, 8, 2)))));
    }
    out.push((
        "default/product-mis unshadowed".into(),
        hash(&rendered(&scene, &sky, &Settings { shadows: false, ..settings(Method::ProductMis, 8, 2) })),
    ));
    // The JSON-scene path with a lat-long EXR map (host-usd's twins fixture, read only).
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures");
    let mut twins = host_std::scene::json::load(&dir.join("twins.json")).unwrap();
    twins.camera.width = 48;
    twins.camera.height = 32;
    let (source, placement) = twins.env.clone().unwrap();
    let map = Environment::build(&source, placement).unwrap();
    for name in ["product-mis", "mis", "auto"] {
        let method: Method = name.parse().unwrap();
        out.push((format!("twins.json/{name}"), hash(&rendered(&twins, &map, &settings(method, 8, 2)))));
    }
    // A torus of 2 304 triangles beside the default scene's shapes: a tree of inner nodes, whose
    // camera rays go in packets and whose shadow rays go node by node.
    let mut meshed = scene.clone();
    meshed.objects.push(Object { shape: torus(Vec3::new(0.3, 0.55, 0.8), 0.45, 0.16, 48, 24), material: 1 });
    for name in ["mis", "product-mis", "auto"] {
        let method: Method = name.parse().unwrap();
        out.push((format!("torus/{name}"), hash(&rendered(&meshed, &sky, &settings(method, 8, 2)))));
    }
    // `auto` with its pilot: one matte sphere filling a 96×96 view under the sky.
    let sphere = common::pilot_sphere(Bsdf::Diffuse(Lambert::new(Vec3::splat(0.5))));
    let image = rendered(&sphere, &sky, &settings(Method::Auto, 16, 1));
    assert_eq!(image.pilot.len(), 1, "the pilot ran");
    out.push(("sphere/auto with pilot".into(), hash(&image)));
    out
}

/// A torus about `center`, its ring of radius `ring` in a plane tilted about x, its tube of
/// radius `tube`; `around` × `across` quads, two triangles each.
fn torus(center: Vec3, ring: f32, tube: f32, around: u32, across: u32) -> Shape {
    let tilt = 0.6f32;
    let (s, c) = tilt.sin_cos();
    let mut positions = Vec::new();
    for i in 0..around {
        let a = i as f32 / around as f32 * std::f32::consts::TAU;
        for j in 0..across {
            let b = j as f32 / across as f32 * std::f32::consts::TAU;
            let r = ring + tube * b.cos();
            let p = Vec3::new(r * a.cos(), tube * b.sin(), r * a.sin());
            positions.push(center + Vec3::new(p.x, c * p.y - s * p.z, s * p.y + c * p.z));
        }
    }
    let at = |i: u32, j: u32| (i % around) * across + j % across;
    let mut triangles = Vec::new();
    for i in 0..around {
        for j in 0..across {
            let (p, q, r, t) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.push([p, r, q]);
            triangles.push([p, t, r]);
        }
    }
    Shape::Mesh { positions: positions.into(), triangles: triangles.into(), normals: Box::new([]), uvs: Box::new([]) }
}
