//! Env-only descents four to a register: [`choose_grandchild_branchless`]'s step for four
//! descents at once in AVX2 (four f64 lanes), with the same operations in the same order — the
//! same choices and rescaled points, bit for bit. A descent spends most of its instructions on
//! this step's scalar arithmetic; here one register's instructions serve four. A lane whose
//! chosen side holds no mass (rounding at a row's end) takes the scalar step instead.

use super::EnvHierarchy;
use super::lanes::WarpLane;
use super::pyramid::level_offset;
use crate::warp::{ONE_MINUS_EPSILON, choose_grandchild_branchless, grandchild_index};
use core::arch::x86_64::*;

/// Masses of a lane that takes no part (dead, or past the end): no mass, so it picks nothing.
static EMPTY: [f32; 16] = [0.0; 16];

impl EnvHierarchy<'_> {
    /// Descends `lanes` — all at one level — two levels at a time while two remain, four lanes to
    /// a register, as [`warp_down_lanes`](Self::warp_down_lanes) would; returns false (nothing
    /// done) where the CPU lacks AVX2. The last single level, if any, is left to
    /// `warp_down_lanes`.
    pub(super) fn warp_down_pairs_avx2(&self, lanes: &mut [WarpLane]) -> bool {
        if !crate::cpu::has_avx2() {
            return false;
        }
        let Some(mut level) = lanes.first().map(|l| l.cell.level) else { return true };
        debug_assert!(lanes.iter().all(|l| l.cell.level == level), "one level for all lanes");
        if self.is_black() {
            lanes.iter_mut().for_each(|l| l.alive = false);
            return true;
        }
        while level + 2 <= self.finest {
            for lane in lanes.iter().filter(|l| l.alive) {
                crate::prefetch::prefetch(self.grandchildren(level, lane));
            }
            for group in lanes.chunks_mut(4) {
                // SAFETY: AVX2 is available (checked above).
                unsafe { self.step_x4(level, group) };
            }
            level += 2;
        }
        true
    }

    /// The sixteen grandchildren of `lane`'s node at `level`, or [`EMPTY`] for a dead lane.
    #[inline(always)]
    fn grandchildren(&self, level: u32, lane: &WarpLane) -> &[f32; 16] {
        if !lane.alive {
            return &EMPTY;
        }
        let base = level_offset(level + 2) + 16 * lane.morton;
        self.pyramid[base..base + 16].try_into().expect("sixteen grandchildren")
    }

    /// One two-level step of up to four lanes at `level`.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn step_x4(&self, level: u32, group: &mut [WarpLane]) {
        let block = |k: usize| group.get(k).map_or(&EMPTY, |l| self.grandchildren(level, l));
        let m = transpose([block(0), block(1), block(2), block(3)]);
        let xi = |k: usize, y: bool| group.get(k).map_or(0.0, |l| if y { l.xi.y } else { l.xi.x });
        let at = |x: usize, y: usize| m[grandchild_index(x as u32, y as u32)];
        let cols: [__m256d; 4] = core::array::from_fn(|x| {
            _mm256_add_pd(_mm256_add_pd(at(x, 0), at(x, 1)), _mm256_add_pd(at(x, 2), at(x, 3)))
        });
        let column = pick_x4(cols, _mm256_setr_pd(xi(0, false), xi(1, false), xi(2, false), xi(3, false)));
        // The chosen column's four masses, by the same nested masks that chose it.
        let rows: [__m256d; 4] =
            core::array::from_fn(|y| select(column.at_least, [at(0, y), at(1, y), at(2, y), at(3, y)]));
        let row = pick_x4(rows, _mm256_setr_pd(xi(0, true), xi(1, true), xi(2, true), xi(3, true)));
        // rescale: r = 1/(wx·wy), ξ = (ox·wy·r, oy·wx·r) clamped to [0, 1).
        let r = _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_mul_pd(column.weight, row.weight));
        let nx = clamp_unit(_mm256_mul_pd(_mm256_mul_pd(column.offset, row.weight), r));
        let ny = clamp_unit(_mm256_mul_pd(_mm256_mul_pd(row.offset, column.weight), r));
        let (mut xs, mut ys) = ([0.0f64; 4], [0.0f64; 4]);
        // SAFETY: each array holds four f64.
        unsafe {
            _mm256_storeu_pd(xs.as_mut_ptr(), nx);
            _mm256_storeu_pd(ys.as_mut_ptr(), ny);
        }
        let (ok, fallback) = (column.ok & row.ok, column.fallback | row.fallback);
        for (k, lane) in group.iter_mut().enumerate().filter(|(_, l)| l.alive) {
            let bit = 1 << k;
            if ok & bit == 0 {
                lane.alive = false;
            } else if fallback & bit != 0 {
                // Rounding put t past a side of mass: the scalar step's own fallback decides.
                let g = self.grandchildren(level, lane);
                match choose_grandchild_branchless(g, &mut lane.xi) {
                    Some((c, gx, gy)) => lane.step(2, gx, gy, c),
                    None => lane.alive = false,
                }
            } else {
                let (x, y) = (column.index(k), row.index(k));
                lane.xi.x = xs[k];
                lane.xi.y = ys[k];
                lane.step(2, x, y, grandchild_index(x, y));
            }
        }
    }
}

/// The side a [`pick_x4`] chose per lane, with what the rescaling needs.
struct Picked {
    /// `at_least[j - 1]`: lanes whose side is ≥ j (t ≥ prefix j), for j = 1, 2, 3.
    at_least: [__m256d; 3],
    /// The same masks as lane bits.
    at_least_bits: [i32; 3],
    /// t less the chosen side's prefix.
    offset: __m256d,
    /// The chosen side's weight.
    weight: __m256d,
    /// Lane bits whose total is positive (and not NaN).
    ok: i32,
    /// Lane bits whose chosen side has no mass: the scalar fallback decides.
    fallback: i32,
}

impl Picked {
    /// Lane `k`'s side: how many prefixes t reached.
    fn index(&self, k: usize) -> u32 {
        self.at_least_bits.iter().map(|&m| ((m >> k) & 1) as u32).sum()
    }
}

/// `pick_branchless` of four lanes: prefix sums from zero, t = x·total, the side by the count
/// of prefixes t reached (nested masks, as the weights are not negative).
#[inline]
#[target_feature(enable = "avx2")]
fn pick_x4(w: [__m256d; 4], x: __m256d) -> Picked {
    let zero = _mm256_setzero_pd();
    let p1 = _mm256_add_pd(zero, w[0]);
    let p2 = _mm256_add_pd(p1, w[1]);
    let p3 = _mm256_add_pd(p2, w[2]);
    let total = _mm256_add_pd(p3, w[3]);
    let t = _mm256_mul_pd(x, total);
    let at_least = [p1, p2, p3].map(|p| _mm256_cmp_pd::<_CMP_GE_OQ>(t, p));
    let prefix = select(at_least, [zero, p1, p2, p3]);
    let weight = select(at_least, w);
    Picked {
        at_least,
        at_least_bits: at_least.map(|m| _mm256_movemask_pd(m)),
        offset: _mm256_sub_pd(t, prefix),
        weight,
        ok: _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(total, zero)),
        fallback: _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(weight, zero)),
    }
}

/// Per lane, `v[j]` for the largest j whose mask `at_least[j - 1]` is set (else `v[0]`).
#[inline]
#[target_feature(enable = "avx2")]
fn select(at_least: [__m256d; 3], v: [__m256d; 4]) -> __m256d {
    let s = _mm256_blendv_pd(v[0], v[1], at_least[0]);
    let s = _mm256_blendv_pd(s, v[2], at_least[1]);
    _mm256_blendv_pd(s, v[3], at_least[2])
}

/// `f64::clamp(v, 0, ONE_MINUS_EPSILON)` per lane.
#[inline]
#[target_feature(enable = "avx2")]
fn clamp_unit(v: __m256d) -> __m256d {
    let (lo, hi) = (_mm256_setzero_pd(), _mm256_set1_pd(ONE_MINUS_EPSILON));
    let v = _mm256_blendv_pd(v, lo, _mm256_cmp_pd::<_CMP_LT_OQ>(v, lo));
    _mm256_blendv_pd(v, hi, _mm256_cmp_pd::<_CMP_GT_OQ>(v, hi))
}

/// Four lanes' sixteen masses, position by position: `out[i]` holds mass i of lanes 0–3.
#[inline]
#[target_feature(enable = "avx2")]
fn transpose(blocks: [&[f32; 16]; 4]) -> [__m256d; 16] {
    let mut out = [_mm256_setzero_pd(); 16];
    for g in 0..4 {
        // SAFETY: each block holds sixteen values; 4·g + 4 ≤ 16.
        let [a0, a1, a2, a3] = blocks.map(|b| unsafe { _mm_loadu_ps(b.as_ptr().add(4 * g)) });
        let (t0, t1) = (_mm_unpacklo_ps(a0, a1), _mm_unpacklo_ps(a2, a3));
        let (t2, t3) = (_mm_unpackhi_ps(a0, a1), _mm_unpackhi_ps(a2, a3));
        let columns = [_mm_movelh_ps(t0, t1), _mm_movehl_ps(t1, t0), _mm_movelh_ps(t2, t3), _mm_movehl_ps(t3, t2)];
        for (j, c) in columns.into_iter().enumerate() {
            out[4 * g + j] = _mm256_cvtps_pd(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::Cell;
    use crate::env::{build_pyramid, pyramid_len};
    use glam::DVec2;
    use std::vec;
    use std::vec::Vec;

    /// Maps with every kind of mass: smooth, zeros in rows and columns, a 1e7× texel, a
    /// denormal-sized one.
    fn maps(level: u32) -> Vec<Vec<[f32; 3]>> {
        let n = 1usize << (2 * level);
        let smooth: Vec<[f32; 3]> = (0..n).map(|i| [(i * 7 % 13) as f32 + 0.5, (i % 3) as f32, 1.0]).collect();
        let mut holes = smooth.clone();
        holes.iter_mut().enumerate().filter(|(i, _)| i % 5 < 2 || (i / 7) % 3 == 0).for_each(|(_, t)| *t = [0.0; 3]);
        let mut sun = smooth.clone();
        sun[n / 3] = [1e7; 3];
        sun[n / 2] = [1e-38; 3];
        let mut lone = vec![[0.0f32; 3]; n];
        lone[n - 1] = [2.0; 3];
        vec![smooth, holes, sun, lone]
    }

    #[test]
    fn four_lanes_in_a_register_descend_as_the_scalar_lanes() {
        if !crate::cpu::has_avx2() {
            std::println!("no AVX2 here: the scalar descent is the only one");
            return;
        }
        for level in [1u32, 4, 5, 7] {
            for rgb in maps(level) {
                let mut p = vec![0.0f32; pyramid_len(level)];
                build_pyramid(level, &rgb, &mut p).unwrap();
                let env = EnvHierarchy::new(level, &p, &rgb).unwrap();
                let mut u = vec![DVec2::ZERO; 4099];
                crate::points::sobol02(u64::from(level), 0, &mut u);
                u[1] = DVec2::new(crate::warp::ONE_MINUS_EPSILON, crate::warp::ONE_MINUS_EPSILON);
                u[2] = DVec2::new(0.0, crate::warp::ONE_MINUS_EPSILON);
                // Every group size, the last group partial.
                for chunk in u.chunks(7) {
                    let start: Vec<WarpLane> = chunk.iter().map(|u| WarpLane::new(Cell::ROOT, *u)).collect();
                    let (mut simd, mut scalar) = (start.clone(), start);
                    assert!(env.warp_down_pairs_avx2(&mut simd));
                    env.warp_down_lanes(&mut simd);
                    env.warp_down_lanes(&mut scalar);
                    for (a, b) in simd.iter().zip(&scalar) {
                        assert_eq!((a.alive, a.cell, a.morton), (b.alive, b.cell, b.morton));
                        assert_eq!((a.xi.x.to_bits(), a.xi.y.to_bits()), (b.xi.x.to_bits(), b.xi.y.to_bits()));
                    }
                }
            }
        }
    }
}
