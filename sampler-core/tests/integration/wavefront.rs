//! A wavefront of samples at many shading points gives, sample by sample and bit for bit, what
//! the per-point estimators give at each point for the same points of the square — for the
//! env-only sampler and a product, alone, in pairs and with a split budget, under either MIS
//! heuristic — and asks for a shadow ray exactly where they ask for visibility.

use crate::common;
use crate::common::TestEnv;
use glam::{DVec2, DVec3, Vec3};
use sampler_core::brdf::Brdf;
use sampler_core::direction::DirectionSampler;
use sampler_core::env::MisHeuristic;
use sampler_core::estimator::wavefront::{Candidate, Technique, WAVE, WaveSample, Weighting, wavefront};
use sampler_core::estimator::{self, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::points::sobol02;
use sampler_core::sampler::{ProductArena, ProductParams};

/// Visibility that sees everything and remembers whether it was asked.
#[derive(Default)]
struct Asked(bool);

impl estimator::Visibility for Asked {
    fn visible(&mut self, _: Vec3) -> bool {
        self.0 = true;
        true
    }
}

fn bits(v: DVec3) -> [u64; 3] {
    v.to_array().map(f64::to_bits)
}

/// The per-point value of sample `k` (and whether visibility was asked) as the per-point
/// estimators compute it.
fn per_point<S: DirectionSampler + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, dyn Brdf + '_>,
    samples: &[WaveSample],
    k: usize,
    weighting: Weighting,
) -> (DVec3, bool) {
    let s = samples[k];
    let mut asked = Asked::default();
    let value = match (weighting, s.technique) {
        (Weighting::Single, Technique::Sampler) => {
            let mut drawn = [None];
            sampler.sample_many(&[s.u], &mut drawn);
            estimator::sampled_drawn(sampler, sp, drawn[0], &mut asked).value
        }
        (Weighting::Single, Technique::Brdf) => {
            let mut out = [estimator::Contribution::default()];
            estimator::brdf_many(sampler.env(), sp, &[s.u.as_vec2()], &mut asked, &mut out);
            out[0].value
        }
        (_, technique) => {
            // Samples come in (sampler, BRDF) pairs at the same point.
            let (a, b) = if technique == Technique::Sampler { (s, samples[k + 1]) } else { (samples[k - 1], s) };
            let half = usize::from(technique == Technique::Brdf);
            match weighting {
                Weighting::Split { sampler: c_s, brdf: c_b } => {
                    let (u, v) = if half == 0 { (&[a.u][..], &[][..]) } else { (&[][..], &[b.u.as_vec2()][..]) };
                    estimator::sampled_mis_split(sampler, sp, u, v, (c_s, c_b), &mut asked)
                }
                _ => {
                    let mut out = [[estimator::Contribution::default(); 2]];
                    let mut vis = |_: Vec3| true;
                    estimator::sampled_mis_many(sampler, sp, &[a.u], &[b.u.as_vec2()], &mut vis, &mut out);
                    asked.0 = out[0][half].value != DVec3::ZERO;
                    out[0][half].value
                }
            }
        }
    };
    (value, asked.0)
}

fn check<S: DirectionSampler + ?Sized>(
    name: &str,
    sampler: &S,
    points: &[ShadingPoint<'_, dyn Brdf + '_>],
    samples: &[WaveSample],
    weighting: Weighting,
) -> usize {
    let mut out = vec![Candidate::default(); samples.len()];
    wavefront(sampler, points, samples, weighting, &mut out);
    let mut lit = 0;
    for (k, c) in out.iter().enumerate() {
        let (value, asked) = per_point(sampler, &points[samples[k].point], samples, k, weighting);
        assert_eq!(bits(c.value), bits(value), "{name} {weighting:?}, sample {k}");
        assert_eq!(c.needs_ray, asked, "{name} {weighting:?}, sample {k}: shadow ray");
        lit += usize::from(c.needs_ray);
    }
    lit
}

#[test]
fn a_wavefront_is_the_per_point_estimators_sample_by_sample() {
    let env = TestEnv::random_smooth(5, 9);
    let e = env.view();
    let brdfs = common::batch_brdfs();
    let normals = [Vec3::Z, Vec3::new(0.3, -0.5, 0.8), Vec3::new(-0.9, 0.1, 0.2)];
    let points: Vec<ShadingPoint<'_, dyn Brdf + '_>> = (0..15)
        .map(|i| {
            let frame = Frame::from_normal(normals[i % 3].normalize());
            let wo = frame.to_world(Vec3::new(0.4, 0.1 * i as f32, 0.6).normalize());
            ShadingPoint { frame, wo, brdf: brdfs[i % 5].as_ref() }
        })
        .collect();
    // More samples than one wave holds, in (sampler, BRDF) pairs, points out of order.
    let n = 2 * WAVE + 22;
    let mut u = vec![DVec2::ZERO; n];
    sobol02(17, 0, &mut u);
    let samples: Vec<WaveSample> = (0..n)
        .map(|k| WaveSample {
            point: (k / 2 * 7) % points.len(),
            technique: if k % 2 == 0 { Technique::Sampler } else { Technique::Brdf },
            u: u[k],
        })
        .collect();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let p = &points[0];
    let mut lit = 0;
    // Under either heuristic, which the views carry (the product its env view's).
    for heuristic in [MisHeuristic::Balance, MisHeuristic::Power] {
        let e = e.with_mis_heuristic(heuristic);
        let product = arena.build(&e, p.brdf, &p.frame, p.wo, &ProductParams::for_mis(256), 5).unwrap();
        for weighting in [Weighting::Single, Weighting::Pairs, Weighting::Split { sampler: 0.75, brdf: 0.25 }] {
            lit += check("env", &e, &points, &samples, weighting);
            lit += check("product", &product, &points, &samples, weighting);
        }
    }
    assert!(lit > 2 * samples.len(), "only {lit} samples lit");
}
