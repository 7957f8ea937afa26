//! Pinhole camera with the scene format's exact convention: f = normalize(target − origin),
//! r = normalize(f × up), u = r × f, t = tan(fov_y/2), a = W/H (times the pixel aspect ratio, 1 unless a USD stage's
//! render settings say otherwise); film position (x, y), x ∈ [0, W]
//! to the right, y ∈ [0, H] downwards, has direction normalize(f + (2x/W − 1)·t·a·r + (1 − 2y/H)·t·u).

use crate::scene::CameraSpec;
use sampler_core::glam::{Vec3, Vec3A};

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
}
