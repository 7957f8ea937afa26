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

/// `eval_pdf` is `eval` and `pdf` bit for bit (MIS relies on the two agreeing), for directions
/// all over the sphere, from views up to grazing ones, and on drawn directions where lobes peak.
#[test]
fn eval_pdf_is_eval_and_pdf() {
    let brdfs: Vec<Box<dyn Brdf>> = vec![
        Box::new(Lambert::new(Vec3::splat(0.7))),
        Box::new(Phong::new(Vec3::splat(0.2), Vec3::splat(0.7), 300.0)),
        Box::new(Phong::new(Vec3::ZERO, Vec3::splat(0.9), 1e5)),
        Box::new(RoughConductor::new(0.2, Vec3::new(1.0, 0.8, 0.6))),
        Box::new(RoughConductor::new(1e-4, Vec3::ONE)),
        Box::new(CarPaint::default()),
        Box::new(CarPaint { coat: 0.0, ..CarPaint::default() }),
    ];
    let mut rng = Pcg32::new(5, 7);
    let mut sphere = || {
        let z = 2.0 * rng.next_f32() - 1.0;
        let phi = core::f32::consts::TAU * rng.next_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    let views: Vec<Vec3> = (0..40).map(|_| sphere()).chain([Vec3::Z, Vec3::new(1.0, 0.0, 1e-4).normalize()]).collect();
    let mut checked = 0;
    for brdf in &brdfs {
        for &wo in &views {
            let drawn = (0..32).filter_map(|k| brdf.sample(wo, Vec2::new((k as f32 + 0.5) / 32.0, 0.37)));
            let wis: Vec<Vec3> = (0..64).map(|_| sphere()).chain(drawn.map(|s| s.wi)).chain([wo, -wo]).collect();
            for wi in wis {
                let (value, pdf) = brdf.eval_pdf(wo, wi);
                let (e, p) = (brdf.eval(wo, wi), brdf.pdf(wo, wi));
                assert_eq!(value.to_array().map(f32::to_bits), e.to_array().map(f32::to_bits), "{wo} {wi}");
                assert_eq!(pdf.to_bits(), p.to_bits(), "{wo} {wi}");
                checked += usize::from(pdf > 0.0 && value.max_element() > 0.0);
            }
        }
    }
    assert!(checked > 2000, "only {checked} directions where both are positive");
}

/// `sample_many` and `eval_pdf_many` (four lanes for the GGX conductor) are `sample` and
/// `eval_pdf` bit for bit, whatever the batch length (tails of 1–3, outputs longer than inputs).
#[test]
fn many_at_once_is_one_at_a_time() {
    use sampler_core::brdf::BrdfSample;
    let bits = |s: &Option<BrdfSample>| {
        s.map(|s| (s.wi.to_array().map(f32::to_bits), s.value.to_array().map(f32::to_bits), s.pdf.to_bits()))
    };
    let mut brdfs: Vec<Box<dyn Brdf>> = [1e-4, 1e-3, 0.02, 0.1, 0.3, 1.0]
        .map(|a| Box::new(RoughConductor::new(a, Vec3::new(1.0, 0.8, 0.6))) as Box<dyn Brdf>)
        .into();
    brdfs.push(Box::new(CarPaint::default()));
    brdfs.push(Box::new(Lambert::new(Vec3::splat(0.5))));
    let mut rng = Pcg32::new(11, 13);
    let mut u: Vec<Vec2> = (0..61).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect();
    u.extend([Vec2::ZERO, Vec2::new(0.25, 0.5), Vec2::new(0.125, 1.0), Vec2::splat(1.0 - f32::EPSILON / 2.0)]);
    let views = [
        Vec3::Z,
        Vec3::new(0.3, -0.2, 0.9),
        Vec3::new(0.999, 0.0, 0.04),
        Vec3::new(-0.5, 0.5, 1e-3),
        Vec3::new(0.2, 0.1, -0.9),
    ];
    let mut positive = 0;
    for brdf in &brdfs {
        for wo in views.map(Vec3::normalize) {
            for n in [u.len(), 1, 2, 3, 5] {
                let mut many = vec![None; n + 3];
                brdf.sample_many(wo, &u[..n], &mut many);
                for (k, p) in u[..n].iter().enumerate() {
                    assert_eq!(bits(&many[k]), bits(&brdf.sample(wo, *p)), "wo {wo}, u {p}");
                    positive += usize::from(many[k].is_some());
                }
                assert!(many[n..].iter().all(Option::is_none), "wrote past the inputs");
            }
            // Each draw seen from its own view: runs of one view, views alternating, below.
            let mixed: Vec<Vec3> = (0..u.len())
                .map(|k| if (k / 3) % 2 == 0 { wo } else { views[(k / 2) % views.len()].normalize() })
                .collect();
            let mut many = vec![None; u.len() + 3];
            brdf.sample_many_views(&mixed, &u, &mut many);
            for (k, p) in u.iter().enumerate() {
                assert_eq!(bits(&many[k]), bits(&brdf.sample(mixed[k], *p)), "wo {}, u {p}", mixed[k]);
            }
            assert!(many[u.len()..].iter().all(Option::is_none), "wrote past the inputs");
            let wis: Vec<Vec3> =
                u.iter().map(|p| Vec3::new(2.0 * p.x - 1.0, 2.0 * p.y - 1.0, p.x - p.y).normalize()).collect();
            let mut many = vec![(Vec3::NAN, f32::NAN); wis.len()];
            brdf.eval_pdf_many(wo, &wis, &mut many);
            for (wi, (value, pdf)) in wis.iter().zip(&many) {
                let (e, p) = brdf.eval_pdf(wo, *wi);
                assert_eq!(value.to_array().map(f32::to_bits), e.to_array().map(f32::to_bits), "wo {wo}, wi {wi}");
                assert_eq!(pdf.to_bits(), p.to_bits(), "wo {wo}, wi {wi}");
            }
        }
    }
    assert!(positive > 1000, "only {positive} draws");
}
