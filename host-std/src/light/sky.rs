//! The built-in procedural sky, generated at start-up so that the default render needs no
//! files: a blue gradient above the horizon, a dim ground below, and a sun disk of the real
//! sun's size (0.53°) whose radiance is 2·10⁵ × the zenith sky. Generated directly in the
//! equal-area square (Y up, the scene format's frame), the sun's edge antialiased by 4×4
//! coverage samples per texel.

use rayon::prelude::*;
use sampler_core::glam::{Vec2, Vec3};
use sampler_core::mapping::square_to_sphere;

/// Parameters of the sky.
#[derive(Clone, Copy, Debug)]
pub struct Sky {
    /// Unit direction towards the sun (world, Y up).
    pub sun: Vec3,
    /// Angular radius of the sun disk in radians.
    pub sun_radius: f32,
    /// Radiance of the sun disk.
    pub sun_radiance: Vec3,
    /// Sky radiance at the zenith.
    pub zenith: Vec3,
    /// Sky radiance at the horizon.
    pub horizon: Vec3,
    /// Radiance of the ground below the horizon.
    pub ground: Vec3,
}

impl Default for Sky {
    fn default() -> Self {
        let elevation = 35f32.to_radians();
        let azimuth = 40f32.to_radians();
        let sun = Vec3::new(elevation.cos() * azimuth.sin(), elevation.sin(), -elevation.cos() * azimuth.cos());
        Self {
            sun,
            sun_radius: 0.265f32.to_radians(),
            sun_radiance: Vec3::new(1.0, 0.92, 0.82) * 1.0e5,
            zenith: Vec3::new(0.12, 0.24, 0.5),
            horizon: Vec3::new(0.55, 0.62, 0.72),
            ground: Vec3::new(0.09, 0.085, 0.08),
        }
    }
}

impl Sky {
    /// Radiance of the sky (without the sun) in direction `d`.
    pub fn sky(&self, d: Vec3) -> Vec3 {
        if d.y >= 0.0 {
            let t = d.y.powf(0.4);
            self.horizon.lerp(self.zenith, t)
        } else {
            self.ground
        }
    }

    /// The sky as a `2^level` equal-area map.
    pub fn equal_area(&self, level: u32) -> Vec<[f32; 3]> {
        let n = 1usize << level;
        let cos_sun = self.sun_radius.cos();
        let mut out = vec![[0.0f32; 3]; n * n];
        out.par_chunks_mut(n).enumerate().for_each(|(y, row)| {
            for (x, texel) in row.iter_mut().enumerate() {
                let centre = square_to_sphere(Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32));
                let mut radiance = self.sky(centre);
                // Only texels near the sun need the coverage samples.
                if centre.dot(self.sun) > (self.sun_radius * 4.0 + 8.0 / n as f32).cos() {
                    let mut covered = 0;
                    for s in 0..16 {
                        let p = Vec2::new(
                            (x as f32 + ((s % 4) as f32 + 0.5) / 4.0) / n as f32,
                            (y as f32 + ((s / 4) as f32 + 0.5) / 4.0) / n as f32,
                        );
                        covered += usize::from(square_to_sphere(p).dot(self.sun) >= cos_sun);
                    }
                    radiance += self.sun_radiance * (covered as f32 / 16.0);
                }
                *texel = radiance.to_array();
            }
        });
        out
    }
}
