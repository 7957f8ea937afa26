//! The AVX2 register operations of the env-only descents (`lanes_avx2.rs`): lane masks, a
//! side picked for four lanes at once, and the blocks of sixteen grandchildren transposed into
//! registers — each the scalar step's operations in its order. The masks, the clamp and the
//! read-back serve the product tree's descents too (`product/lanes_avx2.rs`).

use crate::warp::ONE_MINUS_EPSILON;
use core::arch::x86_64::*;

/// Lane bits as a mask register (all ones where set).
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) fn lane_mask(bits: i32) -> __m256d {
    let m = |k: i32| if bits & (1 << k) != 0 { -1 } else { 0 };
    _mm256_castsi256_pd(_mm256_setr_epi64x(m(0), m(1), m(2), m(3)))
}

/// The four f64 of a register.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) fn floats(v: __m256d) -> [f64; 4] {
    let mut out = [0.0; 4];
    // SAFETY: `out` holds four f64.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
    out
}

/// The four u64 of a register.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn ints(v: __m256i) -> [u64; 4] {
    let mut out = [0u64; 4];
    // SAFETY: `out` holds four u64.
    unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), v) };
    out
}

/// The side a [`pick_x4`] chose per lane, with what the rescaling needs.
pub(super) struct Picked {
    /// `at_least[j - 1]`: lanes whose side is ≥ j (t ≥ prefix j), for j = 1, 2, 3.
    pub(super) at_least: [__m256d; 3],
    /// t less the chosen side's prefix.
    pub(super) offset: __m256d,
    /// The chosen side's weight.
    pub(super) weight: __m256d,
    /// Lane bits whose total is positive (and not NaN).
    pub(super) ok: i32,
    /// Lane bits whose chosen side has no mass: the scalar fallback decides.
    pub(super) fallback: i32,
}

impl Picked {
    /// Each lane's side: how many prefixes t reached (each mask is −1 where set).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn index(&self) -> __m256i {
        let [a, b, c] = self.at_least;
        let (a, b, c) = (_mm256_castpd_si256(a), _mm256_castpd_si256(b), _mm256_castpd_si256(c));
        _mm256_sub_epi64(_mm256_setzero_si256(), _mm256_add_epi64(_mm256_add_epi64(a, b), c))
    }
}

/// `pick_branchless` of four lanes: prefix sums from zero, t = x·total, the side by the count
/// of prefixes t reached (nested masks, as the weights are not negative).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn pick_x4(w: [__m256d; 4], x: __m256d) -> Picked {
    let zero = _mm256_setzero_pd();
    let p1 = _mm256_add_pd(zero, w[0]);
    let p2 = _mm256_add_pd(p1, w[1]);
    let p3 = _mm256_add_pd(p2, w[2]);
    let total = _mm256_add_pd(p3, w[3]);
    let t = _mm256_mul_pd(x, total);
    let at_least =
        [_mm256_cmp_pd::<_CMP_GE_OQ>(t, p1), _mm256_cmp_pd::<_CMP_GE_OQ>(t, p2), _mm256_cmp_pd::<_CMP_GE_OQ>(t, p3)];
    let prefix = select(at_least, [zero, p1, p2, p3]);
    let weight = select(at_least, w);
    Picked {
        at_least,
        offset: _mm256_sub_pd(t, prefix),
        weight,
        ok: _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(total, zero)),
        fallback: _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(weight, zero)),
    }
}

/// Per lane, `v[j]` for the largest j whose mask `at_least[j - 1]` is set (else `v[0]`).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn select(at_least: [__m256d; 3], v: [__m256d; 4]) -> __m256d {
    let s = _mm256_blendv_pd(v[0], v[1], at_least[0]);
    let s = _mm256_blendv_pd(s, v[2], at_least[1]);
    _mm256_blendv_pd(s, v[3], at_least[2])
}

/// `f64::clamp(v, 0, ONE_MINUS_EPSILON)` per lane.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) fn clamp_unit(v: __m256d) -> __m256d {
    let (lo, hi) = (_mm256_setzero_pd(), _mm256_set1_pd(ONE_MINUS_EPSILON));
    let v = _mm256_blendv_pd(v, lo, _mm256_cmp_pd::<_CMP_LT_OQ>(v, lo));
    _mm256_blendv_pd(v, hi, _mm256_cmp_pd::<_CMP_GT_OQ>(v, hi))
}

/// Four lanes' sixteen masses, position by position: `out[i]` holds mass i of lanes 0–3.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn transpose(blocks: [&[f32; 16]; 4]) -> [__m256d; 16] {
    let mut out = [_mm256_setzero_pd(); 16];
    for g in 0..4 {
        // SAFETY: each block holds sixteen values; 4·g + 4 ≤ 16.
        let load = |b: &[f32; 16]| unsafe { _mm_loadu_ps(b.as_ptr().add(4 * g)) };
        let (a0, a1, a2, a3) = (load(blocks[0]), load(blocks[1]), load(blocks[2]), load(blocks[3]));
        let (t0, t1) = (_mm_unpacklo_ps(a0, a1), _mm_unpacklo_ps(a2, a3));
        let (t2, t3) = (_mm_unpackhi_ps(a0, a1), _mm_unpackhi_ps(a2, a3));
        let columns = [_mm_movelh_ps(t0, t1), _mm_movehl_ps(t1, t0), _mm_movelh_ps(t2, t3), _mm_movehl_ps(t3, t2)];
        for j in 0..4 {
            out[4 * g + j] = _mm256_cvtps_pd(columns[j]);
        }
    }
    out
}
