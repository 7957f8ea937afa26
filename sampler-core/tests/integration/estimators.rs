//! Every estimator's mean equals brute-force quadrature of ∫ L·B·cos·V dω within 3 standard
//! errors (plus the quadrature's own error estimate), at fixed shading points: sharp lobes (GGX
//! α = 1e-3, Phong n = 1e5, car paint), grazing views, an occluder, and an environment with a
//! bright texel. With 7 estimators × 12 cases, a 3σ excursion somewhere has a ~20% chance even
//! for unbiased estimators, so each estimator draws from its own stream: one stream shared by
//! all would tie their excursions together.

#[path = "estimators/units.rs"]
mod units;

use crate::common::*;
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::{EnvHierarchy, MisHeuristic, luminance};
use sampler_core::estimator::{self, ShadingPoint, luminance64};
use sampler_core::frame::Frame;
use sampler_core::points::sobol02;
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::two_level::TwoLevelArena;
use units::*;

struct Case {
    name: String,
    brdf: Box<dyn Brdf>,
    width: f64,
    frame: Frame,
    wo: Vec3,
}

type MakeBrdf = fn() -> Box<dyn Brdf>;

fn cases() -> Vec<Case> {
    let brdfs: Vec<(&str, MakeBrdf, f64)> = vec![
        ("lambert", || Box::new(Lambert::new(Vec3::new(0.8, 0.6, 0.4))), 1.0),
        ("phong n=1e5", || Box::new(Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 1e5)), 6e-3),
        ("ggx a=1", || Box::new(RoughConductor::new(1.0, Vec3::ONE)), 1.0),
        ("ggx a=0.1", || Box::new(RoughConductor::new(0.1, Vec3::ONE)), 0.2),
        ("ggx a=1e-3", || Box::new(RoughConductor::new(1e-3, Vec3::new(0.9, 0.7, 0.5))), 2e-3),
        ("carpaint", || Box::new(CarPaint::default()), 0.01),
    ];
    let mut out = Vec::new();
    for (name, make, width) in brdfs {
        for (view, normal, cos) in
            [("20°", Vec3::new(0.2, 0.9, 0.3), 0.94f32), ("grazing", Vec3::new(-0.6, 0.3, 0.7), 0.02)]
        {
            let frame = Frame::from_normal(normal.normalize());
            let wo = frame.to_world(Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos));
            out.push(Case { name: format!("{name} / {view}"), brdf: make(), width, frame, wo });
        }
    }
    out
}

fn environment() -> TestEnv {
    let mut env = TestEnv::random_smooth(5, 3);
    // A texel 100× the sky, so that lighting is far from uniform.
    let n = 32;
    env.rgb[7 * n + 20] = [60.0, 50.0, 40.0];
    TestEnv::new(5, env.rgb)
}

/// An occluder: everything below a tilted plane through the shading point is blocked.
fn visible(d: Vec3) -> bool {
    d.dot(Vec3::new(0.3, 1.0, 0.0).normalize()) > -0.2
}

/// Quadrature of ∫ L·B·cos·V and an estimate of its own error: the polar cells straddle texel
/// edges and the occluder, so it converges only to first order; |Q(2n) − Q(n)| bounds what is
/// left. Computed once per case and shared by the tests of this binary.
fn reference(env: &EnvHierarchy<'_>, index: usize, case: &Case) -> (f64, f64) {
    static CACHE: std::sync::OnceLock<std::sync::Mutex<std::collections::HashMap<usize, (f64, f64)>>> =
        std::sync::OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(r) = cache.lock().unwrap().get(&index) {
        return *r;
    }
    let sp = ShadingPoint { frame: case.frame, wo: case.wo, brdf: case.brdf.as_ref() };
    let wo_l = case.frame.to_local(case.wo);
    let axis = case.frame.to_world(Vec3::new(-wo_l.x, -wo_l.y, wo_l.z));
    let q = |n| {
        integrate_lobe(axis, case.width, n, |d| {
            if visible(d) { luminance(env.radiance(d) * sp.eval(d)) as f64 } else { 0.0 }
        })
    };
    let (coarse, fine) = (q(1200), q(2400));
    let r = (fine, (fine - coarse).abs());
    cache.lock().unwrap().insert(index, r);
    r
}

/// Running mean and variance (Welford), so that millions of draws need no storage.
#[derive(Default)]
struct Stats {
    n: f64,
    mean: f64,
    m2: f64,
}

impl Stats {
    fn push(&mut self, v: f64) {
        self.n += 1.0;
        let d = v - self.mean;
        self.mean += d / self.n;
        self.m2 += d * (v - self.mean);
    }

    fn standard_error(&self) -> f64 {
        (self.m2 / (self.n - 1.0) / self.n).sqrt()
    }
}

impl FromIterator<f64> for Stats {
    fn from_iter<I: IntoIterator<Item = f64>>(iter: I) -> Self {
        let mut s = Stats::default();
        iter.into_iter().for_each(|v| s.push(v));
        s
    }
}

fn check(label: &str, (reference, quadrature_error): (f64, f64), stats: &Stats, failures: &mut Vec<String>) {
    let (mean, se) = (stats.mean, stats.standard_error());
    assert!(mean.is_finite() && se.is_finite(), "{label}: non-finite estimate");
    let tol = 3.0 * se + quadrature_error + 1e-5 * reference.abs();
    if (mean - reference).abs() > tol {
        failures.push(format!(
            "{label}: mean {mean:.6e} vs quadrature {reference:.6e} (± {quadrature_error:.1e}), SE {se:.2e}"
        ));
    }
}

fn run(label: &str) {
    let env = environment();
    // The MIS estimators as the renderer runs them: env samples from the compensated density,
    // weighed by the balance heuristic or, with ", power", the power heuristic.
    let (label_h, heuristic) = match label.strip_suffix(", power") {
        Some(rest) => (rest, MisHeuristic::Power),
        None => (label, MisHeuristic::Balance),
    };
    let (estimator, e) = match label_h.strip_suffix(", compensated") {
        Some(plain) => (plain, env.compensated_view()),
        None => (label_h, env.view()),
    };
    let e = e.with_mis_heuristic(heuristic);
    assert!(env.compensated.is_some(), "the test map has texels above its mean");
    let mut failures = Vec::new();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    for (index, case) in cases().into_iter().enumerate() {
        let reference = reference(&e, index, &case);
        let sp = ShadingPoint { frame: case.frame, wo: case.wo, brdf: case.brdf.as_ref() };
        let mut vis = visible;
        // Each estimator its own stream: shared streams made their errors correlated.
        let stream = label.bytes().fold(0u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
        let mut rng = Pcg32::new(17, stream);
        let mut u = || DVec2::new(rng.next_f64(), rng.next_f64());
        let lum = luminance64;
        let values: Stats = match estimator {
            "product" | "wavelet" => product_units(estimator, &mut arena, &e, &case, &sp),
            "env" => env_units(&e, &case, &sp, &mut rng),
            "two-level" | "two-level-mis" => two_level_units(estimator, &e, &case, &sp, &mut rng),
            "product-mis" | "product-mis probed" | "product-mis for_mis" | "product-mis for_mis K=16" => {
                product_mis_units(estimator, &mut arena, &e, &case, &sp)
            }
            "product-mis split 3:1" | "product-mis split 1:3" => {
                product_mis_split_units(estimator, &mut arena, &e, &case, &sp)
            }
            // Compensated, the env samples leave the map's dim parts to the BRDF samples: a needle
            // lobe whose mirror direction is occluded is then found only through the GGX tail's
            // rare BRDF samples (heavy-tailed, though bounded by L / c_brdf), so it draws more.
            "mis split 3:1" => (0..if label_h.ends_with("compensated") { 80_000 } else { 20_000 })
                .map(|_| {
                    // Env-heavy MIS, as `auto` runs it on diffuse surfaces under extended light.
                    let pts: Vec<DVec2> = (0..12).map(|_| u()).collect();
                    let brdf_pts: Vec<Vec2> = (0..4).map(|_| u().as_vec2()).collect();
                    lum(estimator::sampled_mis_split(&e, &sp, &pts, &brdf_pts, (0.75, 0.25), &mut vis)) / 16.0
                })
                .collect(),
            "ris" => {
                let mut rng = Pcg32::new(23, 4);
                // Needle lobes at grazing views: ~1 in 15 000 BRDF candidates is both in the lobe
                // and above the occluder, so draw enough for ~100 non-zero estimates.
                let n = if case.width < 5e-3 { 2_000_000 } else { 100_000u64 };
                (0..n)
                    .map(|k| {
                        let mut cands = [DVec2::ZERO; 8];
                        sobol02(k, 0, &mut cands);
                        lum(estimator::ris(&e, &sp, &cands, rng.next_f64(), &mut vis).value)
                    })
                    .collect()
            }
            "brdf" => (0..200_000).map(|_| lum(estimator::brdf(&e, &sp, u(), &mut vis).value)).collect(),
            "mis" => (0..200_000)
                .map(|_| {
                    let [a, b] = estimator::sampled_mis(&e, &sp, u(), u().as_vec2(), &mut vis);
                    lum(a.value + b.value)
                })
                .collect(),
            "mis batched" => (0..20_000)
                .map(|_| {
                    // The renderer's batched path: env draws four side by side, BRDF draws and
                    // evaluations four lanes at a time.
                    let pts: Vec<DVec2> = (0..16).map(|_| u()).collect();
                    let brdf_pts: Vec<Vec2> = (0..16).map(|_| u().as_vec2()).collect();
                    let mut pairs = [[estimator::Contribution::default(); 2]; 16];
                    estimator::sampled_mis_many(&e, &sp, &pts, &brdf_pts, &mut vis, &mut pairs);
                    pairs.iter().map(|[a, b]| lum(a.value + b.value)).sum::<f64>() / 16.0
                })
                .collect(),
            _ => unreachable!(),
        };
        check(&format!("{label} / {}", case.name), reference, &values, &mut failures);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn two_level_estimator_is_unbiased() {
    run("two-level");
}

#[test]
fn two_level_mis_estimator_is_unbiased() {
    run("two-level-mis");
}

#[test]
fn product_estimator_is_unbiased() {
    run("product");
}

#[test]
fn wavelet_product_estimator_is_unbiased() {
    run("wavelet");
}

#[test]
fn product_mis_estimator_is_unbiased() {
    run("product-mis");
}

#[test]
fn product_mis_estimator_with_probed_leaves_is_unbiased() {
    run("product-mis probed");
}

/// The preset hosts use beside BRDF sampling: probed and refined leaves, ε = 0.25.
#[test]
fn product_mis_estimator_with_the_mis_preset_is_unbiased() {
    run("product-mis for_mis");
}

/// The same from 16 BRDF samples, the renderer's K for a diffuse BRDF (host-std
/// `render::brdf_samples`): coarser trees, refined from 1/16 of the mass.
#[test]
fn product_mis_estimator_with_the_mis_preset_from_16_samples_is_unbiased() {
    run("product-mis for_mis K=16");
}

/// MIS with three env samples to each BRDF sample.
#[test]
fn mis_with_an_uneven_split_is_unbiased() {
    run("mis split 3:1");
}

/// Product-MIS with three product samples to each BRDF sample, and the other way round.
#[test]
fn product_mis_with_uneven_splits_is_unbiased() {
    run("product-mis split 3:1");
    run("product-mis split 1:3");
}

#[test]
fn ris_estimator_is_unbiased() {
    run("ris");
}

#[test]
fn env_estimator_is_unbiased() {
    run("env");
}

#[test]
fn brdf_estimator_is_unbiased() {
    run("brdf");
}

#[test]
fn batched_mis_estimator_is_unbiased() {
    run("mis batched");
}

#[test]
fn mis_estimator_is_unbiased() {
    run("mis");
}

#[test]
fn mis_estimator_with_the_compensated_density_is_unbiased() {
    run("mis, compensated");
}

#[test]
fn mis_split_with_the_compensated_density_is_unbiased() {
    run("mis split 3:1, compensated");
}

/// The power heuristic, in pairs (one by one and batched), with a split budget and under the
/// product: each sample's weights still sum to one over the techniques.
#[test]
fn mis_with_the_power_heuristic_is_unbiased() {
    run("mis, compensated, power");
    run("mis batched, compensated, power");
    run("mis split 3:1, compensated, power");
}

#[test]
fn product_mis_with_the_power_heuristic_is_unbiased() {
    run("product-mis, power");
    run("product-mis split 3:1, power");
}
