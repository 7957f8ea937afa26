//! The lights of the seed's baselines, built once per render: structured importance sampling's
//! strata of the map (`--method sis`), and Lightcuts' light tree over the map's directional
//! lights and the scene's point lights and delta distant lights (`--method lightcuts`).
//!
//! Lightcuts represents point lights and directional lights only. The scene's other lights
//! (spheres, rectangles, disks, mesh triangles, distant lights with an angular size) stay with
//! the standard lights' estimator, as under every other method: [`LightcutTable::rest`] is the
//! scene's light list with the lights the tree took made dark in place (so that the indices the
//! BVH's emitter surfaces carry still name the same lights).

use sampler_core::env::EnvHierarchy;
use sampler_core::glam::Vec3;
use sampler_core::light::{Light, PointLight, SceneLight};
use sampler_core::lightcuts::{CutLight, CutLightKind, CutNode, DEFAULT_ENV_LIGHTS, LightcutTree};
use sampler_core::sis::{SisBuffers, Stratum, build_strata, cells_len};

/// The strata of `env`: at most `n` (fewer only on maps of fewer cells), the dark ones left
/// out (they light nothing).
#[must_use]
pub fn sis_strata(env: &EnvHierarchy<'_>, n: usize) -> Vec<Stratum> {
    let m = cells_len(env);
    let (mut dirs, mut nearest, mut labels) = (vec![Vec3::ZERO; m], vec![0.0; m], vec![0u32; m]);
    let mut intensity = vec![0.0f32; m];
    let mut strata = vec![Stratum::default(); n.max(1)];
    let buffers = SisBuffers {
        dirs: &mut dirs,
        intensity: &mut intensity,
        nearest: &mut nearest,
        labels: &mut labels,
        strata: &mut strata,
    };
    let count = build_strata(env, buffers).expect("buffers sized by cells_len, at least one stratum");
    strata.truncate(count);
    strata.retain(|s| s.irradiance.max_element() > 0.0);
    strata
}

/// Lightcuts' lights and tree, and the lights left to the standard estimator.
pub struct LightcutTable {
    lights: Vec<CutLight>,
    nodes: Vec<CutNode>,
    roots: [Option<u32>; 2],
    /// The scene's lights with the ones the tree holds made dark.
    pub rest: Vec<SceneLight>,
    /// The scene has lights the tree does not hold (area lights, distant lights with a size).
    pub has_rest: bool,
}

impl LightcutTable {
    /// The tree over `env`'s [`DEFAULT_ENV_LIGHTS`] strata and the unshaped point lights and
    /// delta distant lights of `scene_lights`.
    #[must_use]
    pub fn new(env: Option<&EnvHierarchy<'_>>, scene_lights: &[SceneLight]) -> Self {
        let mut lights: Vec<CutLight> = env
            .map(|e| sis_strata(e, DEFAULT_ENV_LIGHTS))
            .unwrap_or_default()
            .iter()
            .map(|s| CutLight { kind: CutLightKind::Directional, at: s.dir, intensity: s.irradiance.as_vec3() })
            .collect();
        let mut rest = scene_lights.to_vec();
        let dark = PointLight::new(Vec3::ZERO, Vec3::ZERO).expect("a dark point light at the origin is valid");
        for light in &mut rest {
            let taken = match light {
                // Lightcuts' bounds take a point light as isotropic: a shaped one (a cone, a
                // focus, an IES profile) stays with the other lights.
                SceneLight::Point(p) if p.shaping().is_none() => {
                    Some(CutLight { kind: CutLightKind::Point, at: p.position(), intensity: p.intensity() })
                }
                SceneLight::Distant(d) if d.is_delta() => {
                    Some(CutLight { kind: CutLightKind::Directional, at: d.direction(), intensity: d.irradiance() })
                }
                _ => None,
            };
            if let Some(l) = taken {
                lights.push(l);
                *light = dark.into();
            }
        }
        let has_rest = rest.iter().any(|l| l.power(1.0).max_element() > 0.0);
        let mut order = vec![0u32; lights.len()];
        let mut nodes = vec![CutNode::default(); LightcutTree::nodes_len(lights.len())];
        let (roots, used) = {
            let tree = LightcutTree::build(&lights, &mut order, &mut nodes).expect("buffers sized for the lights");
            (tree.roots(), tree.nodes().len())
        };
        nodes.truncate(used);
        Self { lights, nodes, roots, rest, has_rest }
    }

    /// The tree.
    #[must_use]
    pub fn tree(&self) -> LightcutTree<'_> {
        LightcutTree::from_parts(&self.lights, &self.nodes, self.roots).expect("built by LightcutTree::build")
    }
}
