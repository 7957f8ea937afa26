//! A scene's lights besides the environment, ready for a render: the core's lights, the
//! distribution that picks one in proportion to its power (as luminance; a distant light's
//! power is what crosses the scene's bounding disk), and the distant lights with an angular size,
//! which rays that leave the scene receive.

use sampler_core::estimator::lights::LightSet;
use sampler_core::estimator::luminance64;
use sampler_core::light::{Light, PowerSelector, SceneLight};

/// The lights and their selection, kept for a render.
pub struct LightTable<'a> {
    lights: &'a [SceneLight],
    cdf: Vec<f64>,
    infinite: Vec<u32>,
}

impl<'a> LightTable<'a> {
    /// The table of `lights` in a scene of bounding radius `scene_radius`; `None` when no light
    /// emits (then no light is sampled; the lights' surfaces still occlude).
    #[must_use]
    pub fn new(lights: &'a [SceneLight], scene_radius: f32) -> Option<Self> {
        let weights: Vec<f32> =
            lights.iter().map(|l| luminance64(l.power(scene_radius).as_dvec3()).max(0.0) as f32).collect();
        let mut cdf = vec![0.0; lights.len() + 1];
        PowerSelector::build(&weights, &mut cdf)?;
        let infinite = (0..lights.len() as u32).filter(|&i| lights[i as usize].is_infinite_area()).collect();
        Some(Self { lights, cdf, infinite })
    }

    /// The set the estimators sample.
    #[must_use]
    pub fn set(&self) -> LightSet<'_> {
        let selector = PowerSelector::from_cdf(&self.cdf).expect("built by PowerSelector::build");
        LightSet::new(self.lights, selector, &self.infinite).expect("built over these lights")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sampler_core::glam::Vec3;
    use sampler_core::light::{DistantLight, PointLight, SphereLight};

    #[test]
    fn lights_are_picked_by_power_and_dark_scenes_have_no_table() {
        let lights: Vec<SceneLight> = vec![
            PointLight::new(Vec3::ZERO, Vec3::splat(1.0)).unwrap().into(),
            PointLight::new(Vec3::ONE, Vec3::splat(3.0)).unwrap().into(),
            DistantLight::new(Vec3::Z, Vec3::ONE, 0.01).unwrap().into(),
            SphereLight::new(Vec3::X, 0.5, Vec3::ZERO).unwrap().into(),
        ];
        let table = LightTable::new(&lights, 10.0).unwrap();
        let set = table.set();
        // Point lights' power is 4πI; the distant light's E·π r².
        let (a, b, c) = (4.0 * std::f64::consts::PI, 12.0 * std::f64::consts::PI, 100.0 * std::f64::consts::PI);
        let total = a + b + c;
        for (i, expect) in [a / total, b / total, c / total, 0.0].into_iter().enumerate() {
            assert!((set.pick_probability(i) - expect).abs() < 1e-6, "{i}");
        }
        assert!(set.has_area_lights());
        let dark = [SceneLight::from(SphereLight::new(Vec3::X, 0.5, Vec3::ZERO).unwrap())];
        assert!(LightTable::new(&dark, 1.0).is_none());
    }
}
