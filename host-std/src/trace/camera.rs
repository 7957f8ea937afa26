//! Pinhole camera with the scene format's exact convention: f = normalize(target − origin),
//! r = normalize(f × up), u = r × f, t = tan(fov_y/2), a = W/H (times the pixel aspect ratio, 1 unless a USD stage's
//! render settings say otherwise); film position (x, y), x ∈ [0, W]
//! to the right, y ∈ [0, H] downwards, has direction normalize(f + (2x/W − 1)·t·a·r + (1 − 2y/H)·t·u).

use crate::scene::CameraSpec;
use crate::trace::bvh::F4;
use sampler_core::glam::{DVec2, Vec3, Vec3A};

/// A camera ready to make primary rays.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Eye position: where primary rays start.
    pub origin: Vec3,
    // In 16-byte lanes: a ray's direction is then one register, stored to the BVH's argument
    // whole rather than as a lane and a pair that the argument's load cannot be forwarded from.
    forward: Vec3A,
    right: Vec3A,
    up: Vec3A,
    tan_half: f32,
    aspect: f32,
    /// `width` and `height` as f32: the same values, converted once rather than per ray.
    film: (f32, f32),
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Distance below which primary hits are ignored.
    pub near_clip: f32,
}

impl Camera {
    /// The camera of `spec`.
    pub fn new(spec: &CameraSpec) -> Self {
        let forward = (spec.target - spec.origin).normalize();
        let right = forward.cross(spec.up).normalize();
        let up = right.cross(forward);
        Self {
            origin: spec.origin,
            forward: forward.into(),
            right: right.into(),
            up: up.into(),
            tan_half: (spec.fov_y_deg.to_radians() * 0.5).tan(),
            aspect: spec.width as f32 * spec.pixel_aspect / spec.height as f32,
            film: (spec.width as f32, spec.height as f32),
            width: spec.width,
            height: spec.height,
            near_clip: spec.near_clip,
        }
    }

    /// Unit direction through film position (x, y).
    pub fn direction(&self, x: f32, y: f32) -> Vec3 {
        let sx = (2.0 * x / self.film.0 - 1.0) * self.tan_half * self.aspect;
        let sy = (1.0 - 2.0 * y / self.film.1) * self.tan_half;
        let d = self.forward + sx * self.right + sy * self.up;
        // Times the reciprocal length, as `Vec3::normalize` does: the same bits.
        Vec3::from(d * (1.0 / d.length()))
    }

    /// [`direction`](Self::direction) through film position (x + f.x, y + f.y) for each `f` of
    /// `film` (offsets within pixel (x, y)), into `out` (one direction per position): the same
    /// operations in the same order, four rays at a time in `bvh::F4` lanes (SSE on x86-64) — the same bits.
    pub fn directions(&self, x: usize, y: usize, film: &[DVec2], out: &mut [Vec3]) {
        debug_assert_eq!(film.len(), out.len(), "one direction per film position");
        let (px, py) = (x as f32, y as f32);
        let s = F4::splat;
        for (fs, os) in film.chunks(4).zip(out.chunks_mut(4)) {
            let (mut fx, mut fy) = ([0.5f32; 4], [0.5f32; 4]);
            for (k, f) in fs.iter().enumerate() {
                (fx[k], fy[k]) = (px + f.x as f32, py + f.y as f32);
            }
            let tan_half = s(self.tan_half);
            let sx = s(2.0).mul(F4::load(&fx)).div(s(self.film.0)).sub(s(1.0)).mul(tan_half).mul(s(self.aspect));
            let sy = s(1.0).sub(s(2.0).mul(F4::load(&fy)).div(s(self.film.1))).mul(tan_half);
            let axis = |f: f32, r: f32, u: f32| s(f).add(sx.mul(s(r))).add(sy.mul(s(u)));
            let (f, r, u) = (self.forward, self.right, self.up);
            let d = [axis(f.x, r.x, u.x), axis(f.y, r.y, u.y), axis(f.z, r.z, u.z)];
            let inv_length = s(1.0).div(d[0].mul(d[0]).add(d[1].mul(d[1])).add(d[2].mul(d[2])).sqrt());
            let [dx, dy, dz] = d.map(|v| v.mul(inv_length).to_array());
            for (k, o) in os.iter_mut().enumerate() {
                *o = Vec3::new(dx[k], dy[k], dz[k]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sampler_core::rng::hash_combine;

    /// A number in [0, 1) from a hash.
    fn unit(h: u64) -> f64 {
        (h >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn batched_directions_are_the_one_ray_directions_bit_for_bit() {
        let specs = [
            (Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 256, 256, 1.0),
            (Vec3::new(-3.2, 0.4, 1.1), Vec3::new(0.5, 0.2, -0.7), Vec3::new(0.1, 1.0, 0.2), 75.0, 640, 360, 1.0),
            (Vec3::new(1e3, -20.0, 7.5), Vec3::new(1e3, -19.0, 9.0), Vec3::Z, 12.5, 97, 131, 1.5),
        ];
        let mut seen = 0;
        for (s, &(origin, target, up, fov_y_deg, width, height, pixel_aspect)) in specs.iter().enumerate() {
            let spec = CameraSpec { origin, target, up, fov_y_deg, width, height, pixel_aspect, near_clip: 0.0 };
            let camera = Camera::new(&spec);
            // Lengths that fill no chunk, one, and several with every remainder.
            for (p, n) in [1usize, 2, 3, 5, 6, 7, 8, 21, 64, 257].into_iter().enumerate() {
                let h = |k: usize, axis: u64| hash_combine((s * 100 + p) as u64, (k as u64) << 1 | axis);
                let (x, y) = ((h(999, 0) % u64::from(width)) as usize, (h(999, 1) % u64::from(height)) as usize);
                let film: Vec<DVec2> = (0..n).map(|k| DVec2::new(unit(h(k, 0)), unit(h(k, 1)))).collect();
                let mut out = vec![Vec3::NAN; n];
                camera.directions(x, y, &film, &mut out);
                for (f, d) in film.iter().zip(&out) {
                    let one = camera.direction(x as f32 + f.x as f32, y as f32 + f.y as f32);
                    assert_eq!(d.to_array().map(f32::to_bits), one.to_array().map(f32::to_bits), "{s} {x} {y} {f}");
                    seen += 1;
                }
            }
        }
        assert_eq!(seen, 3 * 374);
    }
}
