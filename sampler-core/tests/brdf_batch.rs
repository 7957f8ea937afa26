//! The batched `sample_batch` fast path (used to build B̃) draws the same directions with the
//! same values as `sample`.

use glam::{Vec2, Vec3};
use sampler_core::brdf::{Brdf, BrdfDraw, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::luminance;
use sampler_core::rng::Pcg32;

#[test]
fn batched_samples_match_single_samples() {
    let brdfs: Vec<Box<dyn Brdf>> = vec![
        Box::new(Lambert::new(Vec3::splat(0.7))),
        Box::new(Phong::new(Vec3::splat(0.2), Vec3::splat(0.7), 300.0)),
        Box::new(RoughConductor::new(0.2, Vec3::new(1.0, 0.8, 0.6))),
        Box::new(RoughConductor::new(1e-3, Vec3::ONE)),
        Box::new(CarPaint::default()),
    ];
    let mut rng = Pcg32::new(3, 3);
    let u: Vec<Vec2> = (0..256).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect();
    for brdf in &brdfs {
        for wo in [Vec3::new(0.3, -0.2, 0.9).normalize(), Vec3::new(0.999, 0.0, 0.04).normalize()] {
            let mut out = vec![BrdfDraw::default(); u.len()];
            let n = brdf.sample_batch(wo, &u, &mut out);
            let single: Vec<_> = u.iter().filter_map(|p| brdf.sample(wo, *p)).collect();
            assert!(n >= single.len());
            // Compare the draws that `sample` accepted, in order.
            let mut k = 0;
            for d in &out[..n] {
                if k < single.len() && (single[k].wi - d.wi).length() < 1e-5 {
                    let value = luminance(single[k].value);
                    assert!((value - d.value).abs() <= 1e-3 * value.max(d.value).max(1e-6), "{value} vs {}", d.value);
                    k += 1;
                }
            }
            assert_eq!(k, single.len(), "batched draws differ from single draws");
        }
    }
}
