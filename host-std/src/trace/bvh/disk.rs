//! Disks, which only disk lights make: few per scene, so they are tested one by one beside the
//! hierarchy rather than given a lane layout of their own.

use sampler_core::glam::Vec3;

/// A disk of the scene.
#[derive(Clone, Copy, Debug)]
pub(super) struct Disk {
    pub(super) center: Vec3,
    /// Unit normal of the front side.
    pub(super) normal: Vec3,
    pub(super) radius_squared: f32,
    /// Its surface's id ([`super::Surface::id`]).
    pub(super) surface: u32,
}

impl Disk {
    /// Distance along o + t·d to the disk, if the ray meets it within (t_min, t_max).
    #[inline]
    pub(super) fn intersect(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
        let t = (self.center - o).dot(self.normal) / d.dot(self.normal);
        if !(t > t_min && t < t_max) {
            return None;
        }
        let q = o + t * d - self.center;
        let along = q.dot(self.normal);
        (q.length_squared() - along * along <= self.radius_squared).then_some(t)
    }
}

/// The nearest disk hit within (t_min, t_max): its index and distance.
pub(super) fn closest(disks: &[Disk], o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<(usize, f32)> {
    let mut best = None;
    let mut t_max = t_max;
    for (k, disk) in disks.iter().enumerate() {
        if let Some(t) = disk.intersect(o, d, t_min, t_max) {
            (best, t_max) = (Some((k, t)), t);
        }
    }
    best
}
