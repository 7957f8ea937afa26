//! The lights' estimator (`estimator::lights`) is unbiased: its balance-heuristic pairs of a
//! light sample and a BRDF sample, and its light samples alone, average to the reflected
//! radiance ∫ L·B·cos dω that jittered quadrature over the light's cone computes — for every
//! kind of area and distant light near and far, under Lambert, GGX α 0.1 and 0.4 and car paint
//! (light samples alone on the wide lobes) — within 4 standard errors plus the quadrature's error. With several lights picked by power the
//! pair still averages to the sum of their quadratures; a delta light is estimated exactly.

use crate::common::{integrate_cone_jittered, light_cases};
use glam::{DVec2, DVec3, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, RoughConductor};
use sampler_core::estimator::ShadingPoint;
use sampler_core::estimator::lights::{FirstHit, LightRays, LightSet, brdf_sample, light_pair, light_sample};
use sampler_core::frame::Frame;
use sampler_core::light::{
    DiskLight, DistantLight, Light, PointLight, PowerSelector, RectLight, SceneLight, SphereLight,
};
use sampler_core::rng::Pcg32;

const SAMPLES: usize = 20_000;

/// An empty scene around the lights: nothing occludes, a ray meets the nearest light surface.
struct Unoccluded<'a> {
    lights: &'a [SceneLight],
    p: Vec3,
}

impl LightRays for Unoccluded<'_> {
    fn unoccluded(&mut self, _dir: Vec3, _distance: f32) -> bool {
        true
    }
    fn first_hit(&mut self, dir: Vec3) -> FirstHit {
        let mut nearest = (f32::INFINITY, FirstHit::Escapes);
        for (i, l) in self.lights.iter().enumerate().filter(|(_, l)| l.surface().is_some()) {
            if let Some(h) = l.eval(self.p, dir).filter(|h| h.distance < nearest.0) {
                nearest = (h.distance, FirstHit::Emitter(i));
            }
        }
        nearest.1
    }
}

/// (mean, standard error) of the red channel of `f` over independent uniform points.
fn mean_of(seed: u64, mut f: impl FnMut(DVec2, Vec2) -> DVec3) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 9);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..SAMPLES {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let v = Vec2::new(rng.next_f32(), rng.next_f32());
        let x = f(u, v).x;
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / SAMPLES as f64;
    (mean, ((sum2 / SAMPLES as f64 - mean * mean).max(0.0) / SAMPLES as f64).sqrt())
}

fn brdfs() -> Vec<(&'static str, Box<dyn Brdf>)> {
    vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.8)))),
        ("ggx 0.1", Box::new(RoughConductor::new(0.1, Vec3::ONE))),
        ("ggx 0.4", Box::new(RoughConductor::new(0.4, Vec3::ONE))),
        // A coat of α 0.05: the default's 0.005 is far sharper than a quadrature cell.
        ("car paint", Box::new(CarPaint::new(Vec3::new(0.01, 0.03, 0.15), Vec3::new(0.1, 0.2, 0.5), 0.25, 1.0, 0.05))),
    ]
}

/// A set over `lights` with its own selection buffers.
fn with_set<R>(lights: &[SceneLight], f: impl FnOnce(&LightSet<'_>) -> R) -> R {
    let weights: Vec<f32> = lights.iter().map(|l| l.power(10.0).x).collect();
    let mut cdf = vec![0.0; lights.len() + 1];
    let selector = PowerSelector::build(&weights, &mut cdf).unwrap();
    let infinite: Vec<u32> = (0..lights.len() as u32).filter(|&i| lights[i as usize].is_infinite_area()).collect();
    f(&LightSet::new(lights, selector, &infinite).unwrap())
}

#[test]
fn light_and_brdf_pairs_average_to_the_quadrature_of_the_reflected_light() {
    let mut checked = 0;
    for (k, case) in light_cases().into_iter().enumerate() {
        // The surface faces the light, tilted, and is seen from a side.
        let n = (case.axis + Vec3::new(0.3, -0.2, 0.1)).normalize();
        let frame = Frame::from_normal(n);
        let wo = (n + 0.8 * frame.s).normalize();
        let lights = [case.light];
        for (name, brdf) in brdfs() {
            let sp = ShadingPoint { frame, wo, brdf: brdf.as_ref() };
            let reflected = |d: Vec3| case.light.eval(case.p, d).map_or(0.0, |h| (h.radiance * sp.eval(d)).x as f64);
            let expected = integrate_cone_jittered(case.axis, case.cone, 300, 17 + k as u64, reflected);
            let quad_error = 2e-3 * expected.abs() + 1e-7;
            with_set(&lights, |set| {
                let mut rays = Unoccluded { lights: &lights, p: case.p };
                let (pair, se) = mean_of(k as u64, |u, v| light_pair(set, case.p, &sp, u, v, &mut rays));
                let mut rays = Unoccluded { lights: &lights, p: case.p };
                let (alone, se_alone) =
                    mean_of(99 + k as u64, |u, _| light_sample(set, case.p, &sp, u, false, &mut rays));
                // Light samples alone under a sharp lobe have a heavy tail that the standard error
                // understates: they are checked on the wide lobes only.
                let wide = name == "lambert" || name == "ggx 0.4";
                let checks = [("pair", pair, se, true), ("light samples", alone, se_alone, wide)];
                for (what, got, se, _) in checks.into_iter().filter(|c| c.3) {
                    let bound = 4.0 * se + quad_error;
                    assert!(
                        (got - expected).abs() <= bound,
                        "{} under {name}, {what}: {got} against {expected} (bound {bound})",
                        case.name
                    );
                }
            });
            checked += usize::from(expected > 1e-6);
        }
    }
    assert!(checked > 30, "only {checked} cases reflect any light");
}

#[test]
fn several_lights_picked_by_power_and_a_delta_light_stay_unbiased() {
    let l = Vec3::new(3.0, 2.0, 1.0);
    let lights: Vec<SceneLight> = vec![
        SphereLight::new(Vec3::new(1.8, 1.2, 3.0), 0.6, l).unwrap().into(),
        DistantLight::new(Vec3::new(-0.6, -0.9, 1.0), l, 6f32.to_radians()).unwrap().into(),
        RectLight::new(Vec3::new(-1.0, -1.0, 2.5), Vec3::new(0.0, 1.5, 0.0), Vec3::new(2.0, 0.0, 0.0), l)
            .unwrap()
            .into(),
        DiskLight::new(Vec3::new(-1.5, 0.5, 2.0), Vec3::new(0.5, -0.2, -1.0), 0.5, l).unwrap().into(),
    ];
    let n = Vec3::new(0.1, 0.2, 1.0).normalize();
    let frame = Frame::from_normal(n);
    let wo = (n + 0.5 * frame.t).normalize();
    let brdf = RoughConductor::new(0.3, Vec3::ONE);
    let sp = ShadingPoint { frame, wo, brdf: &brdf };
    // No light hides another from the shading point. Each light over a cone that holds it: the sphere's and the distant light's own, the
    // hemisphere for the rectangle and the disk.
    let sphere_cone = (0.6f64 / Vec3::new(1.8, 1.2, 3.0).length() as f64).asin() * 1.05;
    let cones = [
        (Vec3::new(1.8, 1.2, 3.0).normalize(), sphere_cone),
        (Vec3::new(-0.6, -0.9, 1.0).normalize(), 3f64.to_radians() * 1.05),
        (n, std::f64::consts::FRAC_PI_2),
        (n, std::f64::consts::FRAC_PI_2),
    ];
    let (mut expected, mut bound) = (0.0, 0.0);
    for (k, (light, (axis, cone))) in lights.iter().zip(cones).enumerate() {
        let reflected = |d: Vec3| light.eval(Vec3::ZERO, d).map_or(0.0, |h| (h.radiance * sp.eval(d)).x as f64);
        let e = integrate_cone_jittered(axis, cone, 400, 40 + k as u64, reflected);
        (expected, bound) = (expected + e, bound + 3e-3 * e);
    }
    with_set(&lights, |set| {
        let mut rays = Unoccluded { lights: &lights, p: Vec3::ZERO };
        let (got, se) = mean_of(5, |u, v| light_pair(set, Vec3::ZERO, &sp, u, v, &mut rays));
        assert!((got - expected).abs() <= 4.0 * se + bound, "{got} against {expected} (4σ {})", 4.0 * se);
        // The BRDF sample alone finds only part of it: its weight leaves the rest to the lights.
        let mut rays = Unoccluded { lights: &lights, p: Vec3::ZERO };
        let (brdf_part, _) = mean_of(6, |_, v| brdf_sample(set, Vec3::ZERO, &sp, v, &mut rays));
        assert!(brdf_part > 0.0 && brdf_part < got);
    });
    // A point light facing the surface: one sample is exact.
    let point = [SceneLight::from(PointLight::new(Vec3::new(0.0, 0.0, 2.0), Vec3::splat(8.0)).unwrap())];
    let lambert = Lambert::new(Vec3::splat(0.5));
    let flat = ShadingPoint { frame: Frame::from_normal(Vec3::Z), wo: Vec3::Z, brdf: &lambert };
    with_set(&point, |set| {
        let mut rays = Unoccluded { lights: &point, p: Vec3::ZERO };
        let v = light_pair(set, Vec3::ZERO, &flat, DVec2::new(0.3, 0.6), Vec2::new(0.2, 0.9), &mut rays);
        let exact = 0.5 / std::f64::consts::PI * 8.0 / 4.0;
        assert!((v.x - exact).abs() < 1e-6 * exact, "{} against {exact}", v.x);
    });
}
