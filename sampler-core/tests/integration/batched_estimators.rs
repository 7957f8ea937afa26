//! The batched estimators the renderer uses (MIS, env alone, BRDF alone) give, pair by pair, bit for bit what the
//! one-pair estimators give for the same drawn directions and BRDF points; both MIS estimators
//! split half and half sum to the pairs' estimate — for more pairs than one batch holds (101:
//! six batches of `estimator::BATCH`, the last one partial, and more than the 64 an older
//! version took at most).

use crate::common;
use crate::common::TestEnv;
use glam::{DVec2, Vec2, Vec3};
use sampler_core::estimator::{self, Contribution, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::points::sobol02;
use sampler_core::sampler::{ProductArena, ProductParams};

fn bits(c: &Contribution) -> ([u64; 3], [u32; 3], u32, u32) {
    (c.value.to_array().map(f64::to_bits), c.dir.to_array().map(f32::to_bits), c.pdf.to_bits(), c.other_pdf.to_bits())
}

#[test]
fn batched_mis_is_pair_by_pair_mis() {
    let env = TestEnv::random_smooth(5, 9);
    let e = env.view();
    let brdfs = common::batch_brdfs();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut compared = 0;
    for (i, brdf) in brdfs.iter().enumerate() {
        for (j, n) in [Vec3::Z, Vec3::new(0.3, -0.5, 0.8), Vec3::new(-0.9, 0.1, 0.2)].into_iter().enumerate() {
            let frame = Frame::from_normal(n.normalize());
            let wo = frame.to_world(Vec3::new(0.4, 0.1, 0.6).normalize());
            let sp = ShadingPoint { frame, wo, brdf: brdf.as_ref() };
            // Visibility that blocks part of the sphere, the same for both paths.
            let mut vis = |d: Vec3| d.x + 0.3 * d.y < 0.5;
            let (mut u, mut v) = ([DVec2::ZERO; 101], [DVec2::ZERO; 101]);
            sobol02((i * 7 + j) as u64, 0, &mut u);
            sobol02((i * 7 + j) as u64 + 99, 0, &mut v);
            let brdf_points: Vec<Vec2> = v.iter().map(|p| p.as_vec2()).collect();
            let mut out = [[Contribution::default(); 2]; 101];
            // Env and BRDF.
            let mut drawn = [None; 101];
            e.sample_many(&u, &mut drawn);
            estimator::sampled_mis_many(&e, &sp, &u, &brdf_points, &mut vis, &mut out);
            for k in 0..u.len() {
                let one = estimator::sampled_mis_drawn(&e, &sp, drawn[k], brdf_points[k], &mut vis);
                assert_eq!(out[k].map(|c| bits(&c)), one.map(|c| bits(&c)), "mis, brdf {i}, pair {k}");
                compared += usize::from(out[k][0].value.max_element() > 0.0 && out[k][1].value.max_element() > 0.0);
            }
            assert_split_is_pairs(&out, estimator::sampled_mis_split(&e, &sp, &u, &brdf_points, (0.5, 0.5), &mut vis));
            // Env alone and BRDF alone.
            let mut singles = [Contribution::default(); 101];
            estimator::sampled_many(&e, &sp, &u, &mut vis, &mut singles);
            for k in 0..u.len() {
                let one = estimator::sampled_drawn(&e, &sp, drawn[k], &mut vis);
                assert_eq!(bits(&singles[k]), bits(&one), "env, brdf {i}, sample {k}");
            }
            estimator::brdf_many(&e, &sp, &brdf_points, &mut vis, &mut singles);
            for k in 0..u.len() {
                let one = estimator::brdf(&e, &sp, v[k], &mut vis);
                assert_eq!(bits(&singles[k]), bits(&one), "brdf, brdf {i}, sample {k}");
            }
            // Product and BRDF.
            let s = arena.build(&e, brdf.as_ref(), &frame, wo, &ProductParams::for_mis(256), 5).unwrap();
            let mut drawn = [None; 101];
            s.sample_many(&u, &mut drawn);
            estimator::sampled_mis_many(&s, &sp, &u, &brdf_points, &mut vis, &mut out);
            for k in 0..u.len() {
                let one = estimator::sampled_mis_drawn(&s, &sp, drawn[k], brdf_points[k], &mut vis);
                assert_eq!(out[k].map(|c| bits(&c)), one.map(|c| bits(&c)), "product-mis, brdf {i}, pair {k}");
            }
            assert_split_is_pairs(&out, estimator::sampled_mis_split(&s, &sp, &u, &brdf_points, (0.5, 0.5), &mut vis));
        }
    }
    assert!(compared > 100, "only {compared} pairs with both halves lit");
}

/// A split half and half is the pairs' estimate (×2: the pairs' sum is over n pairs, the
/// split's over 2n samples), up to the order of the sums.
fn assert_split_is_pairs(pairs: &[[Contribution; 2]], split: glam::DVec3) {
    let pairs: glam::DVec3 = pairs.iter().map(|[a, b]| a.value + b.value).sum();
    let tol = 1e-12 * pairs.abs().max_element().max(1e-300);
    assert!((split - 2.0 * pairs).abs().max_element() <= tol, "split {split} vs pairs {pairs}");
}
