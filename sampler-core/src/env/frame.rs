//! The environment map's frame: world directions to and from the map's frame and the
//! equal-area square, one at a time and four lanes at a time with the same bits.

use super::EnvHierarchy;
use crate::mapping::{sphere_to_square, sphere_to_square_batch, square_to_sphere, square_to_sphere_batch};
use glam::{Mat3, Vec2, Vec3};

impl EnvHierarchy<'_> {
    /// The rotation taking world directions to the map's frame.
    #[inline]
    #[must_use]
    pub fn world_to_map(&self) -> Mat3 {
        self.world_to_map
    }

    /// World direction → map direction.
    #[inline]
    #[must_use]
    pub fn to_map(&self, world: Vec3) -> Vec3 {
        self.world_to_map * world
    }

    /// Map direction → world direction.
    #[inline]
    #[must_use]
    pub fn to_world(&self, map: Vec3) -> Vec3 {
        self.map_to_world * map
    }

    /// Point of the equal-area square seen in world direction `dir`.
    #[inline]
    #[must_use]
    pub fn square_of(&self, dir: Vec3) -> Vec2 {
        sphere_to_square(self.to_map(dir))
    }

    /// World direction of a point of the square.
    #[inline]
    #[must_use]
    pub fn dir_of(&self, uv: Vec2) -> Vec3 {
        self.to_world(square_to_sphere(uv))
    }

    /// [`dir_of`](Self::dir_of) for every point of `uv` (as many as both hold), four lanes at a
    /// time, bit for bit.
    pub fn dirs_of(&self, uv: &[Vec2], out: &mut [Vec3]) {
        let n = uv.len().min(out.len());
        square_to_sphere_batch(&uv[..n], &mut out[..n]);
        for d in &mut out[..n] {
            *d = self.to_world(*d);
        }
    }

    /// [`square_of`](Self::square_of) for every direction of `dirs` (as many as both hold), four
    /// lanes at a time, bit for bit.
    pub fn squares_of(&self, dirs: &[Vec3], out: &mut [Vec2]) {
        for (ds, os) in dirs.chunks(16).zip(out.chunks_mut(16)) {
            let n = ds.len().min(os.len());
            let mut local = [Vec3::ZERO; 16];
            for (l, d) in local.iter_mut().zip(ds) {
                *l = self.to_map(*d);
            }
            sphere_to_square_batch(&local[..n], &mut os[..n]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::build_pyramid;

    #[test]
    fn batched_directions_and_points_are_bit_identical() {
        let rgb = [[1.0f32; 3]; 16];
        let mut p = [0.0f32; 21];
        build_pyramid(2, &rgb, &mut p).unwrap();
        let e = EnvHierarchy::new(2, &p, &rgb)
            .unwrap()
            .with_rotation(Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.3));
        let mut uv = [Vec2::ZERO; 67];
        for (k, u) in uv.iter_mut().enumerate() {
            *u = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 * 0.754_877_7).fract());
        }
        let mut dirs = [Vec3::ZERO; 67];
        e.dirs_of(&uv, &mut dirs);
        let mut back = [Vec2::ZERO; 67];
        e.squares_of(&dirs, &mut back);
        for k in 0..uv.len() {
            assert_eq!(dirs[k].to_array().map(f32::to_bits), e.dir_of(uv[k]).to_array().map(f32::to_bits));
            assert_eq!(back[k].to_array().map(f32::to_bits), e.square_of(dirs[k]).to_array().map(f32::to_bits));
        }
    }
}
