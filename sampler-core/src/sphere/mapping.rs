//! Equal-area mapping between the unit sphere and the unit square
//! (Clarberg, "Fast equal-area mapping of the (hemi)sphere using SIMD", JGT 2008).
//!
//! Square coordinates are `(u, v) ∈ [0, 1]²`. The inner diamond `|2u−1| + |2v−1| ≤ 1` is the
//! upper hemisphere (+z at the centre), the four corner triangles the lower one (all corners are
//! −z). The Jacobian is constant: `dω = 4π du dv`, so every cell of a regular 2^k grid subtends
//! exactly `4π / 4^k` sr and a 2×2 box average of an equal-area map is again an equal-area map.
//!
//! The trigonometry is done with polynomials (max error 4e-8 rad) instead of `atan2`/`sincos`:
//! the scalar and the 4-wide functions then run the *same* IEEE operations in the same order and
//! give bit-identical results, and the batched form vectorises completely.

use core::f32::consts::{FRAC_1_SQRT_2, FRAC_2_PI, FRAC_PI_4};
use glam::{Vec2, Vec3, Vec4};

/// Minimax coefficients of atan(x) ≈ x·P(x²) on [0, 1]; max abs error 3.7e-8 rad.
const ATAN: [f32; 8] = [
    0.999_999_34,
    -0.333_298_6,
    0.199_465_66,
    -0.139_086_3,
    0.096_421_97,
    -0.055_912_32,
    0.021_862_952,
    -0.004_054_565_3,
];

/// Smallest positive normal; guards the divisions at the poles, the centre and the corners.
const TINY: f32 = f32::MIN_POSITIVE;

#[inline(always)]
fn atan_unit(x: f32) -> f32 {
    let x2 = x * x;
    let mut p = ATAN[7];
    let mut k = 7;
    while k > 0 {
        k -= 1;
        p = p * x2 + ATAN[k];
    }
    x * p
}

#[inline(always)]
fn atan_unit4(x: Vec4) -> Vec4 {
    let x2 = x * x;
    let mut p = Vec4::splat(ATAN[7]);
    let mut k = 7;
    while k > 0 {
        k -= 1;
        p = p * x2 + Vec4::splat(ATAN[k]);
    }
    x * p
}

/// (sin w, cos w) for w ∈ [−π/4, π/4] by Taylor polynomials (error < 1e-9).
#[inline(always)]
fn sin_cos_quarter(w: f32) -> (f32, f32) {
    let w2 = w * w;
    let s = w * (1.0 + w2 * (-1.0 / 6.0 + w2 * (1.0 / 120.0 + w2 * (-1.0 / 5040.0 + w2 * (1.0 / 362_880.0)))));
    let c =
        1.0 + w2 * (-0.5 + w2 * (1.0 / 24.0 + w2 * (-1.0 / 720.0 + w2 * (1.0 / 40_320.0 + w2 * (-1.0 / 3_628_800.0)))));
    (s, c)
}

#[inline(always)]
fn sin_cos_quarter4(w: Vec4) -> (Vec4, Vec4) {
    let w2 = w * w;
    let sp = |c: f32| Vec4::splat(c);
    let s = w
        * (sp(1.0)
            + w2 * (sp(-1.0 / 6.0) + w2 * (sp(1.0 / 120.0) + w2 * (sp(-1.0 / 5040.0) + w2 * sp(1.0 / 362_880.0)))));
    let c = sp(1.0)
        + w2 * (sp(-0.5)
            + w2 * (sp(1.0 / 24.0)
                + w2 * (sp(-1.0 / 720.0) + w2 * (sp(1.0 / 40_320.0) + w2 * sp(-1.0 / 3_628_800.0)))));
    (s, c)
}

/// Lane-wise square root (correctly rounded, as `libm::sqrtf`).
#[inline(always)]
pub(crate) fn sqrt4(v: Vec4) -> Vec4 {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use core::arch::x86_64::{__m128, _mm_sqrt_ps};
        let m: __m128 = v.into();
        #[allow(unused_unsafe)]
        let r = unsafe { _mm_sqrt_ps(m) };
        Vec4::from(r)
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        v.sqrt()
    }
}

/// Maps a point of the unit square to a unit direction (constant Jacobian `4π`).
#[inline]
#[must_use]
pub fn square_to_sphere(p: Vec2) -> Vec3 {
    let s = 2.0 * p.x - 1.0;
    let t = 2.0 * p.y - 1.0;
    let (as_, at) = (s.abs(), t.abs());
    let sd = 1.0 - (as_ + at); // > 0 inside the diamond (upper hemisphere)
    let r = 1.0 - sd.abs();
    let q = ((at - as_) / r.max(TINY)).clamp(-1.0, 1.0);
    let (sw, cw) = sin_cos_quarter(FRAC_PI_4 * q);
    // φ = π/4 + w: cos φ = (cos w − sin w)/√2, sin φ = (cos w + sin w)/√2.
    let cos_phi = (cw - sw) * FRAC_1_SQRT_2;
    let sin_phi = (cw + sw) * FRAC_1_SQRT_2;
    let rs = r * libm::sqrtf((2.0 - r * r).max(0.0));
    Vec3::new((cos_phi * rs).copysign(s), (sin_phi * rs).copysign(t), (1.0 - r * r).copysign(sd))
}

/// Maps a direction (any length > 0; the zero vector goes to +z) to the unit square.
/// Exact inverse of [`square_to_sphere`] up to f32 rounding.
#[inline]
#[must_use]
pub fn sphere_to_square(d: Vec3) -> Vec2 {
    // Scale by the largest component first: squares of tiny or huge inputs would under/overflow.
    let m = d.x.abs().max(d.y.abs()).max(d.z.abs()).max(TINY);
    let (x, y, z) = (d.x / m, d.y / m, d.z / m);
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let xy2 = x * x + y * y;
    let len = libm::sqrtf(xy2 + z * z);
    // r² = 1 − |z|/len, written without cancellation near the poles.
    let r = libm::sqrtf((xy2 / (len * (len + az)).max(TINY)).min(1.0));
    let a = ax.min(ay) / ax.max(ay).max(TINY);
    let phi = atan_unit(a) * FRAC_2_PI; // in [0, ½]
    let phi = if ay > ax { 1.0 - phi } else { phi };
    let mut tp = phi * r;
    let mut sp = r - tp;
    if z < 0.0 {
        (sp, tp) = (1.0 - tp, 1.0 - sp);
    }
    Vec2::new(0.5 * sp.copysign(x) + 0.5, 0.5 * tp.copysign(y) + 0.5)
}

/// Four points at a time (structure of arrays): `u`, `v` → `(x, y, z)`.
/// Bit-identical to four calls of [`square_to_sphere`].
#[inline]
#[must_use]
pub fn square_to_sphere_x4(u: Vec4, v: Vec4) -> [Vec4; 3] {
    let one = Vec4::ONE;
    let s = Vec4::splat(2.0) * u - one;
    let t = Vec4::splat(2.0) * v - one;
    let (as_, at) = (s.abs(), t.abs());
    let sd = one - (as_ + at);
    let r = one - sd.abs();
    let q = ((at - as_) / r.max(Vec4::splat(TINY))).clamp(-one, one);
    let (sw, cw) = sin_cos_quarter4(Vec4::splat(FRAC_PI_4) * q);
    let cos_phi = (cw - sw) * Vec4::splat(FRAC_1_SQRT_2);
    let sin_phi = (cw + sw) * Vec4::splat(FRAC_1_SQRT_2);
    let rs = r * sqrt4((Vec4::splat(2.0) - r * r).max(Vec4::ZERO));
    [(cos_phi * rs).copysign(s), (sin_phi * rs).copysign(t), (one - r * r).copysign(sd)]
}

/// Four directions at a time (structure of arrays): `(x, y, z)` → `[u, v]`.
/// Bit-identical to four calls of [`sphere_to_square`].
#[inline]
#[must_use]
pub fn sphere_to_square_x4(x: Vec4, y: Vec4, z: Vec4) -> [Vec4; 2] {
    let one = Vec4::ONE;
    let tiny = Vec4::splat(TINY);
    let m = x.abs().max(y.abs()).max(z.abs()).max(tiny);
    let (x, y, z) = (x / m, y / m, z / m);
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let xy2 = x * x + y * y;
    let len = sqrt4(xy2 + z * z);
    let r = sqrt4((xy2 / (len * (len + az)).max(tiny)).min(one));
    let a = ax.min(ay) / ax.max(ay).max(tiny);
    let phi = atan_unit4(a) * Vec4::splat(FRAC_2_PI);
    let phi = Vec4::select(ay.cmpgt(ax), one - phi, phi);
    let tp = phi * r;
    let sp = r - tp;
    let lower = z.cmplt(Vec4::ZERO);
    let (sp, tp) = (Vec4::select(lower, one - tp, sp), Vec4::select(lower, one - sp, tp));
    let half = Vec4::splat(0.5);
    [half * sp.copysign(x) + half, half * tp.copysign(y) + half]
}

/// Batched [`square_to_sphere`] over slices, four lanes at a time.
/// Panics if the slices differ in length.
pub fn square_to_sphere_batch(points: &[Vec2], out: &mut [Vec3]) {
    assert_eq!(points.len(), out.len());
    let mut pc = points.chunks_exact(4);
    let mut oc = out.chunks_exact_mut(4);
    for (p, o) in (&mut pc).zip(&mut oc) {
        let u = Vec4::new(p[0].x, p[1].x, p[2].x, p[3].x);
        let v = Vec4::new(p[0].y, p[1].y, p[2].y, p[3].y);
        let [x, y, z] = square_to_sphere_x4(u, v);
        for k in 0..4 {
            o[k] = Vec3::new(x[k], y[k], z[k]);
        }
    }
    for (p, o) in pc.remainder().iter().zip(oc.into_remainder()) {
        *o = square_to_sphere(*p);
    }
}

/// Batched [`sphere_to_square`] over slices, four lanes at a time.
/// Panics if the slices differ in length.
pub fn sphere_to_square_batch(dirs: &[Vec3], out: &mut [Vec2]) {
    assert_eq!(dirs.len(), out.len());
    let mut dc = dirs.chunks_exact(4);
    let mut oc = out.chunks_exact_mut(4);
    for (d, o) in (&mut dc).zip(&mut oc) {
        let x = Vec4::new(d[0].x, d[1].x, d[2].x, d[3].x);
        let y = Vec4::new(d[0].y, d[1].y, d[2].y, d[3].y);
        let z = Vec4::new(d[0].z, d[1].z, d[2].z, d[3].z);
        let [u, v] = sphere_to_square_x4(x, y, z);
        for k in 0..4 {
            o[k] = Vec2::new(u[k], v[k]);
        }
    }
    for (d, o) in dc.remainder().iter().zip(oc.into_remainder()) {
        *o = sphere_to_square(*d);
    }
}

/// Continuous wrap rule: a point just outside the square maps to the point of the square that
/// is its neighbour on the sphere. Valid for overshoots of less than one square width.
#[inline]
#[must_use]
pub fn wrap_square(p: Vec2) -> Vec2 {
    let (mut u, mut v) = (p.x, p.y);
    if u < 0.0 {
        (u, v) = (-u, 1.0 - v);
    } else if u > 1.0 {
        (u, v) = (2.0 - u, 1.0 - v);
    }
    if v < 0.0 {
        (u, v) = (1.0 - u, -v);
    } else if v > 1.0 {
        (u, v) = (1.0 - u, 2.0 - v);
    }
    Vec2::new(u, v)
}

/// The wrap rule on texel indices of an `n × n` grid: the texel whose centre is the sphere
/// neighbour of texel `(i, j)` when `(i, j)` lies at most `n − 1` texels outside the grid.
/// Texel −1 maps to texel 0 (mirrored), not to texel 1.
#[inline]
#[must_use]
pub fn wrap_texel(i: i32, j: i32, n: u32) -> (u32, u32) {
    let n = n as i32;
    let (mut i, mut j) = (i, j);
    if i < 0 {
        (i, j) = (-1 - i, n - 1 - j);
    } else if i >= n {
        (i, j) = (2 * n - 1 - i, n - 1 - j);
    }
    if j < 0 {
        (i, j) = (n - 1 - i, -1 - j);
    } else if j >= n {
        (i, j) = (n - 1 - i, 2 * n - 1 - j);
    }
    (i.clamp(0, n - 1) as u32, j.clamp(0, n - 1) as u32)
}

/// The texel of an `n × n` grid that contains `p`; `u = 1` belongs to the last texel and
/// out-of-range or NaN coordinates are clamped (NaN → 0).
#[inline]
#[must_use]
pub fn texel_of(p: Vec2, n: u32) -> (u32, u32) {
    let nf = n as f32;
    let i = ((p.x * nf) as u32).min(n - 1); // `as` saturates: negative and NaN give 0
    let j = ((p.y * nf) as u32).min(n - 1);
    (i, j)
}

/// Solid-angle measure of a region of the square: `4π × area`.
pub const SPHERE_AREA: f32 = 4.0 * core::f32::consts::PI;

/// Angle between two unit vectors, accurate for small angles (used by tests and callers that
/// check round trips).
#[must_use]
pub fn angle_between(a: Vec3, b: Vec3) -> f32 {
    // 2·atan2(|a−b|, |a+b|) is accurate over the whole range, unlike acos(a·b).
    2.0 * libm::atan2f((a - b).length(), (a + b).length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poles_and_corners() {
        assert_eq!(square_to_sphere(Vec2::new(0.5, 0.5)), Vec3::Z);
        for c in [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)] {
            let d = square_to_sphere(c);
            assert!((d.z + 1.0).abs() < 1e-7, "{c:?} -> {d:?}");
        }
        let c = sphere_to_square(Vec3::Z);
        assert_eq!(c, Vec2::new(0.5, 0.5));
        // −z with ±0 in x, y goes to the matching corner (sign bit, not sign()).
        assert_eq!(sphere_to_square(Vec3::new(0.0, 0.0, -1.0)), Vec2::new(1.0, 1.0));
        assert_eq!(sphere_to_square(Vec3::new(-0.0, -0.0, -1.0)), Vec2::new(0.0, 0.0));
        assert_eq!(sphere_to_square(Vec3::new(-0.0, 0.0, -1.0)), Vec2::new(0.0, 1.0));
        assert_eq!(sphere_to_square(Vec3::ZERO), Vec2::new(0.5, 0.5));
    }

    #[test]
    fn axes_land_on_the_diamond() {
        let cases = [
            (Vec3::X, Vec2::new(1.0, 0.5)),
            (Vec3::NEG_X, Vec2::new(0.0, 0.5)),
            (Vec3::Y, Vec2::new(0.5, 1.0)),
            (Vec3::NEG_Y, Vec2::new(0.5, 0.0)),
        ];
        for (d, p) in cases {
            let q = sphere_to_square(d);
            assert!((q - p).abs().max_element() < 1e-6, "{d:?} -> {q:?}");
            let back = square_to_sphere(p);
            assert!(angle_between(back, d) < 1e-6, "{p:?} -> {back:?}");
        }
    }

    #[test]
    fn texel_wrap_is_a_mirror_not_an_off_by_one() {
        assert_eq!(wrap_texel(-1, 0, 8), (0, 7));
        assert_eq!(wrap_texel(8, 2, 8), (7, 5));
        assert_eq!(wrap_texel(3, -1, 8), (4, 0));
        assert_eq!(wrap_texel(3, 8, 8), (4, 7));
        assert_eq!(wrap_texel(-1, -1, 8), (7, 7)); // a corner: both touch −z
        assert_eq!(texel_of(Vec2::new(1.0, 1.0), 8), (7, 7));
        assert_eq!(texel_of(Vec2::new(-0.1, f32::NAN), 8), (0, 0));
    }
}
