//! A distant light of angular size moved into the environment map: its disc rasterised into the
//! texels it covers (each by the fraction of it inside the disc, from 8 × 8 points per texel:
//! the equal-area texels all subtend the same solid angle, so coverage × radiance keeps the
//! light's power), and the pyramid rebuilt, so that the map's samplers — the product among them —
//! sample sun × BRDF together instead of the sun by its own cone. The disc's outline is then
//! the texels', not exact: what the image gains or loses by it is measured in docs/tuning.md,
//! "A sun in the map or by its cone".

use crate::light::environment::Environment;
use sampler_core::env::build_pyramid;
use sampler_core::glam::{Vec2, Vec3};
use sampler_core::light::{DistantLight, Light, SceneLight};
use sampler_core::mapping::square_to_sphere;

/// Points per texel edge for the coverage.
const SUBSAMPLES: usize = 8;

impl Environment {
    /// Adds `light` (a distant light with an angular size; a delta light is left alone and
    /// `false` returned) to the map.
    pub fn add_distant(&mut self, light: &DistantLight) -> bool {
        if light.is_delta() {
            return false;
        }
        let radiance = light.radiance();
        let axis = self.map_to_world.transpose() * light.direction();
        let n = 1usize << self.level;
        // Texels whose centre lies within the cone widened by two texels' width can be touched.
        let texel_angle = (4.0 * std::f32::consts::PI / (n * n) as f32).sqrt();
        let cos_reach = (light.half_angle() + 2.0 * texel_angle).min(std::f32::consts::PI).cos();
        let world = self.map_to_world;
        for y in 0..n {
            for x in 0..n {
                let centre = Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
                if square_to_sphere(centre).dot(axis) < cos_reach {
                    continue;
                }
                let mut inside = 0usize;
                for j in 0..SUBSAMPLES {
                    for i in 0..SUBSAMPLES {
                        let u = Vec2::new(
                            (x as f32 + (i as f32 + 0.5) / SUBSAMPLES as f32) / n as f32,
                            (y as f32 + (j as f32 + 0.5) / SUBSAMPLES as f32) / n as f32,
                        );
                        let d = world * square_to_sphere(u);
                        inside += usize::from(light.eval(Vec3::ZERO, d.normalize()).is_some());
                    }
                }
                if inside > 0 {
                    let f = inside as f32 / (SUBSAMPLES * SUBSAMPLES) as f32;
                    let t = &mut self.rgb[y * n + x];
                    for c in 0..3 {
                        t[c] += f * radiance[c];
                    }
                }
            }
        }
        build_pyramid(self.level, &self.rgb, &mut self.pyramid).expect("the map's own level and buffers");
        true
    }
}

/// Moves every distant light with an angular size out of `lights` into `env`; returns how many.
pub fn move_distant_lights(lights: &mut Vec<SceneLight>, env: &mut Environment) -> usize {
    let before = lights.len();
    lights.retain(|l| match l {
        SceneLight::Distant(d) => !env.add_distant(d),
        _ => true,
    });
    before - lights.len()
}
