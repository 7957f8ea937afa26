//! Pins the rendered images: a 64-bit hash of every pixel's f32 bits and of the render's
//! counters, per method on the default scene (every method of `Method::ALL`), for the JSON-scene path, and for `auto` with its
//! pilot, all at a fixed seed on 2 threads. A restructuring must leave every hash as it is.
//!
//! A change that is *meant* to alter images (a new estimator, another seed derivation…) fails
//! here; then run
//!
//! ```text
//! cargo test --release -p host-std --test integration image_hashes -- --nocapture
//! ```
//!
//! and replace [`EXPECTED`] with the table the failure prints, saying in the commit why the
//! images changed.

use crate::common;
use host_std::light::environment::Environment;
use host_std::plan::Method;
use host_std::plan::{Rendered, Settings, render};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::builtin;
use host_std::scene::{Bsdf, Scene};
use host_std::trace::bvh::Bvh;
use sampler_core::brdf::Lambert;
use sampler_core::glam::Vec3;

/// (case, hash of the pixels and counters).
const EXPECTED: &[(&str, u64)] = &[
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
    Settings {
        method,
        spp,
        shading_points,
        brdf_samples: BrdfSamples::PerLobe,
        seed: 11,
        progress: false,
        shadows: true,
        lights: Default::default(),
    }
}

fn rendered(scene: &Scene, env: &Environment, s: &Settings) -> Rendered {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let bvh = pool.install(|| Bvh::build(scene));
    let h = env.hierarchy();
    pool.install(|| render(scene, &bvh, Some(&h), s))
}

fn cases() -> Vec<(String, u64)> {
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
    // `auto` with its pilot: one matte sphere filling a 96×96 view under the sky.
    let sphere = common::pilot_sphere(Bsdf::Diffuse(Lambert::new(Vec3::splat(0.5))));
    let image = rendered(&sphere, &sky, &settings(Method::Auto, 16, 1));
    assert_eq!(image.pilot.len(), 1, "the pilot ran");
    out.push(("sphere/auto with pilot".into(), hash(&image)));
    out
}

#[test]
fn images_are_bit_identical_to_the_recorded_hashes() {
    let actual = cases();
    let table: String = actual.iter().map(|(case, h)| format!("    (\"{case}\", 0x{h:016x}),\n")).collect();
    let expected: Vec<(String, u64)> = EXPECTED.iter().map(|&(c, h)| (c.to_string(), h)).collect();
    assert!(
        actual == expected,
        "the rendered images differ from the recorded ones. If that is meant (the commit says \
         why), replace EXPECTED in host-std/tests/integration/image_hashes.rs with:\n\
         const EXPECTED: &[(&str, u64)] = &[\n{table}];"
    );
}
