//! The light tree picks lights with the probabilities its `pmf` states (the frequencies of
//! `pick` match them within 5σ per light, and it returns none as often as they fall short of 1), never gives probability 0
//! to a light that can reach the shading point (importance is conservative: any light sample
//! with a non-zero contribution has a positive probability), keeps every path within 64 levels
//! on ten thousand lights in a line, and the lights' estimator stays unbiased when it picks
//! through the tree.

use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::RoughConductor;
use sampler_core::estimator::ShadingPoint;
use sampler_core::estimator::lights::{FirstHit, LightRays, LightSet, light_pair};
use sampler_core::frame::Frame;
use sampler_core::light::{
    DiskLight, Light, LightBounds, LightNode, LightTree, PointLight, PowerSelector, RectLight, SceneLight, Shaping,
    SphereLight, TriangleLight,
};
use sampler_core::rng::Pcg32;

/// A few hundred lights of every kind with a position, scattered and turned every way (some
/// faces shaped about an axis that is not their normal).
fn lights(n: usize) -> Vec<SceneLight> {
    let mut rng = Pcg32::new(3, 1);
    let mut v = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
    (0..n)
        .map(|k| {
            let (c, d, l) = (v() * 5.0, v(), Vec3::new(1.0, 0.5, 0.2) * (1.0 + (k % 7) as f32));
            match k % 5 {
                0 => PointLight::new(c, l).unwrap().into(),
                1 => SphereLight::new(c, 0.2, l).unwrap().into(),
                2 => DiskLight::new(c, d, 0.3, l).unwrap().with_two_sided(k % 2 == 0).into(),
                3 => {
                    // Every other face shaped as a mesh light's: a cone about an axis of its own.
                    let face = TriangleLight::new([c, c + d, c + d.cross(Vec3::Z) * 0.5], l).unwrap();
                    let cone = Shaping::new(v(), 0.7, 0.3, 1.0, Vec3::new(0.5, 0.2, 0.0)).unwrap();
                    if k % 2 == 0 { face.with_two_sided(true).with_shaping(cone).into() } else { face.into() }
                }
                _ => {
                    let e1 = d.normalize() * 0.4;
                    let e2 = e1.cross(Vec3::new(0.3, 0.9, 0.1)).normalize() * 0.3;
                    RectLight::new(c, e1, e2, l).unwrap().into()
                }
            }
        })
        .collect()
}

struct Built {
    nodes: Vec<LightNode>,
    paths: Vec<u64>,
}

fn build(lights: &[SceneLight]) -> Built {
    let bounds: Vec<Option<LightBounds>> = lights.iter().map(LightBounds::of).collect();
    let n = bounds.iter().flatten().count();
    let mut order = vec![0u32; n];
    let first = bounds.iter().flatten().next().copied().unwrap();
    let mut nodes = vec![LightNode { bounds: first, index: 0, leaf: true }; 2 * n - 1];
    let mut paths = vec![0u64; lights.len()];
    let used = LightTree::build(&bounds, &mut order, &mut nodes, &mut paths).unwrap().nodes().len();
    nodes.truncate(used);
    Built { nodes, paths }
}

#[test]
fn picks_match_the_stated_probabilities_and_no_reachable_light_is_starved() {
    let lights = lights(300);
    let built = build(&lights);
    let tree = LightTree::from_parts(&built.nodes, &built.paths).unwrap();
    let mut rng = Pcg32::new(8, 2);
    for trial in 0..6 {
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 8.0 - Vec3::splat(4.0);
        let n = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE).normalize();
        let pmf: Vec<f64> = (0..lights.len()).map(|i| tree.pmf(i, p, n)).collect();
        // A descent may end where neither child can light p (a parent's looser bounds let it
        // in): the pick then returns none, with the probability the sum falls short of 1.
        let total: f64 = pmf.iter().sum();
        assert!(total <= 1.0 + 1e-9 && total > 0.5, "trial {trial}: probabilities sum to {total}");
        let draws = 200_000;
        let (mut counts, mut none) = (vec![0usize; lights.len()], 0usize);
        for k in 0..draws {
            let Some(s) = tree.pick((k as f64 + 0.5) / draws as f64, p, n) else {
                none += 1;
                continue;
            };
            assert!((s.pmf - pmf[s.index]).abs() <= 1e-9 * pmf[s.index].max(1e-300), "pick's pmf is pmf()'s");
            counts[s.index] += 1;
        }
        let expect_none = (1.0 - total) * draws as f64;
        assert!(
            (none as f64 - expect_none).abs() <= 5.0 * expect_none.sqrt() + 2.0,
            "{none} picks of none, {expect_none} expected"
        );
        for (i, &c) in counts.iter().enumerate() {
            let expect = pmf[i] * draws as f64;
            assert!(
                (c as f64 - expect).abs() <= 5.0 * expect.sqrt() + 2.0,
                "trial {trial}, light {i}: {c} vs {expect}"
            );
        }
        // Conservative: a light that sends light above the surface is never given 0.
        for (i, light) in lights.iter().enumerate() {
            for k in 0..16 {
                let u = Vec2::new((k % 4) as f32 / 4.0 + 0.1, (k / 4) as f32 / 4.0 + 0.1);
                if let Some(s) = light.sample(p, u)
                    && s.dir.dot(n) > 1e-3
                    && s.radiance.max_element() > 0.0
                {
                    assert!(pmf[i] > 0.0, "trial {trial}: light {i} ({light:?}) reaches p but has probability 0");
                }
            }
        }
    }
}

#[test]
fn ten_thousand_lights_in_a_line_stay_within_the_depth_limit() {
    let lights: Vec<SceneLight> = (0..10_000)
        .map(|k| PointLight::new(Vec3::new(1.5f32.powi(k % 60), 0.0, 0.0), Vec3::ONE).unwrap().into())
        .collect();
    let built = build(&lights);
    let tree = LightTree::from_parts(&built.nodes, &built.paths).unwrap();
    let (p, n) = (Vec3::new(0.0, 1.0, 0.0), Vec3::NEG_Y);
    let total: f64 = (0..lights.len()).map(|i| tree.pmf(i, p, n)).sum();
    assert!(total > 0.99 && total <= 1.0 + 1e-9, "{total}");
    assert!(built.nodes.len() == 2 * lights.len() - 1);
}

struct Unoccluded<'a>(&'a [SceneLight]);

impl LightRays for Unoccluded<'_> {
    fn unoccluded(&mut self, _: Vec3, _: f32) -> bool {
        true
    }
    fn first_hit(&mut self, dir: Vec3) -> FirstHit {
        let mut nearest = (f32::INFINITY, FirstHit::Escapes);
        for (i, l) in self.0.iter().enumerate() {
            if let Some(h) = l.eval(Vec3::ZERO, dir).filter(|h| h.distance < nearest.0 && l.surface().is_some()) {
                nearest = (h.distance, FirstHit::Emitter(i));
            }
        }
        nearest.1
    }
}

#[test]
fn the_estimator_through_the_tree_agrees_with_power_selection() {
    // Lights that do not hide one another from the origin, all above its surface.
    let l = Vec3::splat(2.0);
    let lights: Vec<SceneLight> = vec![
        SphereLight::new(Vec3::new(1.8, 1.2, 3.0), 0.6, l).unwrap().into(),
        RectLight::new(Vec3::new(-1.0, -1.0, 2.5), Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 0.0, 0.0), l)
            .unwrap()
            .into(),
        DiskLight::new(Vec3::new(-1.5, 0.5, 2.0), Vec3::new(0.5, -0.2, -1.0), 0.5, l).unwrap().into(),
        PointLight::new(Vec3::new(3.0, -2.0, 1.0), l).unwrap().into(),
    ];
    let n = Vec3::new(0.1, 0.2, 1.0).normalize();
    let frame = Frame::from_normal(n);
    let brdf = RoughConductor::new(0.3, Vec3::ONE);
    let sp = ShadingPoint { frame, wo: (n + 0.5 * frame.t).normalize(), brdf: &brdf };
    let built = build(&lights);
    let tree = LightTree::from_parts(&built.nodes, &built.paths).unwrap();
    let mut top_cdf = [0.0; 2];
    let top = PowerSelector::build(&[1.0], &mut top_cdf).unwrap();
    let by_tree = LightSet::with_tree(&lights, tree, top, &[], &[]).unwrap();
    let weights: Vec<f32> = lights.iter().map(|l| l.power(1.0).x).collect();
    let mut cdf = vec![0.0; lights.len() + 1];
    let by_power = LightSet::new(&lights, PowerSelector::build(&weights, &mut cdf).unwrap(), &[]).unwrap();
    let mean = |set: &LightSet<'_>| {
        let mut rng = Pcg32::new(4, 4);
        let (mut sum, mut sum2, n) = (0.0, 0.0, 200_000);
        for _ in 0..n {
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            let x = light_pair(
                set,
                Vec3::ZERO,
                &sp,
                u,
                Vec2::new(rng.next_f32(), rng.next_f32()),
                &mut Unoccluded(&lights),
            )
            .x;
            (sum, sum2) = (sum + x, sum2 + x * x);
        }
        let m = sum / n as f64;
        (m, ((sum2 / n as f64 - m * m) / n as f64).sqrt())
    };
    let ((a, sa), (b, sb)) = (mean(&by_tree), mean(&by_power));
    assert!((a - b).abs() <= 4.0 * (sa * sa + sb * sb).sqrt(), "tree {a} ± {sa}, power {b} ± {sb}");
}
