//! A leaf's primitives four to a block, as structure of arrays: one four-lane Möller–Trumbore
//! test for its triangles and one four-lane quadratic for its spheres. The lanes repeat
//! [`Primitive::intersect`]'s operations in its order, so a lane's distance is bit for bit the
//! scalar test's and the closest hit does not depend on which path found it.

use super::Primitive;
use super::lanes::F4;
use sampler_core::glam::Vec3;

/// A lane with no primitive.
pub(super) const NONE: u32 = u32::MAX;

/// A primitive as lane tests read it, one primitive splat over rays (`ray_lanes/`).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(super) enum LanePrim {
    /// A vertex and the two edges from it.
    Triangle { v0: Vec3, e1: Vec3, e2: Vec3 },
    /// The centre and the squared radius (rounded as the blocks round it).
    Sphere { center: Vec3, r2: f32 },
}

#[cfg(target_arch = "x86_64")]
impl LanePrim {
    /// The lane form of `p`.
    pub(super) fn of(p: &Primitive) -> Self {
        match *p {
            Primitive::Triangle { v0, e1, e2, .. } => LanePrim::Triangle { v0, e1, e2 },
            Primitive::Sphere { center, radius, .. } => LanePrim::Sphere { center, r2: radius * radius },
        }
    }
}

/// Up to four primitives of one leaf.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(super) struct Block {
    /// v0, e1, e2 of triangle lanes, one row per coordinate. A sphere lane keeps its centre in
    /// `v0` and its squared radius in `e1[0]`. NaN in the other lanes and rows, which no test
    /// accepts.
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
    /// The blocks of the primitives `first..first + count`, in order, or triangles first
    /// and spheres after them where that takes no more blocks: then a block is one kind and a
    /// ray runs one of the two tests on it.
    pub(super) fn pack(prims: &[Primitive], first: u32, count: u32, out: &mut Vec<Block>) {
        let is_sphere = |&id: &u32| matches!(prims[id as usize], Primitive::Sphere { .. });
        let (spheres, tris): (Vec<u32>, Vec<u32>) = (first..first + count).partition(is_sphere);
        let chunks: Vec<&[u32]> = if tris.len().div_ceil(4) + spheres.len().div_ceil(4) == (count as usize).div_ceil(4)
        {
            tris.chunks(4).chain(spheres.chunks(4)).collect()
        } else {
            Vec::new()
        };
        let ids: Vec<u32> = (first..first + count).collect();
        let chunks = if chunks.is_empty() { ids.chunks(4).collect() } else { chunks };
        for chunk in chunks {
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
                    Primitive::Sphere { center, radius, .. } => {
                        for a in 0..3 {
                            b.v0[a][k] = center[a];
                        }
                        b.e1[0][k] = radius * radius;
                        b.spheres |= 1 << k;
                    }
                }
            }
            out.push(b);
        }
    }

    /// Lane k's primitive as the lane tests read it (the block's own rounding of a sphere's
    /// squared radius), or `None` where the lane is empty.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn lane(&self, k: usize) -> Option<LanePrim> {
        let column = |r: &[[f32; 4]; 3]| Vec3::new(r[0][k], r[1][k], r[2][k]);
        if self.tris & (1 << k) != 0 {
            Some(LanePrim::Triangle { v0: column(&self.v0), e1: column(&self.e1), e2: column(&self.e2) })
        } else if self.spheres & (1 << k) != 0 {
            Some(LanePrim::Sphere { center: column(&self.v0), r2: self.e1[0][k] })
        } else {
            None
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
        (ok & self.tris, t.to_array())
    }

    /// The sphere lanes the ray hits in (t_min, t_max) (bit k for lane k) and their distances:
    /// the nearer root where it is in the interval, else the farther.
    #[inline(always)]
    pub(super) fn spheres(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> (u32, [f32; 4]) {
        if self.spheres == 0 {
            return (0, [0.0; 4]);
        }
        let (disc, q, cq) = self.sphere_roots(o, d);
        let (q, cq, disc) = (q.to_array(), cq.to_array(), disc.to_array());
        let (mut hits, mut t) = (0, [0.0; 4]);
        let mut lanes = self.spheres;
        while lanes != 0 {
            let k = lanes.trailing_zeros() as usize;
            lanes &= lanes - 1;
            if disc[k] < 0.0 {
                continue;
            }
            let (t0, t1) = if q[k] != 0.0 { (q[k], cq[k]) } else { (0.0, 0.0) };
            let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
            if near > t_min && near < t_max {
                (hits, t[k]) = (hits | 1 << k, near);
            } else if far > t_min && far < t_max {
                (hits, t[k]) = (hits | 1 << k, far);
            }
        }
        (hits, t)
    }

    /// Whether the ray hits any primitive of the block in (t_min, t_max): the lanes
    /// [`Block::triangles`] and [`Block::spheres`] find, up to rounding at the edges of
    /// triangles and of the interval, decided without a division or a square root where it
    /// can be. A triangle's barycentrics and distance are compared scaled by its determinant
    /// ([`Block::triangles_hit`]). A sphere hit anywhere ahead, t ∈ (0, ∞), needs only the
    /// signs of the quadratic's coefficients ([`Block::spheres_ahead`]); in another interval
    /// a sphere lane hits where either root is in it: its nearer root in it, or else its
    /// farther, is the same test. Where q = 0 the scalar test takes 0 for both roots; then
    /// q's own lane tests 0 and c/q (infinite or NaN) is in no interval, so the answer is the
    /// same.
    #[inline(always)]
    pub(super) fn occludes(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        if self.tris != 0 && self.triangles_hit(o, d, t_min, t_max) {
            return true;
        }
        if self.spheres == 0 {
            return false;
        }
        if t_min == 0.0 && t_max == f32::INFINITY {
            return self.spheres_ahead(o, d);
        }
        let (disc, q, cq) = self.sphere_roots(o, d);
        let (lo, hi) = (F4::splat(t_min), F4::splat(t_max));
        let inside = |t: F4| lo.lt_mask(t) & t.lt_mask(hi);
        let real = !disc.lt_mask(F4::splat(0.0));
        real & (inside(q) | inside(cq)) & self.spheres != 0
    }

    /// Whether a triangle lane hits in (t_min, t_max): [`Block::triangles`]'s Möller–Trumbore
    /// test with u, v and t left multiplied by the determinant det, so that u ∈ [0, 1]
    /// becomes u·|det| ∈ [0, |det|] (u·det times the sign of det) and no lane divides.
    #[inline(always)]
    fn triangles_hit(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        let row = |r: &[[f32; 4]; 3]| r.each_ref().map(F4::load);
        let (v0, e1, e2) = (row(&self.v0), row(&self.e1), row(&self.e2));
        let d = [d.x, d.y, d.z].map(F4::splat);
        let o = [o.x, o.y, o.z].map(F4::splat);
        let p = cross(d, e2);
        let det = dot(e1, p);
        let (sign, scale) = (det.sign(), det.abs());
        let mut ok = !scale.lt_mask(F4::splat(1e-20));
        let s = [o[0].sub(v0[0]), o[1].sub(v0[1]), o[2].sub(v0[2])];
        let u = dot(s, p).xor(sign);
        ok &= F4::splat(0.0).le_mask(u) & u.le_mask(scale);
        let q = cross(s, e1);
        let v = dot(d, q).xor(sign);
        ok &= !(v.lt_mask(F4::splat(0.0)) | scale.lt_mask(u.add(v)));
        let t = dot(e2, q).xor(sign);
        ok &= F4::splat(t_min).mul(scale).lt_mask(t) & t.lt_mask(F4::splat(t_max).mul(scale));
        ok & self.tris != 0
    }

    /// Whether a sphere lane hits at some t ∈ (0, ∞). The quadratic t² − 2bt + c = 0 of
    /// [`Block::sphere_roots`] has real roots where its discriminant is not negative; their
    /// product is c and their sum 2b, so one is ahead where c < 0 (the origin inside) and
    /// both are where c ≥ 0 and b > 0 (the sphere ahead; with c = 0 one root is 0 and the
    /// other 2b). No root needs computing.
    #[inline(always)]
    fn spheres_ahead(&self, o: Vec3, d: Vec3) -> bool {
        let center = self.v0.each_ref().map(F4::load);
        let r2 = F4::load(&self.e1[0]);
        let d = [d.x, d.y, d.z].map(F4::splat);
        let f = [o.x, o.y, o.z].map(F4::splat);
        let f = [f[0].sub(center[0]), f[1].sub(center[1]), f[2].sub(center[2])];
        let b = dot(f, d).neg();
        let perp = [f[0].add(b.mul(d[0])), f[1].add(b.mul(d[1])), f[2].add(b.mul(d[2]))];
        let disc = r2.sub(dot(perp, perp));
        let c = dot(f, f).sub(r2);
        let zero = F4::splat(0.0);
        let real = !disc.lt_mask(zero);
        real & (c.lt_mask(zero) | zero.lt_mask(b)) & self.spheres != 0
    }

    /// Per sphere lane: the discriminant (its root's radicand), q and c/q, the roots of
    /// [`Primitive::intersect`]'s quadratic where q ≠ 0.
    #[inline(always)]
    fn sphere_roots(&self, o: Vec3, d: Vec3) -> (F4, F4, F4) {
        let center = self.v0.each_ref().map(F4::load);
        let r2 = F4::load(&self.e1[0]);
        let d = [d.x, d.y, d.z].map(F4::splat);
        let f = [o.x, o.y, o.z].map(F4::splat);
        let f = [f[0].sub(center[0]), f[1].sub(center[1]), f[2].sub(center[2])];
        let b = dot(f, d).neg();
        let perp = [f[0].add(b.mul(d[0])), f[1].add(b.mul(d[1])), f[2].add(b.mul(d[2]))];
        let disc = r2.sub(dot(perp, perp));
        let c = dot(f, f).sub(r2);
        let q = b.add(disc.sqrt().copysign(b));
        (disc, q, c.div(q))
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
                0 => Primitive::Sphere { center: v(), radius: 0.3, surface: 0 },
                _ => Primitive::Triangle { v0: v(), e1: v(), e2: v() * 1e-3f32.powi(k % 3), surface: 0, attrs: 0 },
            })
            .collect();
        let mut blocks = Vec::new();
        Block::pack(&prims, 0, prims.len() as u32, &mut blocks);
        let (mut hits, mut sphere_hits) = (0, 0);
        for (i, b) in blocks.iter().enumerate() {
            // Aimed near one lane's primitive, so that many rays hit and some graze edges.
            let (lo, hi) = prims[b.prim[i % 4] as usize].bounds();
            let o = v() * 3.0;
            let d = ((lo + hi) * 0.5 + v() * 0.02 - o).normalize();
            let (tris, t_tri) = b.triangles(o, d, 1e-3, 4.5);
            let (spheres, t_sphere) = b.spheres(o, d, 1e-3, 4.5);
            assert_eq!(tris & spheres, 0, "block {i}: a lane is one primitive");
            assert_eq!(b.occludes(o, d, 1e-3, 4.5), tris | spheres != 0, "block {i}: occlusion");
            let unbounded = b.triangles(o, d, 0.0, f32::INFINITY).0 | b.spheres(o, d, 0.0, f32::INFINITY).0;
            assert_eq!(b.occludes(o, d, 0.0, f32::INFINITY), unbounded != 0, "block {i}: occlusion to ∞");
            for k in 0..4 {
                let scalar = prims[b.prim[k] as usize].intersect(o, d, 1e-3, 4.5);
                let lane = match (tris & (1 << k) != 0, spheres & (1 << k) != 0) {
                    (true, _) => Some(t_tri[k]),
                    (_, true) => Some(t_sphere[k]),
                    _ => None,
                };
                assert_eq!(scalar.map(f32::to_bits), lane.map(f32::to_bits), "block {i} lane {k}");
                hits += usize::from(lane.is_some());
                sphere_hits += usize::from(spheres & (1 << k) != 0);
            }
        }
        // From inside a sphere only the far root is in the interval.
        let inside = Primitive::Sphere { center: Vec3::new(0.5, -0.25, 2.0), radius: 0.75, surface: 0 };
        let mut one = Vec::new();
        Block::pack(&[inside], 0, 1, &mut one);
        for d in [Vec3::X, -Vec3::Z, Vec3::new(0.3, -0.5, 0.8).normalize()] {
            let o = Vec3::new(0.6, -0.2, 1.9);
            let scalar = inside.intersect(o, d, 1e-3, 4.5);
            assert!(scalar.is_some());
            assert_eq!(one[0].spheres(o, d, 1e-3, 4.5), (1, [scalar.unwrap(), 0.0, 0.0, 0.0]));
            assert!(one[0].occludes(o, d, 1e-3, 4.5));
            assert!(!one[0].occludes(o, d, 1e-3, 0.5), "both roots beyond the interval");
        }
        assert!(hits > 150 && sphere_hits > 30, "{hits} hits, {sphere_hits} on spheres: too few to test the lanes");
    }
}
