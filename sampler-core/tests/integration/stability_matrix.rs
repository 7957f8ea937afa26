//! The stability matrix: every estimator × extreme lighting × extreme material ×
//! extreme geometry. Each case asserts no NaN/Inf (exactly 0 under a black sky and for a
//! back-facing view) and compares the mean with a reference — quadrature of the sky plus the
//! sun's excess integrated over its texel — in standard errors, writing the whole table (mean,
//! reference, z, variance, time) to `stability_matrix.md` in the target directory's `tmp/`
//! (`CARGO_TARGET_TMPDIR`, under `CARGO_TARGET_DIR` when that is set).
//!
//! * Estimators that cover both a needle lobe and a one-texel sun (product, wavelet, mis,
//!   product-mis, ris): with ~1000 cases at 3σ, a few exceed 3σ by chance, so the test asserts
//!   the rate of 3σ exceedances stays at chance level (≤ 1%) and none exceeds 5σ.
//! * Single techniques (env-only, BRDF-only, product built from K = 1 BRDF sample — a constant
//!   B̃, i.e. env sampling — and two-stage): a needle lobe under env sampling, or a one-texel
//!   sun under BRDF sampling, is hit with probability ~1e-5; in 4096 draws the rare event is
//!   usually never seen and the sample SE means nothing (z can be in the thousands, in either
//!   direction, for an estimator that merely missed it). They are asserted one-sided — a missed rare event makes the mean
//!   low, never high: mean ≤ reference + 3 SE — and their z is recorded.

use crate::common::*;
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::{EnvHierarchy, luminance};
use sampler_core::estimator::{self, ShadingPoint, luminance64};
use sampler_core::frame::Frame;
use sampler_core::points::sobol02;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::two_stage::{TwoStageSampler, build_sat, sat_len};
use std::fmt::Write as _;
use std::time::Instant;

struct Light {
    name: &'static str,
    env: TestEnv,
    /// The sun texel (x, y) and its RGB excess over the sky, for the exact reference decomposition.
    sun: Option<((usize, usize), Vec3)>,
}

fn lights() -> Vec<Light> {
    let sky = |level: u32| {
        let n = 1usize << level;
        let mut rgb = vec![[0.0f32; 3]; n * n];
        for y in 0..n {
            for x in 0..n {
                let d = sampler_core::mapping::square_to_sphere(Vec2::new(
                    (x as f32 + 0.5) / n as f32,
                    (y as f32 + 0.5) / n as f32,
                ));
                let v = 0.3 + 0.5 * d.z.max(0.0) + 0.2 * d.x.abs();
                rgb[y * n + x] = [0.6 * v, 0.8 * v, v];
            }
        }
        rgb
    };
    let with_sun = |level: u32, texel: (usize, usize), radiance: f32| {
        let n = 1usize << level;
        let mut rgb = sky(level);
        let base = rgb[texel.1 * n + texel.0];
        rgb[texel.1 * n + texel.0] = [radiance; 3];
        (TestEnv::new(level, rgb), Some((texel, Vec3::splat(radiance) - Vec3::from_array(base))))
    };
    let (sun_env, sun) = with_sun(9, (300, 170), 1e6);
    let (pole_env, pole) = with_sun(9, (256, 256), 1e6);
    // Full resolution: a 1e7× one-texel sun in a 4096² map (the texel subtends 7.5e-7 sr).
    let (big_env, big) = with_sun(12, (2400, 1360), 1e7);
    vec![
        Light { name: "sun 1e6 (512²)", env: sun_env, sun },
        Light { name: "sun 1e7 (4096²)", env: big_env, sun: big },
        Light { name: "sun on +z pole", env: pole_env, sun: pole },
        Light { name: "constant", env: TestEnv::constant(4, 1.0), sun: None },
        Light { name: "2×2", env: TestEnv::new(1, vec![[4.0; 3], [0.5; 3], [0.0; 3], [1.0; 3]]), sun: None },
        Light { name: "black", env: TestEnv::constant(3, 0.0), sun: None },
        Light { name: "1e30", env: TestEnv::constant(3, 1e30), sun: None },
    ]
}

/// (name, BRDF, width of its sharpest lobe, whether that lobe is a microfacet lobe — integrated
/// over half vectors — or a lobe about the mirror direction)
fn materials() -> Vec<(&'static str, Box<dyn Brdf>, f64, bool)> {
    vec![
        ("lambert ρ=1", Box::new(Lambert::new(Vec3::ONE)), 1.0, false),
        ("lambert ρ=0", Box::new(Lambert::new(Vec3::ZERO)), 1.0, false),
        ("ggx α=1e-4", Box::new(RoughConductor::new(1e-4, Vec3::ONE)), 1e-4, true),
        ("ggx α=1e-3", Box::new(RoughConductor::new(1e-3, Vec3::ONE)), 1e-3, true),
        ("ggx α=1", Box::new(RoughConductor::new(1.0, Vec3::ONE)), 1.0, true),
        ("phong n=1", Box::new(Phong::new(Vec3::splat(0.3), Vec3::splat(0.6), 1.0)), 1.0, false),
        ("phong n=1e4", Box::new(Phong::new(Vec3::ZERO, Vec3::ONE, 1e4)), 0.02, false),
        ("phong n=1e6", Box::new(Phong::new(Vec3::ZERO, Vec3::ONE, 1e6)), 2e-3, false),
        ("carpaint", Box::new(CarPaint::default()), 0.005, true),
    ]
}

/// (label, normal, local view)
fn geometries() -> Vec<(&'static str, Vec3, Vec3)> {
    let tilt = |c: f32| Vec3::new((1.0 - c * c).max(0.0).sqrt(), 0.0, c);
    vec![
        ("n=+Z, n·v=0.7", Vec3::Z, tilt(0.7)),
        ("n=−X, n·v=1e-3", Vec3::NEG_X, tilt(1e-3)),
        ("n=+Y, n·v=1e-6", Vec3::Y, tilt(1e-6)),
        ("back-facing", Vec3::new(0.2, 0.3, 0.9).normalize(), Vec3::new(0.3, 0.0, -0.95).normalize()),
    ]
}

const METHODS: [&str; 9] =
    ["product", "wavelet", "env", "brdf", "mis", "product-mis", "ris", "two-stage", "product K=1"];

/// The methods whose mean is tested two-sided (see the module docs).
fn covers_both(method: &str) -> bool {
    matches!(method, "product" | "wavelet" | "mis" | "product-mis" | "ris")
}

/// ∫ L·B·cos: sky by quadrature, plus the sun's excess integrated over its own texel.
fn reference(
    env: &EnvHierarchy<'_>,
    light: &Light,
    sp: &ShadingPoint<'_, dyn Brdf>,
    width: f64,
    microfacet: bool,
) -> (f64, f64) {
    let wo_l = sp.frame.to_local(sp.wo);
    if wo_l.z <= 0.0 || env.is_black() {
        return (0.0, 0.0);
    }
    let axis = sp.frame.to_world(Vec3::new(-wo_l.x, -wo_l.y, wo_l.z));
    let n = env.resolution() as usize;
    // The sky alone is L with the sun's excess removed from its texel: piecewise constant and
    // smooth enough for the lobe quadrature; the excess is integrated over its texel below.
    let f = |d: Vec3| {
        let (x, y) = env.texel_at(env.square_of(d));
        let mut l = env.radiance(d);
        if let Some(((sx, sy), excess)) = light.sun
            && (x as usize, y as usize) == (sx, sy)
        {
            l -= excess;
        }
        luminance(l * sp.eval(d)) as f64
    };
    // Microfacet lobes (GGX, car paint) over half vectors, where they stay isotropic at grazing
    // views; Lambert and Phong lobes about the mirror direction.
    let q = |m| {
        if microfacet {
            integrate_half_vector(sp.frame.n, sp.wo, width, m, f)
        } else {
            integrate_lobe(axis, width, m, f)
        }
    };
    let (coarse, fine) = (q(600), q(1200));
    let mut value = fine;
    let mut error = (fine - coarse).abs();
    if let Some(((sx, sy), excess)) = light.sun {
        // ∫ over the sun texel of B, on a 256² grid of the texel (equal-area: dω = 4π/N² per texel).
        let m = 256;
        let mut acc = Vec3::ZERO.as_dvec3();
        for j in 0..m {
            for i in 0..m {
                let uv = Vec2::new(
                    (sx as f32 + (i as f32 + 0.5) / m as f32) / n as f32,
                    (sy as f32 + (j as f32 + 0.5) / m as f32) / n as f32,
                );
                acc += sp.eval(env.dir_of(uv)).as_dvec3();
            }
        }
        let integral = acc * (4.0 * std::f64::consts::PI / (n * n * m * m) as f64);
        let sun_part = luminance((excess.as_dvec3() * integral).as_vec3()) as f64;
        value += sun_part;
        error += 1e-3 * sun_part.abs();
    }
    (value, error)
}

/// One shading point of the matrix, as every method draws from it.
struct Point<'p, 'e> {
    env: &'p EnvHierarchy<'e>,
    sat: &'p [f64],
    sp: &'p ShadingPoint<'p, dyn Brdf>,
    /// The lighting's scale, divided out of every value.
    scale: f64,
}

/// One build's 32 values of `method` at `at`, from the points of `seed`, pushed onto `values`.
fn draw(method: &str, arena: &mut ProductArena, at: &Point<'_, '_>, seed: u64, values: &mut Vec<f64>) {
    let (env, sp) = (at.env, at.sp);
    let (brdf, frame, wo) = (sp.brdf, sp.frame, sp.wo);
    let mut vis = |_: Vec3| true;
    let mut pts = [DVec2::ZERO; 32];
    sobol02(seed, 0, &mut pts);
    let mut qts = [DVec2::ZERO; 32];
    sobol02(seed ^ 1, 0, &mut qts);
    let lum = |v: glam::DVec3| luminance64(v) / at.scale;
    let mut push = |v: f64| values.push(v);
    match method {
        "product" | "wavelet" | "product-mis" | "product K=1" => {
            let kind = if method == "wavelet" {
                sampler_core::quadtree::ProductKind::WAVELET
            } else {
                sampler_core::quadtree::ProductKind::QUADTREE
            };
            let brdf_samples = if method == "product K=1" { 1 } else { 256 };
            // product-MIS with the preset the renderer uses beside BRDF sampling.
            let params = if method == "product-mis" {
                ProductParams::for_mis(256)
            } else {
                ProductParams { kind, brdf_samples, ..ProductParams::default() }
            };
            let s = arena.build(env, brdf, &frame, wo, &params, seed).unwrap();
            for i in 0..32 {
                push(if method == "product-mis" {
                    let [a, c] = estimator::sampled_mis(&s, sp, pts[i], qts[i].as_vec2(), &mut vis);
                    lum(a.value + c.value)
                } else {
                    lum(estimator::sampled(&s, sp, pts[i], &mut vis).value)
                });
            }
        }
        "two-stage" => {
            let s: TwoStageSampler<'_, '_> = TwoStageSampler::new(env, at.sat, brdf, &frame, wo);
            for p in pts {
                push(lum(estimator::sampled(&s, sp, p, &mut vis).value));
            }
        }
        "ris" => {
            for (i, q) in qts.iter().enumerate() {
                let mut cands = [DVec2::ZERO; 8];
                sobol02(seed ^ (i as u64 + 7), 0, &mut cands);
                push(lum(estimator::ris(env, sp, &cands, q.x, &mut vis).value));
            }
        }
        _ => {
            for i in 0..32 {
                push(match method {
                    "env" => lum(estimator::sampled(env, sp, pts[i], &mut vis).value),
                    "brdf" => lum(estimator::brdf(env, sp, pts[i], &mut vis).value),
                    _ => {
                        let [a, c] = estimator::sampled_mis(env, sp, pts[i], qts[i].as_vec2(), &mut vis);
                        lum(a.value + c.value)
                    }
                });
            }
        }
    }
}

/// The mean, its standard error and the per-sample variance of `builds` builds' values (32
/// each): per-build means are i.i.d. (points within a build are stratified).
fn statistics(values: &[f64], builds: u64) -> (f64, f64, f64) {
    let per_build: Vec<f64> = values.chunks(32).map(|c| c.iter().sum::<f64>() / c.len() as f64).collect();
    let mean = per_build.iter().sum::<f64>() / builds as f64;
    let var_b = per_build.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (builds - 1) as f64;
    let se = (var_b / builds as f64).sqrt();
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (values.len() - 1) as f64;
    (mean, se, var)
}

/// How many standard errors `se` the mean lies from the reference beyond its tolerance
/// (infinite when there is no spread and it lies outside).
fn z_score(mean: f64, se: f64, reference: f64, tolerance: f64) -> f64 {
    if se > 0.0 {
        ((mean - reference).abs() - tolerance).max(0.0) / se
    } else if (mean - reference).abs() <= tolerance + 1e-12 * reference.abs() {
        0.0
    } else {
        f64::INFINITY
    }
}

/// One method at one case: the method, the mean, its standard error, the variance per sample,
/// µs per sample and the case's label.
type MethodResult = (&'static str, f64, f64, f64, f64, String);

/// Every method of [`METHODS`] at one case (`index` seeds it), 256 builds each. A non-finite
/// value, or a nonzero one where no light can arrive (`dark`), is a problem.
fn every_method(
    arena: &mut ProductArena,
    at: &Point<'_, '_>,
    index: usize,
    case: &str,
    dark: bool,
    problems: &mut Vec<String>,
) -> Vec<MethodResult> {
    let mut results = Vec::new();
    for (k, method) in METHODS.iter().enumerate() {
        let mut rng = Pcg32::new(99, (index * 8 + k) as u64);
        let t0 = Instant::now();
        let mut values: Vec<f64> = Vec::with_capacity(4096);
        let builds = 256u64;
        for _ in 0..builds {
            let seed = rng.next_u32() as u64;
            draw(method, arena, at, seed, &mut values);
        }
        let micros = t0.elapsed().as_secs_f64() * 1e6 / values.len() as f64;
        let label = format!("{case} / {method}");
        if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
            problems.push(format!("{label}: non-finite value {bad}"));
            continue;
        }
        let (mean, se, var) = statistics(&values, builds);
        if dark && values.iter().any(|v| *v != 0.0) {
            problems.push(format!("{label}: not exactly 0"));
        }
        results.push((*method, mean, se, var, micros, label));
    }
    results
}

#[test]
fn every_estimator_on_every_extreme_case() {
    let mut table = String::from(
        "| lighting | material | geometry | method | mean | reference | z | variance | µs/sample |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let (mut cases, mut over3, mut worst) = (0usize, 0usize, (0.0f64, String::new()));
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut problems = Vec::new();
    for light in lights() {
        let env = light.env.view();
        let mut sat = vec![0.0f64; sat_len(env.finest_level())];
        build_sat(&env, &mut sat);
        for (mname, brdf, width, microfacet) in materials() {
            for (gname, normal, wo_local) in geometries() {
                let frame = Frame::from_normal(normal);
                let wo = frame.to_world(wo_local);
                let sp: ShadingPoint<'_, dyn Brdf> = ShadingPoint { frame, wo, brdf: brdf.as_ref() };
                let (reference, quad_err) = reference(&env, &light, &sp, width, microfacet);
                let scale = if light.name == "1e30" { 1e30 } else { 1.0 };
                let at = Point { env: &env, sat: &sat, sp: &sp, scale };
                let case = format!("{} / {mname} / {gname}", light.name);
                let dark = light.name == "black" || gname == "back-facing";
                let results = every_method(&mut arena, &at, cases, &case, dark, &mut problems);
                // The reference: quadrature — except for needle microfacet lobes at grazing views,
                // where f32 evaluation dividing by 4 cos θo ≈ 4e-6 breaks the quadrature (it gave a
                // directional albedo of 2.1 under a constant sky). There MIS is the reference: its
                // env half reaches the lobe's far tail, its BRDF half the lobe, and the balance
                // heuristic bounds its weights. (BRDF sampling alone is not: where the lobe sees a
                // black texel and its tail a bright one it returns 0 against 7e-5 from all others.)
                let grazing_needle = microfacet && width <= 1e-3 && wo_local.z <= 1e-3 && wo_local.z > 0.0;
                let (ref_mean, ref_se, tol_ref) = if grazing_needle {
                    let b = results.iter().find(|r| r.0 == "mis").expect("mis result");
                    (b.1, b.2, 0.0)
                } else {
                    (reference / scale, 0.0, 3.0 * quad_err / scale + 1e-4 * (reference / scale).abs())
                };
                for (method, mean, se, var, micros, label) in results {
                    let se_all = (se * se + ref_se * ref_se).sqrt();
                    let z = z_score(mean, se_all, ref_mean, tol_ref);
                    if covers_both(method) && !(grazing_needle && method == "mis") {
                        cases += 1;
                        over3 += usize::from(z > 3.0);
                        if z > worst.0 {
                            worst = (z, label.clone());
                        }
                    } else if mean > ref_mean + tol_ref + 3.0 * se_all + 1e-12 {
                        problems.push(format!(
                            "{label}: mean {mean:e} above the reference {ref_mean:e} by more than 3 SE ({se_all:e})"
                        ));
                    }
                    let reference = ref_mean;
                    let _ = writeln!(
                        table,
                        "| {} | {mname} | {gname} | {method} | {mean:.5e} | {reference:.5e} | {z:.2} | {var:.3e} | {micros:.3} |",
                        light.name
                    );
                }
            }
        }
    }
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("stability_matrix.md");
    let _ = std::fs::write(&path, &table);
    println!("{cases} cases, {over3} beyond 3σ, worst z = {:.2} ({}); table in {}", worst.0, worst.1, path.display());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(over3 as f64 <= 0.01 * cases as f64, "{over3} of {cases} cases beyond 3σ (chance level: ~0.3%)");
    assert!(worst.0 <= 5.0, "worst case z = {:.2}: {}", worst.0, worst.1);
}
