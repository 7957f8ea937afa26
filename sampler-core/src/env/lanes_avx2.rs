//! Env-only descents four to a register: [`choose_grandchild_branchless`]'s step for four
//! descents at once in AVX2 (four f64 lanes), with the same operations in the same order — the
//! same choices and rescaled points, bit for bit. The lanes' ξ, Morton indices and cells stay
//! in registers from the root down; per step only the four addresses of the next sixteen
//! grandchildren leave them. Up to [`IN_FLIGHT`] lanes descend together, level by level, every
//! group's loads asked for before any group's arithmetic, so that their cache misses overlap.
//! A lane whose chosen side holds no mass (rounding at a row's end) takes the scalar step
//! instead.

use super::EnvHierarchy;
use super::lanes::{IN_FLIGHT, WarpLane};
use super::lanes_avx2_ops::{clamp_unit, floats, ints, lane_mask, pick_x4, select, transpose};
use super::pyramid::level_offset;
use crate::cell::Cell;
use crate::prefetch::prefetch;
use crate::warp::{choose_grandchild_branchless, grandchild_index};
use core::arch::x86_64::*;

/// Masses of a lane that takes no part (dead, or past the end): no mass, so it picks nothing.
static EMPTY: [f32; 16] = [0.0; 16];

/// Groups of four lanes a descent advances level by level together: every group's next loads
/// are asked for before any group's arithmetic, so that the deep levels' cache misses of all
/// of them are in flight at once.
const GROUPS: usize = IN_FLIGHT / 4;

impl EnvHierarchy<'_> {
    /// Descends `lanes`, each from its own node, two levels at a time while two remain, four
    /// lanes to a register, as [`warp_down_lanes_scalar`](Self::warp_down_lanes_scalar) would
    /// (a black map's lanes die at their first step, there as here); nothing where the CPU
    /// lacks AVX2. A last single level is left to the scalar lanes.
    pub(super) fn warp_down_pairs_avx2(&self, lanes: &mut [WarpLane]) {
        if !crate::cpu::has_avx2() {
            return;
        }
        for chunk in lanes.chunks_mut(IN_FLIGHT) {
            // SAFETY: AVX2 is available (checked above).
            unsafe { self.descend_groups(chunk) };
        }
    }

    /// Up to [`IN_FLIGHT`] lanes down to the last even step above the finest level, in groups
    /// of four advanced a level pair at a time: first every group's sixteen grandchildren per
    /// lane are asked for, then each group steps.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn descend_groups(&self, lanes: &mut [WarpLane]) {
        let n = lanes.len().div_ceil(4).min(GROUPS);
        let mut groups = [Group::load(&[]); GROUPS];
        for (g, four) in groups.iter_mut().zip(lanes.chunks(4)) {
            *g = Group::load(four);
        }
        let mut active = [0i32; GROUPS];
        let mut blocks = [[&EMPTY; 4]; GROUPS];
        loop {
            // No closures through generic code here: they would not inherit AVX2 and so
            // would not inline.
            let mut any = false;
            for k in 0..n {
                active[k] = groups[k].active(self.finest);
                if active[k] != 0 {
                    blocks[k] = groups[k].blocks(self.pyramid, active[k]);
                    blocks[k].iter().for_each(|b| prefetch(&b[..]));
                    any = true;
                }
            }
            if !any {
                break;
            }
            for k in 0..n {
                if active[k] != 0 {
                    groups[k].step(active[k], blocks[k]);
                }
            }
        }
        for (g, four) in groups.iter().zip(lanes.chunks_mut(4)) {
            g.store(four);
        }
    }
}

/// Four descents in registers: ξ, the Morton index and the cell's column and row per lane.
#[derive(Clone, Copy)]
struct Group {
    xi_x: __m256d,
    xi_y: __m256d,
    morton: __m256i,
    x: __m256i,
    y: __m256i,
    /// Lane bits not dead.
    alive: i32,
    /// Per lane, the level of its node.
    level: [u32; 4],
}

impl Group {
    /// The state of `lanes` (up to four); missing lanes are dead.
    #[target_feature(enable = "avx2")]
    fn load(lanes: &[WarpLane]) -> Self {
        let get = |k: usize, f: fn(&WarpLane) -> u64| lanes.get(k).map_or(0, f);
        let ints = |f: fn(&WarpLane) -> u64| {
            _mm256_setr_epi64x(get(0, f) as i64, get(1, f) as i64, get(2, f) as i64, get(3, f) as i64)
        };
        let xs = |f: fn(&WarpLane) -> u64| {
            _mm256_setr_pd(
                f64::from_bits(get(0, f)),
                f64::from_bits(get(1, f)),
                f64::from_bits(get(2, f)),
                f64::from_bits(get(3, f)),
            )
        };
        let alive = lanes.iter().take(4).enumerate().filter(|(_, l)| l.alive).fold(0, |a, (k, _)| a | 1 << k);
        Self {
            xi_x: xs(|l| l.xi.x.to_bits()),
            xi_y: xs(|l| l.xi.y.to_bits()),
            morton: ints(|l| l.morton as u64),
            x: ints(|l| u64::from(l.cell.x)),
            y: ints(|l| u64::from(l.cell.y)),
            alive,
            level: core::array::from_fn(|k| lanes.get(k).map_or(0, |l| l.cell.level)),
        }
    }

    /// Writes the state back into `lanes`.
    #[target_feature(enable = "avx2")]
    fn store(&self, lanes: &mut [WarpLane]) {
        let [xs, ys] = [self.xi_x, self.xi_y].map(|v| floats(v));
        let [ms, cx, cy] = [self.morton, self.x, self.y].map(|v| ints(v));
        for (k, lane) in lanes.iter_mut().enumerate().take(4).filter(|(_, l)| l.alive) {
            lane.xi = glam::DVec2::new(xs[k], ys[k]);
            lane.morton = ms[k] as usize;
            lane.cell = Cell::new(self.level[k], cx[k] as u32, cy[k] as u32);
            lane.alive = self.alive & (1 << k) != 0;
        }
    }

    /// Lane bits alive with two levels left above `finest`.
    fn active(&self, finest: u32) -> i32 {
        let mut bits = 0;
        for k in 0..4 {
            if self.alive & (1 << k) != 0 && self.level[k] + 2 <= finest {
                bits |= 1 << k;
            }
        }
        bits
    }

    /// Each active lane's sixteen grandchildren, [`EMPTY`] for the others.
    #[target_feature(enable = "avx2")]
    fn blocks<'p>(&self, pyramid: &'p [f32], active: i32) -> [&'p [f32; 16]; 4] {
        let ms = ints(self.morton);
        let mut out = [&EMPTY; 4];
        for k in 0..4 {
            if active & (1 << k) != 0 {
                let at = level_offset(self.level[k] + 2) + 16 * ms[k] as usize;
                out[k] = pyramid[at..at + 16].try_into().expect("sixteen grandchildren");
            }
        }
        out
    }

    /// One two-level step of the `active` lanes over their grandchildren `blocks`.
    #[target_feature(enable = "avx2")]
    fn step(&mut self, active: i32, blocks: [&[f32; 16]; 4]) {
        let m = transpose(blocks);
        let at = |x: usize, y: usize| m[grandchild_index(x as u32, y as u32)];
        let col = |x: usize| _mm256_add_pd(_mm256_add_pd(at(x, 0), at(x, 1)), _mm256_add_pd(at(x, 2), at(x, 3)));
        let cols = [col(0), col(1), col(2), col(3)];
        let column = pick_x4(cols, self.xi_x);
        // The chosen column's four masses, by the same nested masks that chose it.
        let row_of = |y: usize| select(column.at_least, [at(0, y), at(1, y), at(2, y), at(3, y)]);
        let rows = [row_of(0), row_of(1), row_of(2), row_of(3)];
        let row = pick_x4(rows, self.xi_y);
        // rescale: r = 1/(wx·wy), ξ = (ox·wy·r, oy·wx·r) clamped to [0, 1).
        let r = _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_mul_pd(column.weight, row.weight));
        let nx = clamp_unit(_mm256_mul_pd(_mm256_mul_pd(column.offset, row.weight), r));
        let ny = clamp_unit(_mm256_mul_pd(_mm256_mul_pd(row.offset, column.weight), r));
        // The grandchild (gx, gy) and its Morton index x0 | y0 << 1 | x1 << 2 | y1 << 3.
        let (gx, gy) = (column.index(), row.index());
        let one = _mm256_set1_epi64x(1);
        let bits = |v: __m256i, low: i32, high: i32| {
            _mm256_or_si256(
                _mm256_sll_epi64(_mm256_and_si256(v, one), _mm_cvtsi32_si128(low)),
                _mm256_sll_epi64(_mm256_srli_epi64::<1>(v), _mm_cvtsi32_si128(high)),
            )
        };
        let child = _mm256_or_si256(bits(gx, 0, 2), bits(gy, 1, 3));
        let old = *self;
        let ok = column.ok & row.ok & active;
        let keep = lane_mask(ok);
        let keep_i = _mm256_castpd_si256(keep);
        self.xi_x = _mm256_blendv_pd(self.xi_x, nx, keep);
        self.xi_y = _mm256_blendv_pd(self.xi_y, ny, keep);
        let advance = |v: __m256i, by: __m256i, shift: i32| {
            let next = _mm256_add_epi64(_mm256_sll_epi64(v, _mm_cvtsi32_si128(shift)), by);
            _mm256_blendv_epi8(v, next, keep_i)
        };
        self.morton = advance(self.morton, child, 4);
        self.x = advance(self.x, gx, 2);
        self.y = advance(self.y, gy, 2);
        // Active lanes without mass die where they are; the others move two levels down.
        self.alive &= !(active & !ok);
        for k in 0..4 {
            self.level[k] += if ok & (1 << k) != 0 { 2 } else { 0 };
        }
        let fallback = (column.fallback | row.fallback) & ok;
        if fallback != 0 {
            self.redo_scalar(&old, blocks, fallback);
        }
    }

    /// The scalar step, from the state before it (`old`), for the lanes of `fallback`: rounding
    /// put t past a side of mass, which the scalar step's own fallback decides.
    #[cold]
    #[target_feature(enable = "avx2")]
    fn redo_scalar(&mut self, old: &Group, blocks: [&[f32; 16]; 4], fallback: i32) {
        let [mut xs, mut ys] = [self.xi_x, self.xi_y].map(|v| floats(v));
        let [mut ms, mut cx, mut cy] = [self.morton, self.x, self.y].map(|v| ints(v));
        let [ox, oy] = [old.xi_x, old.xi_y].map(|v| floats(v));
        let [om, ocx, ocy] = [old.morton, old.x, old.y].map(|v| ints(v));
        for k in (0..4).filter(|k| fallback & (1 << k) != 0) {
            let mut xi = glam::DVec2::new(ox[k], oy[k]);
            match choose_grandchild_branchless(blocks[k], &mut xi) {
                Some((c, gx, gy)) => {
                    (xs[k], ys[k]) = (xi.x, xi.y);
                    ms[k] = (om[k] << 4) + c as u64;
                    (cx[k], cy[k]) = ((ocx[k] << 2) + u64::from(gx), (ocy[k] << 2) + u64::from(gy));
                }
                None => {
                    (xs[k], ys[k], ms[k], cx[k], cy[k]) = (ox[k], oy[k], om[k], ocx[k], ocy[k]);
                    self.alive &= !(1 << k);
                    self.level[k] = old.level[k];
                }
            }
        }
        self.xi_x = _mm256_setr_pd(xs[0], xs[1], xs[2], xs[3]);
        self.xi_y = _mm256_setr_pd(ys[0], ys[1], ys[2], ys[3]);
        let v = |a: [u64; 4]| _mm256_setr_epi64x(a[0] as i64, a[1] as i64, a[2] as i64, a[3] as i64);
        (self.morton, self.x, self.y) = (v(ms), v(cx), v(cy));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::Cell;
    use crate::env::{build_pyramid, pyramid_len};
    use crate::warp::ONE_MINUS_EPSILON;
    use glam::DVec2;
    use std::vec;
    use std::vec::Vec;

    #[test]
    fn four_lanes_in_a_register_descend_as_the_scalar_lanes() {
        if !crate::cpu::has_avx2() {
            std::println!("no AVX2 here: the scalar descent is the only one");
            return;
        }
        for level in [1u32, 4, 5, 7] {
            for rgb in super::super::test_maps::maps(level) {
                let mut p = vec![0.0f32; pyramid_len(level)];
                build_pyramid(level, &rgb, &mut p).unwrap();
                let env = EnvHierarchy::new(level, &p, &rgb).unwrap();
                let mut u = vec![DVec2::ZERO; 4099];
                crate::points::sobol02(u64::from(level), 0, &mut u);
                u[1] = DVec2::new(ONE_MINUS_EPSILON, ONE_MINUS_EPSILON);
                u[2] = DVec2::new(0.0, ONE_MINUS_EPSILON);
                // From the root, and from nodes of every level (the product's leaves), in
                // groups of every size.
                let node = |k: usize| {
                    let l = (k as u32 * 7) % (level + 1);
                    let side = 1u32 << l;
                    Cell::new(l, (k as u32 * 13) % side, (k as u32 * 29) % side)
                };
                for (mixed, size) in [(false, 8), (true, 7), (true, 3)] {
                    for (c, chunk) in u.chunks(size).enumerate() {
                        let start: Vec<WarpLane> = chunk
                            .iter()
                            .enumerate()
                            .map(|(k, u)| WarpLane::new(if mixed { node(c * size + k) } else { Cell::ROOT }, *u))
                            .collect();
                        let (mut simd, mut scalar) = (start.clone(), start);
                        env.warp_down_lanes(&mut simd);
                        env.warp_down_lanes_scalar(&mut scalar);
                        for (a, b) in simd.iter().zip(&scalar) {
                            assert_eq!((a.alive, a.cell, a.morton), (b.alive, b.cell, b.morton));
                            assert_eq!((a.xi.x.to_bits(), a.xi.y.to_bits()), (b.xi.x.to_bits(), b.xi.y.to_bits()));
                        }
                    }
                }
            }
        }
    }
}
