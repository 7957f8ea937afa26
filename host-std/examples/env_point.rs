//! The variance of env-only sampling at one point: the estimate of a plane's irradiance from
//! 256 of the map's env samples (Owen-scrambled (0,2) points, the renderer's sequence), over 200
//! scrambles, for each normal given; and the points themselves, so that another renderer's
//! sampler can be measured on the same ones (docs/env_point.py, docs/perf.md "What is left
//! against Mitsuba on studio").
//!
//! `cargo run --release -p host-std --example env_point -- MAP.exr POINTS.txt TILT,AZIMUTH...`
//! (degrees: the normal's angle from +y and its azimuth from +x towards +z). Prints one line per
//! normal: the estimate's mean and its relative variance, for the plain pyramid (env-only
//! sampling's) and the MIS-compensated one.
use host_std::light::environment::{EnvSource, Environment, Placement};
use sampler_core::env::EnvHierarchy;
use sampler_core::glam::{DVec2, Vec3};
use sampler_core::points::Sobol02;

const POINTS: usize = 256;
const SCRAMBLES: u64 = 200;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: env_point MAP.exr POINTS.txt TILT,AZIMUTH...");
        std::process::exit(2);
    }
    let env = Environment::build(&EnvSource::File(args[1].clone().into()), Placement::default())
        .unwrap_or_else(|e| panic!("{}: {e}", args[1]));
    let sets: Vec<Vec<DVec2>> = (0..SCRAMBLES)
        .map(|seed| {
            let mut u = vec![DVec2::ZERO; POINTS];
            Sobol02::new(seed).fill(0, &mut u);
            u
        })
        .collect();
    let text: String = sets.iter().flatten().map(|p| format!("{} {}\n", p.x, p.y)).collect();
    std::fs::write(&args[2], text).unwrap_or_else(|e| panic!("{}: {e}", args[2]));
    let plain = env.hierarchy();
    let mut above = vec![0.0f32; env.pyramid.len()];
    let compensated = match plain.compensate_into(&mut above).expect("the view's own pyramid") {
        true => plain.with_compensated(&above).expect("built from this view").compensated(),
        false => plain,
    };
    for normal in &args[3..] {
        let (tilt, azimuth) = normal.split_once(',').expect("TILT,AZIMUTH");
        let (t, a) = (tilt.parse::<f32>().unwrap().to_radians(), azimuth.parse::<f32>().unwrap().to_radians());
        let n = Vec3::new(t.sin() * a.cos(), t.cos(), t.sin() * a.sin());
        let (mean, plain_var) = relative_variance(&plain, &sets, n);
        let (_, compensated_var) = relative_variance(&compensated, &sets, n);
        println!(
            "normal {tilt},{azimuth}: mean {mean:.5} relvar plain {plain_var:.4e} compensated {compensated_var:.4e}"
        );
    }
}

/// The mean and relative variance over the point sets of the irradiance estimate at a plane of
/// normal `n` (RGB averaged).
fn relative_variance(env: &EnvHierarchy<'_>, sets: &[Vec<DVec2>], n: Vec3) -> (f64, f64) {
    let mut drawn = vec![None; POINTS];
    let estimates: Vec<f64> = sets
        .iter()
        .map(|u| {
            env.sample_many(u, &mut drawn);
            let value = |s: &sampler_core::direction::DirectionSample| {
                f64::from(env.radiance(s.dir).element_sum() / 3.0 * s.dir.dot(n).max(0.0) / s.pdf)
            };
            drawn.iter().flatten().map(value).sum::<f64>() / POINTS as f64
        })
        .collect();
    let mean = estimates.iter().sum::<f64>() / estimates.len() as f64;
    let var = estimates.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / estimates.len() as f64;
    (mean, var / (mean * mean))
}
