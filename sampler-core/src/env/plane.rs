//! The map times a plane's cosine: the product a Lambertian surface of fixed normal integrates,
//! as an importance of the finest level. A pyramid built from it once per plane and side
//! ([`build_pyramid_from_importance`](super::build_pyramid_from_importance)) samples
//! radiance × cosine exactly, texel by texel, with nothing built per shading point: on such a
//! surface only visibility is left to vary the estimate.

use super::EnvHierarchy;
use super::pyramid::{EnvError, luminance};
use crate::cone::cell_radius_bound;
use crate::mapping::square_to_sphere;
use glam::{Vec2, Vec3};

impl<'a> EnvHierarchy<'a> {
    /// Writes the plane importance of the finest level's rows `first_row ..` into `out` (whole
    /// rows, row-major) for Lambertian surfaces whose normal lies within `tolerance` radians of
    /// the unit world direction `normal`. Each texel's luminance is weighted by
    /// - its centre's cosine to `normal` where the texel lies wholly above the plane,
    /// - the largest cosine within it where it straddles the horizon, so that every direction
    ///   above the plane keeps a density > 0,
    /// - 0 where it lies wholly below.
    ///
    /// Errors when `out` is not whole rows within the map.
    pub fn plane_importance_rows(
        &self,
        normal: Vec3,
        tolerance: f32,
        first_row: u32,
        out: &mut [f32],
    ) -> Result<(), EnvError> {
        let n = self.resolution() as usize;
        let rows = out.len() / n;
        if !out.len().is_multiple_of(n) || first_row as usize + rows > n {
            return Err(EnvError::WrongLength { buffer: "plane importance rows", expected: n, found: out.len() });
        }
        let normal = self.world_to_map * normal;
        let reach = (cell_radius_bound(self.finest) + tolerance.max(0.0)).min(core::f32::consts::FRAC_PI_2);
        let (sin_r, cos_r) = (libm::sinf(reach), libm::cosf(reach));
        let first = first_row as usize * n;
        for (i, w) in out.iter_mut().enumerate() {
            let (x, y) = (i % n, first_row as usize + i / n);
            let centre = square_to_sphere(Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32));
            let c = normal.dot(centre).clamp(-1.0, 1.0);
            let weight = if c >= sin_r {
                c
            } else if c <= -sin_r {
                0.0
            } else {
                // cos(θ − reach): the nearest the texel comes to the normal.
                c * cos_r + libm::sqrtf(1.0 - c * c) * sin_r
            };
            *w = luminance(Vec3::from_array(self.radiance[first + i])) * weight;
        }
        Ok(())
    }

    /// This view sampled ∝ `pyramid` instead (a pyramid of the same finest level, e.g. of
    /// [`plane_importance_rows`](Self::plane_importance_rows)): the same radiance, orientation,
    /// tint and MIS heuristic, without a texel table or a compensated pyramid.
    pub fn with_importance(&self, pyramid: &'a [f32]) -> Result<Self, EnvError> {
        let fresh = Self::new(self.finest, pyramid, self.radiance)?;
        let mut view = *self;
        (view.pyramid, view.inv_mean, view.cdf, view.compensated) = (pyramid, fresh.inv_mean, None, None);
        Ok(view)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{build_pyramid, build_pyramid_from_importance, pyramid_len};
    use crate::rng::Pcg32;

    #[test]
    fn every_texel_reaching_above_the_plane_keeps_weight_and_the_rest_none() {
        let level = 6;
        let n = 1usize << level;
        let rgb = [[1.0f32; 3]; 1 << 12];
        let mut pyramid = [0.0f32; pyramid_len(6)];
        build_pyramid(level, &rgb, &mut pyramid).unwrap();
        let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
        let mut rng = Pcg32::new(9, 9);
        let mut w = [0.0f32; 1 << 12];
        let reach = cell_radius_bound(level);
        for _ in 0..8 {
            let normal = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            env.plane_importance_rows(normal, 0.0, 0, &mut w).unwrap();
            for (i, &weight) in w.iter().enumerate() {
                let corner = Vec2::new((i % n) as f32, (i / n) as f32);
                let mut above = false;
                for _ in 0..64 {
                    let d = square_to_sphere((corner + Vec2::new(rng.next_f32(), rng.next_f32())) / n as f32);
                    above |= normal.dot(d) > 0.0;
                    // The cosine across the texel, within the texel's reach of the weight.
                    let off = (weight - normal.dot(d).max(0.0)).abs();
                    assert!(off <= 2.0 * reach, "texel {i}: weight {weight}, cosine {}", normal.dot(d));
                }
                if above {
                    assert!(weight > 0.0, "texel {i} reaches above the plane but has no weight");
                }
            }
        }
    }

    #[test]
    fn the_view_keeps_the_radiance_and_orientation_and_samples_the_new_pyramid() {
        let level = 3;
        let rgb: [[f32; 3]; 64] = core::array::from_fn(|i| [i as f32, 1.0, 2.0]);
        let (mut plain, mut plane) = ([0.0f32; pyramid_len(3)], [0.0f32; pyramid_len(3)]);
        build_pyramid(level, &rgb, &mut plain).unwrap();
        let rotation = glam::Mat3::from_rotation_y(0.7);
        let env = EnvHierarchy::new(level, &plain, &rgb).unwrap().with_rotation(rotation);
        let mut w = [0.0f32; 64];
        env.plane_importance_rows(Vec3::Y, 0.0, 0, &mut w[..32]).unwrap();
        env.plane_importance_rows(Vec3::Y, 0.0, 4, &mut w[32..]).unwrap();
        assert!(env.plane_importance_rows(Vec3::Y, 0.0, 5, &mut w[..32]).is_err(), "rows past the map");
        assert!(env.plane_importance_rows(Vec3::Y, 0.0, 0, &mut w[..7]).is_err(), "part of a row");
        build_pyramid_from_importance(level, &w, &mut plane).unwrap();
        let view = env.with_importance(&plane).unwrap();
        for d in [Vec3::Y, Vec3::X, Vec3::new(0.3, 0.4, -0.5).normalize()] {
            assert_eq!(view.radiance(d), env.radiance(d));
        }
        let below = -Vec3::Y;
        assert_eq!(view.pdf(below), 0.0);
        assert!(view.pdf(Vec3::Y) > 0.0);
    }
}
