//! A leaf's primitives four to a block: triangles as structure of arrays for one four-lane
//! Möller–Trumbore test, spheres flagged for their scalar test. The lanes repeat
//! [`Primitive::intersect`]'s operations in its order, so a lane's distance is bit for bit the
//! scalar test's and the closest hit does not depend on which path found it.

use super::Primitive;
use super::lanes::F4;
use sampler_core::glam::Vec3;

/// A lane with no primitive.
const NONE: u32 = u32::MAX;

/// Up to four primitives of one leaf.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Block {
    /// v0, e1, e2 of triangle lanes, one row per coordinate; NaN in other lanes, which no
    /// triangle test accepts.
    v0: [[f32; 4]; 3],
    e1: [[f32; 4]; 3],
    e2: [[f32; 4]; 3],
    /// Each lane's primitive index, or `NONE`.
    pub(super) prim: [u32; 4],
    /// Bit k set when lane k is a sphere.
    spheres: u32,
    /// Bit k set when lane k is a triangle.
    tris: u32,
}

impl Block {
    /// The blocks of the primitives `first..first + count`, in order.
    pub(super) fn pack(prims: &[Primitive], first: u32, count: u32, out: &mut Vec<Block>) {
        let ids: Vec<u32> = (first..first + count).collect();
        for chunk in ids.chunks(4) {
            let mut b = Block {
                v0: [[f32::NAN; 4]; 3],
                e1: [[f32::NAN; 4]; 3],
                e2: [[f32::NAN; 4]; 3],
                prim: [NONE; 4],
                spheres: 0,
                tris: 0,
            };
            for (k, &id) in chunk.iter().enumerate() {
                b.prim[k] = id;
                match prims[id as usize] {
                    Primitive::Triangle { v0, e1, e2, .. } => {
                        for a in 0..3 {
                            (b.v0[a][k], b.e1[a][k], b.e2[a][k]) = (v0[a], e1[a], e2[a]);
                        }
                        b.tris |= 1 << k;
                    }
                    Primitive::Sphere { .. } => b.spheres |= 1 << k,
                }
            }
            out.push(b);
        }
    }

    /// The triangle lanes the ray hits in (t_min, t_max) (bit k for lane k) and their distances.
    #[inline(always)]
    pub(super) fn triangles(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> (u32, [f32; 4]) {
        if self.tris == 0 {
            return (0, [0.0; 4]);
        }
        let row = |r: &[[f32; 4]; 3]| r.each_ref().map(F4::load);
        let (v0, e1, e2) = (row(&self.v0), row(&self.e1), row(&self.e2));
        let d = [d.x, d.y, d.z].map(F4::splat);
        let o = [o.x, o.y, o.z].map(F4::splat);
        let p = cross(d, e2);
        let det = dot(e1, p);
        let mut ok = !det.abs().lt_mask(F4::splat(1e-20));
        let inv = F4::splat(1.0).div(det);
        let s = [o[0].sub(v0[0]), o[1].sub(v0[1]), o[2].sub(v0[2])];
        let u = dot(s, p).mul(inv);
        ok &= F4::splat(0.0).le_mask(u) & u.le_mask(F4::splat(1.0));
        let q = cross(s, e1);
        let v = dot(d, q).mul(inv);
        ok &= !(v.lt_mask(F4::splat(0.0)) | F4::splat(1.0).lt_mask(u.add(v)));
        let t = dot(e2, q).mul(inv);
        ok &= F4::splat(t_min).lt_mask(t) & t.lt_mask(F4::splat(t_max));
        (ok & 0xf, t.to_array())
    }

    /// Bit k set when lane k is a sphere.
    #[inline(always)]
    pub(super) fn spheres(&self) -> u32 {
        self.spheres
    }
}

/// a × b per lane, as `Vec3::cross` computes it.
#[inline(always)]
fn cross(a: [F4; 3], b: [F4; 3]) -> [F4; 3] {
    [a[1].mul(b[2]).sub(b[1].mul(a[2])), a[2].mul(b[0]).sub(b[2].mul(a[0])), a[0].mul(b[1]).sub(b[0].mul(a[1]))]
}

/// a · b per lane, as `Vec3::dot` computes it.
#[inline(always)]
fn dot(a: [F4; 3], b: [F4; 3]) -> F4 {
    a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_give_the_scalar_tests_distances_bit_for_bit() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut next = move || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut v = || Vec3::new(next(), next(), next());
        let prims: Vec<Primitive> = (0..4000)
            .map(|k| match k % 5 {
                0 => Primitive::Sphere { center: v(), radius: 0.3, material: 0 },
                _ => Primitive::Triangle { v0: v(), e1: v(), e2: v() * 1e-3f32.powi(k % 3), material: 0, attrs: 0 },
            })
            .collect();
        let mut blocks = Vec::new();
        Block::pack(&prims, 0, prims.len() as u32, &mut blocks);
        let mut hits = 0;
        for (i, b) in blocks.iter().enumerate() {
            // Aimed near one lane's primitive, so that many rays hit and some graze edges.
            let (lo, hi) = prims[4 * i + i % 4].bounds();
            let o = v() * 3.0;
            let d = ((lo + hi) * 0.5 + v() * 0.02 - o).normalize();
            let (mask, t) = b.triangles(o, d, 1e-3, 4.5);
            for k in 0..4 {
                let p = prims[4 * i + k];
                let scalar = p.intersect(o, d, 1e-3, 4.5).filter(|_| matches!(p, Primitive::Triangle { .. }));
                let lane = (mask & (1 << k) != 0).then_some(t[k]);
                assert_eq!(scalar.map(f32::to_bits), lane.map(f32::to_bits), "block {i} lane {k}");
                hits += usize::from(lane.is_some());
            }
            assert_eq!(b.spheres().count_ones() as usize, (0..4).filter(|k| (4 * i + k) % 5 == 0).count());
        }
        assert!(hits > 150, "{hits} hits: too few to test the lanes");
    }
}
