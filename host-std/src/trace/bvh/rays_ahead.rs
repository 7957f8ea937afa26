//! Shadow rays over t ∈ (0, ∞), the interval of every environment shadow ray, as structure of
//! arrays: a row per coordinate of the origins and of the directions, which
//! [`Bvh::occluded_ahead_many`](super::Bvh::occluded_ahead_many) reads eight rays to a register.

use sampler_core::glam::Vec3;

/// Rays per row block: the rows' lengths are whole blocks, so that the last rays read a full
/// register (the entries past the last ray are stale and their answers are not used).
pub(super) const BLOCK: usize = 8;

/// A list of rays over t ∈ (0, ∞), reused from batch to batch.
#[derive(Clone, Debug, Default)]
pub struct RaysAhead {
    origin: [Vec<f32>; 3],
    dir: [Vec<f32>; 3],
    len: usize,
}

impl RaysAhead {
    /// Empties the list and makes room for `n` rays: [`RaysAhead::push_if`] of up to `n` rays
    /// then allocates nothing (the rows only grow).
    pub fn clear_for(&mut self, n: usize) {
        self.grow_rows(n);
        self.len = 0;
    }

    /// Rows long enough for `n` rays, in whole blocks.
    fn grow_rows(&mut self, n: usize) {
        let room = n.div_ceil(BLOCK).max(1) * BLOCK;
        for row in self.origin.iter_mut().chain(&mut self.dir) {
            if row.len() < room {
                row.resize(room, 0.0);
            }
        }
    }

    /// Writes the ray from `o` along `d` after the last and keeps it where `keep`: a list
    /// compacted without a branch on which rays are kept. Panics where the list has no room
    /// for it ([`RaysAhead::clear_for`]).
    #[inline]
    pub fn push_if(&mut self, o: Vec3, d: Vec3, keep: bool) {
        let k = self.len;
        for a in 0..3 {
            (self.origin[a][k], self.dir[a][k]) = (o[a], d[a]);
        }
        self.len += usize::from(keep);
    }

    /// Appends the ray from `o` along `d`, making room for it.
    pub fn push(&mut self, o: Vec3, d: Vec3) {
        if self.origin[0].len() <= self.len {
            self.grow_rows(2 * self.len + BLOCK);
        }
        self.push_if(o, d, true);
    }

    /// The number of rays.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the list has no ray.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Ray `k`: its origin and direction.
    #[must_use]
    pub fn ray(&self, k: usize) -> (Vec3, Vec3) {
        assert!(k < self.len, "ray {k} of {}", self.len);
        let at = |rows: &[Vec<f32>; 3]| Vec3::new(rows[0][k], rows[1][k], rows[2][k]);
        (at(&self.origin), at(&self.dir))
    }

    /// The block of rows from ray `first` (a multiple of [`BLOCK`] below the length): origins
    /// and directions, a row per coordinate.
    #[cfg(target_arch = "x86_64")]
    pub(super) fn block(&self, first: usize) -> ([&[f32; BLOCK]; 3], [&[f32; BLOCK]; 3]) {
        debug_assert!(first.is_multiple_of(BLOCK) && first < self.len, "block from {first} of {}", self.len);
        (block_of(&self.origin, first), block_of(&self.dir, first))
    }
}

/// The block of three rows from entry `first` (the rows are whole blocks long).
#[cfg(target_arch = "x86_64")]
fn block_of(rows: &[Vec<f32>; 3], first: usize) -> [&[f32; BLOCK]; 3] {
    rows.each_ref().map(|r| r[first..first + BLOCK].try_into().expect("a slice of BLOCK entries"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_rays_are_compacted_in_order() {
        let mut rays = RaysAhead::default();
        rays.clear_for(5);
        for k in 0..5 {
            rays.push_if(Vec3::splat(k as f32), Vec3::X * k as f32, k % 2 == 0);
        }
        assert_eq!(rays.len(), 3);
        assert_eq!(rays.ray(1), (Vec3::splat(2.0), Vec3::X * 2.0));
        assert_eq!(rays.ray(2), (Vec3::splat(4.0), Vec3::X * 4.0));
        for k in 0..20 {
            rays.push(Vec3::Y, Vec3::Z * k as f32);
        }
        assert_eq!(rays.len(), 23);
        assert_eq!(rays.ray(2).0, Vec3::splat(4.0), "growing keeps the rays");
        assert_eq!(rays.ray(22), (Vec3::Y, Vec3::Z * 19.0));
    }
}
