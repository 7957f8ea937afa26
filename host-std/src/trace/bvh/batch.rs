//! Rays in batches, as the renderer hands them over: a pixel group's camera rays from the
//! camera's origin, and a wavefront's shadow rays over t ∈ (0, ∞) ([`RaysAhead`]). In a scene that
//! is one leaf they go eight to a register (`ray_lanes/`); in a tree camera rays go through it
//! eight at a time as a packet (`ray_lanes/packet.rs`), shadow rays one by one.

#[cfg(target_arch = "x86_64")]
use super::ray_lanes;
use super::{Bvh, Hit, RaysAhead};
use sampler_core::glam::Vec3;

impl Bvh {
    /// [`Bvh::intersect`] of rays from one point `o` (a pinhole camera's) along each of `dirs`,
    /// t ∈ (t_min, ∞): `out[k]` is ray k's hit, bit for bit the one-at-a-time call's. In a scene
    /// that is one leaf, with no disk beside it, rays go eight to a register where the CPU has
    /// AVX2 (`ray_lanes/`); in a tree, eight at a time through it as a packet where their
    /// directions keep one sign per axis. Panics unless `out` has one entry per direction.
    pub fn intersect_from(&self, o: Vec3, dirs: &[Vec3], t_min: f32, out: &mut [Option<Hit>]) {
        assert_eq!(dirs.len(), out.len(), "intersect_from: one hit per ray");
        #[cfg(target_arch = "x86_64")]
        if let Some(leaf) = &self.lanes {
            const LANES: usize = ray_lanes::LANES;
            for (dirs, out) in dirs.chunks(LANES).zip(out.chunks_mut(LANES)) {
                let mut rows = [[0.0f32; LANES]; 3];
                for (k, d) in dirs.iter().enumerate() {
                    (rows[0][k], rows[1][k], rows[2][k]) = (d.x, d.y, d.z);
                }
                // SAFETY: `lanes` exists only where the CPU has AVX2.
                let (t, found) = unsafe { ray_lanes::closest(&leaf.prims, o, rows.each_ref(), t_min) };
                for (k, (d, h)) in dirs.iter().zip(out.iter_mut()).enumerate() {
                    let prim = leaf.ids.get(found[k] as usize);
                    *h = prim.map(|&p| self.hit_at(p as usize, o, *d, t[k]));
                }
            }
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 && self.lone_leaf.is_none() {
            const LANES: usize = ray_lanes::LANES;
            for (dirs, out) in dirs.chunks(LANES).zip(out.chunks_mut(LANES)) {
                // A short last chunk repeats its last ray in the lanes past it.
                let mut packet = [dirs[dirs.len() - 1]; LANES];
                packet[..dirs.len()].copy_from_slice(dirs);
                // SAFETY: `avx2` is set only where the CPU has AVX2.
                let found = unsafe { ray_lanes::closest_packet(self, o, &packet, t_min) };
                // Rays that make no packet go one at a time, as the packet's ties do.
                let (t, best, alone) = found.unwrap_or(([0.0; LANES], [None; LANES], u32::MAX));
                for (k, (d, h)) in dirs.iter().zip(out.iter_mut()).enumerate() {
                    *h = if alone & (1 << k) != 0 {
                        self.intersect(o, *d, t_min, f32::INFINITY)
                    } else {
                        self.nearest_of(best[k], o, *d, t_min, t[k])
                    };
                }
            }
            return;
        }
        for (d, h) in dirs.iter().zip(out.iter_mut()) {
            *h = self.intersect(o, *d, t_min, f32::INFINITY);
        }
    }

    /// Whether [`Bvh::occluded_ahead_many`] answers rays eight at a time (else one by one, as
    /// [`Bvh::occluded`] does).
    #[must_use]
    pub fn batches_rays_ahead(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        return self.lanes.is_some();
        #[cfg(not(target_arch = "x86_64"))]
        return false;
    }

    /// [`Bvh::occluded`] over t ∈ (0, ∞) for each ray of `rays`: `out[k]` is ray k's answer, bit
    /// for bit the one-at-a-time call's. In a scene that is one leaf, with no disk beside it,
    /// rays go eight to a register where the CPU has AVX2 (`ray_lanes/`). Panics unless `out`
    /// has one entry per ray.
    pub fn occluded_ahead_many(&self, rays: &RaysAhead, out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "occluded_ahead_many: one answer per ray");
        #[cfg(target_arch = "x86_64")]
        if let Some(leaf) = &self.lanes {
            for (first, out) in (0..).step_by(ray_lanes::LANES).zip(out.chunks_mut(ray_lanes::LANES)) {
                // SAFETY: `lanes` exists only where the CPU has AVX2.
                let blocked = unsafe { ray_lanes::blocked_ahead(&leaf.prims, rays, first) };
                for (k, o) in out.iter_mut().enumerate() {
                    *o = blocked & (1 << k) != 0;
                }
            }
            return;
        }
        for (k, o) in out.iter_mut().enumerate() {
            let (origin, dir) = rays.ray(k);
            *o = self.occluded(origin, dir, 0.0, f32::INFINITY);
        }
    }
}
