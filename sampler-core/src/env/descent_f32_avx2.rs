//! Env-only descents eight to a register: [`choose_grandchild_f32`]'s step for eight descents at
//! once in AVX2 (eight f32 lanes), with the same operations in the same order — the same
//! choices and rescaled points, bit for bit. The descents start together at the root and step
//! two levels at a time in lockstep; per step only the eight addresses of the next sixteen
//! grandchildren leave the registers. Up to [`IN_FLIGHT`] descents go down together, every
//! group's loads asked for before any group's arithmetic, so that their cache misses overlap. A
//! lane the register step cannot decide (rounding reached a side without mass, or a sum
//! overflowed f32) takes the scalar step instead.

use super::EnvHierarchy;
use super::descent_f32::{DescentF32, ONE_MINUS_EPSILON_F32, choose_grandchild_f32};
use super::lanes::IN_FLIGHT;
use super::pyramid::level_offset;
use crate::cell::Cell;
use crate::prefetch::prefetch;
use crate::warp::grandchild_index;
use core::arch::x86_64::*;

/// Masses of a lane that takes no part (dead, or past the end): no mass, so it picks nothing.
static EMPTY: [f32; 16] = [0.0; 16];

/// Groups of eight descents advanced level by level together.
const GROUPS: usize = IN_FLIGHT / 8;

impl EnvHierarchy<'_> {
    /// Descends `lanes`, all at the root, two levels at a time while two remain, eight lanes to
    /// a register, as [`descend_f32_scalar`](Self::descend_f32_scalar) would; nothing where the
    /// CPU lacks AVX2. A last single level is left to the scalar lanes.
    pub(super) fn descend_f32_avx2(&self, lanes: &mut [DescentF32]) {
        if !crate::cpu::has_avx2() {
            return;
        }
        debug_assert!(lanes.iter().all(|l| l.cell == Cell::ROOT));
        for chunk in lanes.chunks_mut(IN_FLIGHT) {
            // SAFETY: AVX2 is available (checked above).
            unsafe { self.descend_groups_f32(chunk) };
        }
    }

    /// Up to [`IN_FLIGHT`] lanes from the root down to the last even step above the finest
    /// level, in groups of eight: per level pair, first every group's sixteen grandchildren
    /// per lane are asked for, then each group steps.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn descend_groups_f32(&self, lanes: &mut [DescentF32]) {
        let n = lanes.len().div_ceil(8).min(GROUPS);
        let mut groups = [Group::load(&[]); GROUPS];
        for (g, eight) in groups.iter_mut().zip(lanes.chunks(8)) {
            *g = Group::load(eight);
        }
        let mut blocks = [[&EMPTY; 8]; GROUPS];
        let mut level = 0;
        while level + 2 <= self.finest {
            for k in 0..n {
                blocks[k] = groups[k].blocks(self.pyramid, level);
                blocks[k].iter().for_each(|b| prefetch(&b[..]));
            }
            for k in 0..n {
                if groups[k].alive != 0 {
                    groups[k].step(blocks[k]);
                }
            }
            level += 2;
        }
        for (g, eight) in groups.iter().zip(lanes.chunks_mut(8)) {
            g.store(eight, level);
        }
    }
}

/// Eight descents in registers at one level: ξ, the Morton index and the cell's column and row
/// per lane.
#[derive(Clone, Copy)]
struct Group {
    xi_x: __m256,
    xi_y: __m256,
    morton: __m256i,
    x: __m256i,
    y: __m256i,
    /// Lane bits not dead.
    alive: i32,
}

impl Group {
    /// The state of `lanes` (up to eight, at the root); missing lanes are dead.
    #[target_feature(enable = "avx2")]
    fn load(lanes: &[DescentF32]) -> Self {
        let get = |k: usize| lanes.get(k).map_or(0.0, |l| l.xi.x);
        let xi_x = _mm256_setr_ps(get(0), get(1), get(2), get(3), get(4), get(5), get(6), get(7));
        let get = |k: usize| lanes.get(k).map_or(0.0, |l| l.xi.y);
        let xi_y = _mm256_setr_ps(get(0), get(1), get(2), get(3), get(4), get(5), get(6), get(7));
        let alive = lanes.iter().take(8).enumerate().filter(|(_, l)| l.alive).fold(0, |a, (k, _)| a | 1 << k);
        let zero = _mm256_setzero_si256();
        Self { xi_x, xi_y, morton: zero, x: zero, y: zero, alive }
    }

    /// Writes the state at `level` back into `lanes`.
    #[target_feature(enable = "avx2")]
    fn store(&self, lanes: &mut [DescentF32], level: u32) {
        let [xs, ys] = [self.xi_x, self.xi_y].map(|v| floats(v));
        let [ms, cx, cy] = [self.morton, self.x, self.y].map(|v| ints(v));
        for (k, lane) in lanes.iter_mut().enumerate().take(8) {
            lane.alive = self.alive & (1 << k) != 0;
            if lane.alive {
                lane.xi = glam::Vec2::new(xs[k], ys[k]);
                lane.morton = ms[k] as usize;
                lane.cell = Cell::new(level, cx[k], cy[k]);
            }
        }
    }

    /// Each live lane's sixteen grandchildren below `level`, [`EMPTY`] for the others.
    #[target_feature(enable = "avx2")]
    fn blocks<'p>(&self, pyramid: &'p [f32], level: u32) -> [&'p [f32; 16]; 8] {
        let ms = ints(self.morton);
        // The blocks of sixteen below `level`, one bounds check per lane.
        let (below, _) = pyramid[level_offset(level + 2)..].as_chunks::<16>();
        let mut out = [&EMPTY; 8];
        for k in 0..8 {
            if self.alive & (1 << k) != 0 {
                out[k] = &below[ms[k] as usize];
            }
        }
        out
    }

    /// One two-level step of the live lanes over their grandchildren `blocks`.
    #[target_feature(enable = "avx2")]
    fn step(&mut self, blocks: [&[f32; 16]; 8]) {
        let m = transpose(blocks);
        let at = |x: usize, y: usize| m[grandchild_index(x as u32, y as u32)];
        let col = |x: usize| _mm256_add_ps(_mm256_add_ps(at(x, 0), at(x, 1)), _mm256_add_ps(at(x, 2), at(x, 3)));
        let column = pick([col(0), col(1), col(2), col(3)], self.xi_x);
        // The chosen column's four masses, by the same nested masks that chose it.
        let row_of = |y: usize| select(column.at_least, [at(0, y), at(1, y), at(2, y), at(3, y)]);
        let row = pick([row_of(0), row_of(1), row_of(2), row_of(3)], self.xi_y);
        let nx = clamp_unit(_mm256_div_ps(column.offset, column.weight));
        let ny = clamp_unit(_mm256_div_ps(row.offset, row.weight));
        // The grandchild (gx, gy) and its Morton index x0 | y0 << 1 | x1 << 2 | y1 << 3.
        let (gx, gy) = (column.index(), row.index());
        let one = _mm256_set1_epi32(1);
        let low = |v: __m256i| _mm256_and_si256(v, one);
        let high = |v: __m256i| _mm256_srli_epi32::<1>(v);
        let child = _mm256_or_si256(
            _mm256_or_si256(low(gx), _mm256_slli_epi32::<1>(low(gy))),
            _mm256_or_si256(_mm256_slli_epi32::<2>(high(gx)), _mm256_slli_epi32::<3>(high(gy))),
        );
        let old = *self;
        let ok = column.ok & self.alive;
        let keep = lane_mask(ok);
        let keep_i = _mm256_castps_si256(keep);
        self.xi_x = _mm256_blendv_ps(self.xi_x, nx, keep);
        self.xi_y = _mm256_blendv_ps(self.xi_y, ny, keep);
        self.morton =
            _mm256_blendv_epi8(self.morton, _mm256_add_epi32(_mm256_slli_epi32::<4>(self.morton), child), keep_i);
        self.x = _mm256_blendv_epi8(self.x, _mm256_add_epi32(_mm256_slli_epi32::<2>(self.x), gx), keep_i);
        self.y = _mm256_blendv_epi8(self.y, _mm256_add_epi32(_mm256_slli_epi32::<2>(self.y), gy), keep_i);
        // Lanes without mass die where they are; the others move two levels down.
        self.alive = ok;
        let undecided = (column.undecided | row.undecided | !row.ok) & ok;
        if undecided != 0 {
            self.redo_scalar(&old, blocks, undecided);
        }
    }

    /// The scalar step, from the state before it (`old`), for the lanes of `undecided`.
    #[cold]
    #[target_feature(enable = "avx2")]
    fn redo_scalar(&mut self, old: &Group, blocks: [&[f32; 16]; 8], undecided: i32) {
        let [mut xs, mut ys] = [old.xi_x, old.xi_y].map(|v| floats(v));
        let [mut ms, mut cx, mut cy] = [self.morton, self.x, self.y].map(|v| ints(v));
        let [om, ocx, ocy] = [old.morton, old.x, old.y].map(|v| ints(v));
        let [nx, ny] = [self.xi_x, self.xi_y].map(|v| floats(v));
        for k in 0..8 {
            if undecided & (1 << k) == 0 {
                (xs[k], ys[k]) = (nx[k], ny[k]);
                continue;
            }
            let mut xi = glam::Vec2::new(xs[k], ys[k]);
            match choose_grandchild_f32(blocks[k], &mut xi) {
                Some((c, gx, gy)) => {
                    (xs[k], ys[k]) = (xi.x, xi.y);
                    ms[k] = (om[k] << 4) + c as u32;
                    (cx[k], cy[k]) = ((ocx[k] << 2) + gx, (ocy[k] << 2) + gy);
                }
                None => self.alive &= !(1 << k),
            }
        }
        // SAFETY: each array holds eight 32-bit values.
        let f = |a: [f32; 8]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        (self.xi_x, self.xi_y) = (f(xs), f(ys));
        // SAFETY: as above.
        let v = |a: [u32; 8]| unsafe { _mm256_loadu_si256(a.as_ptr().cast()) };
        (self.morton, self.x, self.y) = (v(ms), v(cx), v(cy));
    }
}

/// Lane bits as a mask register (all ones where set).
#[inline]
#[target_feature(enable = "avx2")]
fn lane_mask(bits: i32) -> __m256 {
    let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits), bit), bit))
}

/// The eight f32 of a register.
#[inline]
#[target_feature(enable = "avx2")]
fn floats(v: __m256) -> [f32; 8] {
    let mut out = [0.0; 8];
    // SAFETY: `out` holds eight f32.
    unsafe { _mm256_storeu_ps(out.as_mut_ptr(), v) };
    out
}

/// The eight u32 of a register.
#[inline]
#[target_feature(enable = "avx2")]
fn ints(v: __m256i) -> [u32; 8] {
    let mut out = [0u32; 8];
    // SAFETY: `out` holds eight u32.
    unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), v) };
    out
}

/// The side a [`pick`] chose per lane, with what the rescaling needs.
struct Picked {
    /// `at_least[j - 1]`: lanes whose side is ≥ j (t ≥ prefix j), for j = 1, 2, 3.
    at_least: [__m256; 3],
    /// t less the chosen side's prefix.
    offset: __m256,
    /// The chosen side's weight.
    weight: __m256,
    /// Lane bits whose total is positive (and not NaN).
    ok: i32,
    /// Lane bits the scalar step decides: the chosen side has no mass, or the total overflowed.
    undecided: i32,
}

impl Picked {
    /// Each lane's side: how many prefixes t reached (each mask is −1 where set).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn index(&self) -> __m256i {
        let [a, b, c] = self.at_least.map(|m| _mm256_castps_si256(m));
        _mm256_sub_epi32(_mm256_setzero_si256(), _mm256_add_epi32(_mm256_add_epi32(a, b), c))
    }
}

/// `pick_f32` of eight lanes: prefix sums, t = x·total, the side by the count of prefixes t
/// reached (nested masks, as the weights are not negative).
#[inline]
#[target_feature(enable = "avx2")]
fn pick(w: [__m256; 4], x: __m256) -> Picked {
    let zero = _mm256_setzero_ps();
    let p1 = w[0];
    let p2 = _mm256_add_ps(p1, w[1]);
    let p3 = _mm256_add_ps(p2, w[2]);
    let total = _mm256_add_ps(p3, w[3]);
    let t = _mm256_mul_ps(x, total);
    let ge = |p: __m256| _mm256_cmp_ps::<_CMP_GE_OQ>(t, p);
    let at_least = [ge(p1), ge(p2), ge(p3)];
    let weight = select(at_least, w);
    let empty_side = _mm256_cmp_ps::<_CMP_NGT_UQ>(weight, zero);
    let overflow = _mm256_cmp_ps::<_CMP_EQ_OQ>(total, _mm256_set1_ps(f32::INFINITY));
    Picked {
        at_least,
        offset: _mm256_sub_ps(t, select(at_least, [zero, p1, p2, p3])),
        weight,
        ok: _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(total, zero)),
        undecided: _mm256_movemask_ps(_mm256_or_ps(empty_side, overflow)),
    }
}

/// Per lane, `v[j]` for the largest j whose mask `at_least[j - 1]` is set (else `v[0]`).
#[inline]
#[target_feature(enable = "avx2")]
fn select(at_least: [__m256; 3], v: [__m256; 4]) -> __m256 {
    let s = _mm256_blendv_ps(v[0], v[1], at_least[0]);
    let s = _mm256_blendv_ps(s, v[2], at_least[1]);
    _mm256_blendv_ps(s, v[3], at_least[2])
}

/// `f32::clamp(v, 0, ONE_MINUS_EPSILON_F32)` per lane.
#[inline]
#[target_feature(enable = "avx2")]
fn clamp_unit(v: __m256) -> __m256 {
    let (lo, hi) = (_mm256_setzero_ps(), _mm256_set1_ps(ONE_MINUS_EPSILON_F32));
    let v = _mm256_blendv_ps(v, lo, _mm256_cmp_ps::<_CMP_LT_OQ>(v, lo));
    _mm256_blendv_ps(v, hi, _mm256_cmp_ps::<_CMP_GT_OQ>(v, hi))
}

/// Eight lanes' sixteen masses, position by position: `out[i]` holds mass i of lanes 0–7
/// (two 8×8 transposes).
#[inline]
#[target_feature(enable = "avx2")]
fn transpose(blocks: [&[f32; 16]; 8]) -> [__m256; 16] {
    let mut out = [_mm256_setzero_ps(); 16];
    for half in 0..2 {
        // SAFETY: each block holds sixteen values; 8·half + 8 ≤ 16.
        let load = |k: usize| unsafe { _mm256_loadu_ps(blocks[k].as_ptr().add(8 * half)) };
        let r = [load(0), load(1), load(2), load(3), load(4), load(5), load(6), load(7)];
        let lo = |a: __m256, b: __m256| _mm256_unpacklo_ps(a, b);
        let hi = |a: __m256, b: __m256| _mm256_unpackhi_ps(a, b);
        let t = [lo(r[0], r[1]), hi(r[0], r[1]), lo(r[2], r[3]), hi(r[2], r[3])];
        let u = [lo(r[4], r[5]), hi(r[4], r[5]), lo(r[6], r[7]), hi(r[6], r[7])];
        let quads = |t: [__m256; 4]| {
            [
                _mm256_shuffle_ps::<0x44>(t[0], t[2]),
                _mm256_shuffle_ps::<0xEE>(t[0], t[2]),
                _mm256_shuffle_ps::<0x44>(t[1], t[3]),
                _mm256_shuffle_ps::<0xEE>(t[1], t[3]),
            ]
        };
        let (a, b) = (quads(t), quads(u));
        for j in 0..4 {
            out[8 * half + j] = _mm256_permute2f128_ps::<0x20>(a[j], b[j]);
            out[8 * half + 4 + j] = _mm256_permute2f128_ps::<0x31>(a[j], b[j]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{build_pyramid, pyramid_len};
    use glam::DVec2;
    use std::vec;
    use std::vec::Vec;

    #[test]
    fn eight_lanes_in_a_register_descend_as_the_scalar_lanes() {
        if !crate::cpu::has_avx2() {
            std::println!("no AVX2 here: the scalar descent is the only one");
            return;
        }
        for level in [1u32, 2, 4, 5, 7] {
            for rgb in super::super::test_maps::maps(level) {
                let mut p = vec![0.0f32; pyramid_len(level)];
                build_pyramid(level, &rgb, &mut p).unwrap();
                let env = EnvHierarchy::new(level, &p, &rgb).unwrap();
                let mut u = vec![DVec2::ZERO; 4099];
                crate::points::sobol02(u64::from(level), 0, &mut u);
                u[1] = DVec2::new(1.0, 1.0);
                u[2] = DVec2::new(0.0, 1.0);
                for size in [64, 13, 8, 3] {
                    for chunk in u.chunks(size) {
                        let start: Vec<DescentF32> = chunk.iter().map(|u| DescentF32::from_root(*u)).collect();
                        let (mut simd, mut scalar) = (start.clone(), start);
                        env.descend_f32_avx2(&mut simd);
                        env.descend_f32_scalar(&mut simd);
                        env.descend_f32_scalar(&mut scalar);
                        for (k, (a, b)) in simd.iter().zip(&scalar).enumerate() {
                            assert_eq!(a.alive, b.alive);
                            if a.alive {
                                assert_eq!((a.cell, a.morton), (b.cell, b.morton));
                                assert_eq!((a.xi.x.to_bits(), a.xi.y.to_bits()), (b.xi.x.to_bits(), b.xi.y.to_bits()));
                                let mut xi = super::super::descent_f32::to_unit_f32(chunk[k]);
                                assert_eq!(env.warp_down_f32(&mut xi), Some(a.cell));
                                assert_eq!(xi, a.xi);
                            }
                        }
                    }
                }
            }
        }
    }
}
