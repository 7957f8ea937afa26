//! What a light sample costs when the light is shaped (docs/perf.md, "Shaped and IES lights"):
//! `SAMPLES` samples of a point light and of a rectangle from random shading points, unshaped,
//! with a ShapingAPI cone and focus, and with an IES profile (rotationally symmetric, and a full
//! 0°–360° table of 37 × 73 angles, the size of a common measured file). Run each variant under
//! `valgrind --tool=callgrind` at two sample counts; the difference of the instruction totals
//! over the difference of the counts is the instructions per sample, setup excluded.
//!
//! `cargo run --release -p sampler-core --example shaping_cost -- VARIANT [SAMPLES]` with VARIANT
//! one of `none`, `cone`, `ies-round`, `ies-full`.
use glam::{Vec2, Vec3};
use sampler_core::light::{IntensityProfile, Light, PointLight, RectLight, Shaping};
use sampler_core::rng::Pcg32;

fn leak(v: Vec<f32>) -> &'static [f32] {
    Box::leak(v.into_boxed_slice())
}

/// A table of `nv` vertical angles over 0°–180° and `nh` horizontal ones over 0°–360° (one:
/// rotationally symmetric), a smooth lobe that varies with both.
fn profile(nv: usize, nh: usize) -> &'static IntensityProfile<'static> {
    let v: Vec<f32> = (0..nv).map(|k| std::f32::consts::PI * k as f32 / (nv - 1) as f32).collect();
    let h: Vec<f32> =
        if nh == 1 { vec![0.0] } else { (0..nh).map(|j| std::f32::consts::TAU * j as f32 / (nh - 1) as f32).collect() };
    let c: Vec<f32> = h
        .iter()
        .flat_map(|&p| v.iter().map(move |&t| 100.0 * t.cos().max(0.0).powi(3) * (1.2 + 0.2 * p.cos())))
        .collect();
    Box::leak(Box::new(IntensityProfile::new(leak(v), leak(h), leak(c)).unwrap()))
}

fn main() {
    let mut args = std::env::args().skip(1);
    let variant = args.next().unwrap_or_else(|| "none".into());
    let samples: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(1 << 20);
    let base = Shaping::new(Vec3::NEG_Z, std::f32::consts::PI, 0.0, 0.0, Vec3::ONE).unwrap();
    let shaping = match variant.as_str() {
        "none" => Shaping::NONE,
        "cone" => Shaping::new(Vec3::NEG_Z, 1.0, 0.3, 2.0, Vec3::splat(0.1)).unwrap(),
        "ies-round" => base.with_profile(profile(181, 1), Vec3::X, Vec3::Y, 0.0, true).unwrap(),
        "ies-full" => base.with_profile(profile(37, 73), Vec3::X, Vec3::Y, 0.0, true).unwrap(),
        other => panic!("unknown variant {other}"),
    };
    let point = PointLight::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ONE).unwrap().with_shaping(shaping);
    let rect = RectLight::new(Vec3::new(-1.0, -1.0, 3.0), Vec3::Y * 2.0, Vec3::X * 2.0, Vec3::ONE)
        .unwrap()
        .with_shaping(shaping);
    let mut rng = Pcg32::new(3, 1);
    let mut sink = 0.0f32;
    for _ in 0..samples {
        let p = Vec3::new(8.0 * rng.next_f32() - 4.0, 8.0 * rng.next_f32() - 4.0, 0.0);
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        sink += point.sample(p, u).map_or(0.0, |s| s.radiance.x);
        sink += rect.sample(p, u).map_or(0.0, |s| s.radiance.x / s.pdf);
    }
    println!("{variant}: {samples} samples, sum {sink}");
}
