//! Each estimator's units at one case, for `run`: a unit is one value whose mean over the units
//! is the estimate and whose spread gives its standard error.

use super::*;

/// Product or wavelet-product sampling at one case: each unit a fresh B̃ and 32 warped points.
pub(super) fn product_units(
    estimator: &str,
    arena: &mut ProductArena,
    e: &EnvHierarchy<'_>,
    case: &Case,
    sp: &ShadingPoint<'_, dyn Brdf>,
) -> Stats {
    let mut vis = visible;
    // Each unit: a fresh B̃ (new BRDF samples) and 32 warped points: the whole
    // estimator, including the randomness of the product itself.
    let kind = if estimator == "product" { ProductKind::QUADTREE } else { ProductKind::WAVELET };
    let params = ProductParams { kind, ..ProductParams::default() };
    (0..600u64)
        .map(|seed| {
            let s = arena.build(e, case.brdf.as_ref(), &case.frame, case.wo, &params, seed).unwrap();
            let mut pts = [DVec2::ZERO; 32];
            sobol02(seed ^ 0xabc, 0, &mut pts);
            pts.iter().map(|p| luminance64(estimator::sampled(&s, sp, *p, &mut vis).value)).sum::<f64>() / 32.0
        })
        .collect()
}

/// Env sampling at one case: units of scrambled nets where the lobe is a needle.
pub(super) fn env_units(e: &EnvHierarchy<'_>, case: &Case, sp: &ShadingPoint<'_, dyn Brdf>, rng: &mut Pcg32) -> Stats {
    let mut vis = visible;
    let mut u = || DVec2::new(rng.next_f64(), rng.next_f64());
    // Env sampling finds a needle lobe about once per 1e6 draws (GGX α = 1e-3): with
    // independent draws the mean is carried by a few dozen hits, its standard error
    // is itself unreliable and the test passes or fails by luck. So each unit is the
    // mean of an Owen-scrambled (0,2)-net pushed through the warp, which hits the
    // lobe at a nearly fixed rate; units are independent, so their spread is an
    // honest standard error.
    let (units, per_unit) = if case.width < 5e-3 {
        (64, 1 << 19)
    } else if case.width < 0.05 {
        (64, 1 << 16)
    } else {
        (200_000, 1)
    };
    let mut pts = vec![DVec2::ZERO; per_unit];
    (0..units)
        .map(|unit| {
            if per_unit == 1 {
                return luminance64(estimator::sampled(e, sp, u(), &mut vis).value);
            }
            sobol02(0xe0 ^ unit as u64, 0, &mut pts);
            let sum: f64 = pts.iter().map(|p| luminance64(estimator::sampled(e, sp, *p, &mut vis).value)).sum();
            sum / per_unit as f64
        })
        .collect()
}

/// The two-level product at one case, alone or in MIS with BRDF sampling.
pub(super) fn two_level_units(
    estimator: &str,
    e: &EnvHierarchy<'_>,
    case: &Case,
    sp: &ShadingPoint<'_, dyn Brdf>,
    rng: &mut Pcg32,
) -> Stats {
    let mut vis = visible;
    let mut u = || DVec2::new(rng.next_f64(), rng.next_f64());
    // A 16×16 coarse level. Alone, the product follows the light inside a cell, so a
    // lobe much narrower than a cell is found as env sampling finds it: units of
    // scrambled nets, as for "env". With MIS, BRDF sampling carries such lobes.
    let mut cones = vec![sampler_core::cone::Cone::default(); 256];
    assert!(sampler_core::cone::build_cell_cones(&mut cones));
    let mut two: Box<TwoLevelArena> = Box::default();
    let s = two.build(e, &cones, case.brdf.as_ref(), &case.frame, case.wo).unwrap();
    let mis = estimator == "two-level-mis";
    let (units, per_unit) = match () {
        _ if mis => (200_000, 1),
        _ if case.width < 5e-3 => (64, 1 << 18),
        _ if case.width < 0.05 => (64, 1 << 15),
        _ => (200_000, 1),
    };
    let mut pts = vec![DVec2::ZERO; per_unit];
    (0..units)
        .map(|unit| {
            if mis {
                let [a, b] = estimator::sampled_mis(&s, sp, u(), u().as_vec2(), &mut vis);
                return luminance64(a.value + b.value);
            }
            if per_unit == 1 {
                return luminance64(estimator::sampled(&s, sp, u(), &mut vis).value);
            }
            sobol02(0x7e0 ^ unit as u64, 0, &mut pts);
            let sum: f64 = pts.iter().map(|p| luminance64(estimator::sampled(&s, sp, *p, &mut vis).value)).sum();
            sum / per_unit as f64
        })
        .collect()
}

/// Product-MIS at one case with the default, probed or `for_mis` settings (at K = 256, or 16).
pub(super) fn product_mis_units(
    estimator: &str,
    arena: &mut ProductArena,
    e: &EnvHierarchy<'_>,
    case: &Case,
    sp: &ShadingPoint<'_, dyn Brdf>,
) -> Stats {
    let mut vis = visible;
    let params = match estimator {
        "product-mis probed" => ProductParams {
            kind: ProductKind::Quadtree { leaves: Leaves::Probed, refine_share: 0.0 },
            ..ProductParams::default()
        },
        "product-mis for_mis" => ProductParams::for_mis(256),
        "product-mis for_mis K=16" => ProductParams::for_mis(16),
        _ => ProductParams::default(),
    };
    (0..600u64)
        .map(|seed| {
            let s = arena.build(e, case.brdf.as_ref(), &case.frame, case.wo, &params, seed).unwrap();
            let (mut pts, mut qts) = ([DVec2::ZERO; 32], [DVec2::ZERO; 32]);
            sobol02(seed ^ 0xdef, 0, &mut pts);
            sobol02(seed ^ 0x123, 0, &mut qts);
            if estimator.starts_with("product-mis for_mis") {
                // The renderer's batched path.
                let mut pairs = [[estimator::Contribution::default(); 2]; 32];
                let q = qts.map(|q| q.as_vec2());
                estimator::sampled_mis_many(&s, sp, &pts, &q, &mut vis, &mut pairs);
                return pairs.iter().map(|[a, b]| luminance64(a.value + b.value)).sum::<f64>() / 32.0;
            }
            (0..32)
                .map(|k| {
                    let [a, b] = estimator::sampled_mis(&s, sp, pts[k], qts[k].as_vec2(), &mut vis);
                    luminance64(a.value + b.value)
                })
                .sum::<f64>()
                / 32.0
        })
        .collect()
}

/// Product-MIS at one case with the budget split 3:1 or 1:3 between the techniques.
pub(super) fn product_mis_split_units(
    estimator: &str,
    arena: &mut ProductArena,
    e: &EnvHierarchy<'_>,
    case: &Case,
    sp: &ShadingPoint<'_, dyn Brdf>,
) -> Stats {
    let mut vis = visible;
    // The renderer's product-MIS: the budget split unevenly between the techniques.
    let (n_p, n_b) = if estimator.ends_with("3:1") { (24, 8) } else { (8, 24) };
    let shares = (n_p as f32 / 32.0, n_b as f32 / 32.0);
    let params = ProductParams::for_mis(256);
    (0..600u64)
        .map(|seed| {
            let s = arena.build(e, case.brdf.as_ref(), &case.frame, case.wo, &params, seed).unwrap();
            let (mut pts, mut qts) = ([DVec2::ZERO; 32], [DVec2::ZERO; 32]);
            sobol02(seed ^ 0xdef, 0, &mut pts[..n_p]);
            sobol02(seed ^ 0x123, 0, &mut qts[..n_b]);
            let q = qts.map(|q| q.as_vec2());
            luminance64(estimator::sampled_mis_split(&s, sp, &pts[..n_p], &q[..n_b], shares, &mut vis)) / 32.0
        })
        .collect()
}
