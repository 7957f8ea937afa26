//! The map times a plane's cosine: the product a Lambertian surface of fixed normal integrates,
//! as an importance of the finest level. A pyramid built from it once per plane and side
//! ([`build_pyramid_from_importance`](super::build_pyramid_from_importance)) samples
//! radiance × cosine exactly, texel by texel, with nothing built per shading point: on such a
//! surface only visibility is left to vary the estimate.

use super::EnvHierarchy;
use super::pyramid::{EnvError, luminance};
use crate::cone::cell_radius_bound;
use crate::mapping::{square_to_sphere, square_to_sphere_x4};
use glam::{Vec2, Vec3, Vec4};

/// The level whose cell centres the cosine is evaluated at: texels of a coarser map average
/// the cosine over their share of these points, texels of a finer one share their cell's. A
/// 1024² grid holds the cosine to a few thousandths of its value away from the horizon, and
/// bounds the work at a million directions whatever the map's size.
pub const COSINE_LEVEL: u32 = 10;

impl<'a> EnvHierarchy<'a> {
    /// Writes the plane importance of the finest level's rows `first_row ..` into `out` (whole
    /// rows, row-major) for Lambertian surfaces whose normal lies within `tolerance` radians of
    /// the unit world direction `normal`. Each texel's luminance is weighted by the cosine to
    /// `normal` of the cell it is read at (the texel, or its cell of [`COSINE_LEVEL`] in a finer
    /// map):
    /// - where the cell lies wholly above the plane, the cosine's mean over the cell's points of
    ///   [`COSINE_LEVEL`] (its centre's, in a map that fine or finer);
    /// - where it straddles the horizon, the mean of the cosine's positive part over points of
    ///   it, but at least a sixteenth of the largest cosine within it, so that every direction
    ///   above the plane keeps a density > 0;
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
        let cells = CosineCells::new(self.finest, self.world_to_map * normal, tolerance);
        // A finer map's texels share their cell's weight: one row of cells at a time.
        let mut row = [0.0f32; 1 << COSINE_LEVEL];
        let mut row_of: Option<usize> = None;
        for (r, out_row) in out.chunks_exact_mut(n).enumerate() {
            let y = first_row as usize + r;
            let cy = y >> cells.shift;
            if row_of != Some(cy) {
                cells.row(cy, &mut row[..cells.side]);
                row_of = Some(cy);
            }
            let radiance = &self.radiance[y * n..(y + 1) * n];
            for (x, (w, rgb)) in out_row.iter_mut().zip(radiance).enumerate() {
                *w = luminance(Vec3::from_array(*rgb)) * row[x >> cells.shift];
            }
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

/// Points per side at which a cell across the horizon averages the cosine's positive part.
const HORIZON_POINTS: usize = 8;

/// The least weight of a cell across the horizon, as a share of the largest cosine within it:
/// a sliver above the horizon that the points miss keeps a density, at most this many times
/// below its share of the product.
const HORIZON_FLOOR: f32 = 1.0 / 16.0;

/// The cells the cosine is weighed over: the finest level's texels, or [`COSINE_LEVEL`]'s
/// cells in a finer map.
struct CosineCells {
    /// Cells per side.
    side: usize,
    /// Levels between the map's texels and the cells (0 for a map no finer than the cells).
    shift: u32,
    /// Points per cell side at which the cosine is averaged.
    points: usize,
    /// The plane's normal in the map's frame.
    normal: Vec3,
    /// sin and cos of a cell's reach: the angle within which its directions lie around its
    /// centre's, widened by the normals' tolerance.
    sin_reach: f32,
    cos_reach: f32,
}

impl CosineCells {
    fn new(finest: u32, normal: Vec3, tolerance: f32) -> Self {
        let level = finest.min(COSINE_LEVEL);
        let reach = (cell_radius_bound(level) + tolerance.max(0.0)).min(core::f32::consts::FRAC_PI_2);
        Self {
            side: 1 << level,
            shift: finest - level,
            points: 1 << (COSINE_LEVEL - level),
            normal,
            sin_reach: libm::sinf(reach),
            cos_reach: libm::cosf(reach),
        }
    }

    /// The weights of row `y`'s cells into `out` (one per cell): the centres' cosines four at
    /// a time, the same bits as one at a time.
    fn row(&self, y: usize, out: &mut [f32]) {
        let side = self.side as f32;
        let v = Vec4::splat((y as f32 + 0.5) / side);
        let [nx, ny, nz] = self.normal.to_array().map(Vec4::splat);
        for (k, chunk) in out.chunks_mut(4).enumerate() {
            let x0 = 4 * k;
            let u = Vec4::from_array(core::array::from_fn(|i| ((x0 + i) as f32 + 0.5) / side));
            let [dx, dy, dz] = square_to_sphere_x4(u, v);
            // `Vec3::dot`'s order of operations, lane by lane.
            let c = (nx * dx + ny * dy + nz * dz).to_array();
            for (i, w) in chunk.iter_mut().enumerate() {
                *w = self.weight(x0 + i, y, c[i].clamp(-1.0, 1.0));
            }
        }
    }

    /// The weight of cell (x, y), whose centre has cosine `c` to the normal (see
    /// [`EnvHierarchy::plane_importance_rows`]).
    fn weight(&self, x: usize, y: usize, c: f32) -> f32 {
        let at = |px: f32, py: f32| self.normal.dot(square_to_sphere(Vec2::new(px, py) / self.side as f32));
        let mean = |points: usize| {
            let step = 1.0 / points as f32;
            let mut sum = 0.0f32;
            for j in 0..points {
                for i in 0..points {
                    sum += at(x as f32 + (i as f32 + 0.5) * step, y as f32 + (j as f32 + 0.5) * step).max(0.0);
                }
            }
            sum * step * step
        };
        if c <= -self.sin_reach {
            0.0
        } else if c < self.sin_reach {
            // The mean over the part above the horizon, but at least a share of the largest
            // cosine within the cell, cos(θ − reach), where the points miss a sliver above it.
            let largest = c * self.cos_reach + libm::sqrtf(1.0 - c * c) * self.sin_reach;
            mean(self.points.max(HORIZON_POINTS)).max(largest * HORIZON_FLOOR)
        } else if self.points == 1 {
            c
        } else {
            mean(self.points)
        }
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
    fn a_row_of_cells_weighs_as_each_cell_alone() {
        let mut rng = Pcg32::new(3, 5);
        let mut row = [0.0f32; 1 << COSINE_LEVEL];
        for finest in [0, 1, 3, 6, 10, 11] {
            let normal = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let cells = CosineCells::new(finest, normal, 1e-3);
            for y in [0, cells.side / 3, cells.side - 1] {
                cells.row(y, &mut row[..cells.side]);
                for (x, w) in row[..cells.side].iter().enumerate() {
                    let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) / cells.side as f32;
                    let c = normal.dot(square_to_sphere(centre)).clamp(-1.0, 1.0);
                    assert_eq!(w.to_bits(), cells.weight(x, y, c).to_bits(), "level {finest}, cell ({x}, {y})");
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
