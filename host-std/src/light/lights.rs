//! A scene's lights besides the environment, ready for a render: the core's lights and how one
//! is picked for a shading point — by a light tree over the lights with a position (each subtree
//! in proportion to its importance for the point: power, distance, orientation), beside the
//! lights at infinity in proportion to power (a distant light's power is what crosses the
//! scene's bounding disk) — and the distant lights with an angular size, which rays that leave
//! the scene receive.

use sampler_core::estimator::lights::LightSet;
use sampler_core::estimator::luminance64;
use sampler_core::light::{Light, LightBounds, LightNode, LightTree, PowerSelector, SceneLight};

/// How lights are picked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LightSelection {
    /// A light tree for the lights with a position (the default).
    #[default]
    Tree,
    /// In proportion to power, wherever the shading point is.
    Power,
}

/// How a render samples the lights besides the environment, and how the seed's baselines
/// (`--method sis`, `--method lightcuts`) turn the lights into theirs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightOptions {
    /// How a light is picked.
    pub selection: LightSelection,
    /// Where the scene has an environment too, the share of each shading point's visibility
    /// samples spent on these lights (at least one sample each way).
    pub share: f64,
    /// Strata of structured importance sampling (`--sis-lights`).
    pub sis_lights: usize,
    /// Lightcuts' relative error bound per cluster (`--lightcut-error`).
    pub lightcut_error: f32,
}

impl Default for LightOptions {
    fn default() -> Self {
        Self {
            selection: LightSelection::Tree,
            share: 0.5,
            sis_lights: sampler_core::sis::DEFAULT_LIGHTS,
            lightcut_error: sampler_core::lightcuts::DEFAULT_ERROR,
        }
    }
}

/// The lights and their selection, kept for a render.
pub struct LightTable<'a> {
    lights: &'a [SceneLight],
    /// Power: the CDF over every light. Tree: over the tree and the lights at infinity.
    cdf: Vec<f64>,
    tree: Option<(Vec<LightNode>, Vec<u64>)>,
    distant: Vec<u32>,
    infinite: Vec<u32>,
}

impl<'a> LightTable<'a> {
    /// The table of `lights` in a scene of bounding radius `scene_radius`, picked as
    /// `selection` says; `None` when no light emits (then no light is sampled; the lights'
    /// surfaces still occlude).
    #[must_use]
    pub fn new(lights: &'a [SceneLight], scene_radius: f32, selection: LightSelection) -> Option<Self> {
        let power = |l: &SceneLight| luminance64(l.power(scene_radius).as_dvec3()).max(0.0) as f32;
        let infinite: Vec<u32> = (0..lights.len() as u32).filter(|&i| lights[i as usize].is_infinite_area()).collect();
        if selection == LightSelection::Tree
            && let Some(table) = Self::with_tree(lights, &power, &infinite)
        {
            return Some(table);
        }
        let weights: Vec<f32> = lights.iter().map(power).collect();
        let mut cdf = vec![0.0; lights.len() + 1];
        PowerSelector::build(&weights, &mut cdf)?;
        Some(Self { lights, cdf, tree: None, distant: Vec::new(), infinite })
    }

    /// The tree over the lights with a position, and the lights at infinity beside it; `None`
    /// when no light with a position emits.
    fn with_tree(lights: &'a [SceneLight], power: &impl Fn(&SceneLight) -> f32, infinite: &[u32]) -> Option<Self> {
        let bounds: Vec<Option<LightBounds>> = lights.iter().map(LightBounds::of).collect();
        let count = bounds.iter().filter(|b| b.is_some()).count();
        if count == 0 {
            return None;
        }
        let mut order = vec![0u32; count];
        let mut nodes =
            vec![LightNode { bounds: bounds.iter().flatten().next()?.to_owned(), index: 0, leaf: true }; 2 * count - 1];
        let mut paths = vec![0u64; lights.len()];
        let tree = LightTree::build(&bounds, &mut order, &mut nodes, &mut paths).ok()?;
        let (used, root_power) = (tree.nodes().len(), tree.root().power);
        nodes.truncate(used);
        let distant: Vec<u32> =
            (0..lights.len() as u32).filter(|&i| matches!(lights[i as usize], SceneLight::Distant(_))).collect();
        let weights: Vec<f32> =
            std::iter::once(root_power).chain(distant.iter().map(|&i| power(&lights[i as usize]))).collect();
        let mut cdf = vec![0.0; weights.len() + 1];
        PowerSelector::build(&weights, &mut cdf)?;
        Some(Self { lights, cdf, tree: Some((nodes, paths)), distant, infinite: infinite.to_vec() })
    }

    /// The set the estimators sample.
    #[must_use]
    pub fn set(&self) -> LightSet<'_> {
        let selector = PowerSelector::from_cdf(&self.cdf).expect("built by PowerSelector::build");
        match &self.tree {
            None => LightSet::new(self.lights, selector, &self.infinite),
            Some((nodes, paths)) => {
                let tree = LightTree::from_parts(nodes, paths).expect("built by LightTree::build");
                LightSet::with_tree(self.lights, tree, selector, &self.distant, &self.infinite)
            }
        }
        .expect("built over these lights")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sampler_core::glam::Vec3;
    use sampler_core::light::{DistantLight, PointLight, SphereLight};

    #[test]
    fn lights_are_picked_by_power_or_by_tree_and_dark_scenes_have_no_table() {
        let lights: Vec<SceneLight> = vec![
            PointLight::new(Vec3::ZERO, Vec3::splat(1.0)).unwrap().into(),
            PointLight::new(Vec3::ONE, Vec3::splat(3.0)).unwrap().into(),
            DistantLight::new(Vec3::Z, Vec3::ONE, 0.01).unwrap().into(),
            SphereLight::new(Vec3::X, 0.5, Vec3::ZERO).unwrap().into(),
        ];
        let (p, n) = (Vec3::new(0.3, 0.2, -2.0), Vec3::Z);
        let power = LightTable::new(&lights, 10.0, LightSelection::Power).unwrap();
        let set = power.set();
        // Point lights' power is 4πI; the distant light's E·π r².
        let (a, b, c) = (4.0 * std::f64::consts::PI, 12.0 * std::f64::consts::PI, 100.0 * std::f64::consts::PI);
        let total = a + b + c;
        for (i, expect) in [a / total, b / total, c / total, 0.0].into_iter().enumerate() {
            assert!((set.pmf(i, p, n) - expect).abs() < 1e-6, "{i}");
        }
        assert!(set.has_area_lights());
        // By tree: the distant light keeps its share of power, the point lights share the rest
        // by importance, and the probabilities sum to one.
        let tree = LightTable::new(&lights, 10.0, LightSelection::Tree).unwrap();
        let set = tree.set();
        assert!((set.pmf(2, p, n) - c / total).abs() < 1e-6);
        let sum: f64 = (0..4).map(|i| set.pmf(i, p, n)).sum();
        assert!((sum - 1.0).abs() < 1e-6, "{sum}");
        let dark = [SceneLight::from(SphereLight::new(Vec3::X, 0.5, Vec3::ZERO).unwrap())];
        assert!(LightTable::new(&dark, 1.0, LightSelection::Tree).is_none());
    }
}
