//! Env-only descents sixteen to a register: `descent_f32_avx2.rs`'s step in AVX-512 (sixteen f32
//! lanes, mask registers in place of blends), with the same operations in the same order — the
//! same choices and rescaled points as the portable step, bit for bit. Where the CPU has
//! AVX-512F it takes the place of the AVX2 step (docs/perf.md#env-only-sampling-texel-table-cut-table).

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

/// Groups of sixteen descents advanced level by level together.
const GROUPS: usize = IN_FLIGHT / 16;

impl EnvHierarchy<'_> {
    /// Descends `lanes`, all at the root, two levels at a time while two remain, sixteen lanes
    /// to a register; false (nothing done) where the CPU lacks AVX-512F.
    pub(super) fn descend_f32_avx512(&self, lanes: &mut [DescentF32]) -> bool {
        if !crate::cpu::has_avx512f() {
            return false;
        }
        for chunk in lanes.chunks_mut(IN_FLIGHT) {
            // SAFETY: AVX-512F is available (checked above).
            unsafe { self.descend_groups_f32x16(chunk) };
        }
        true
    }

    /// Up to [`IN_FLIGHT`] lanes from the root down to the last even step above the finest level.
    ///
    /// # Safety
    /// The CPU must have AVX-512F.
    #[target_feature(enable = "avx512f")]
    unsafe fn descend_groups_f32x16(&self, lanes: &mut [DescentF32]) {
        let n = lanes.len().div_ceil(16).min(GROUPS);
        let mut groups = [Group::load(&[]); GROUPS];
        for (g, lanes) in groups.iter_mut().zip(lanes.chunks(16)) {
            *g = Group::load(lanes);
        }
        let mut blocks = [[&EMPTY; 16]; GROUPS];
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
        for (g, lanes) in groups.iter().zip(lanes.chunks_mut(16)) {
            g.store(lanes, level);
        }
    }
}

/// Sixteen descents in registers at one level.
#[derive(Clone, Copy)]
struct Group {
    xi_x: __m512,
    xi_y: __m512,
    morton: __m512i,
    x: __m512i,
    y: __m512i,
    alive: u16,
}

impl Group {
    /// The state of `lanes` (up to sixteen, at the root); missing lanes are dead.
    #[target_feature(enable = "avx512f")]
    fn load(lanes: &[DescentF32]) -> Self {
        let (mut xs, mut ys) = ([0.0f32; 16], [0.0f32; 16]);
        let mut alive = 0u16;
        for (k, l) in lanes.iter().take(16).enumerate() {
            (xs[k], ys[k]) = (l.xi.x, l.xi.y);
            alive |= u16::from(l.alive) << k;
        }
        let zero = _mm512_setzero_si512();
        Self { xi_x: load_f(xs), xi_y: load_f(ys), morton: zero, x: zero, y: zero, alive }
    }

    /// Writes the state at `level` back into `lanes`.
    #[target_feature(enable = "avx512f")]
    fn store(&self, lanes: &mut [DescentF32], level: u32) {
        let [xs, ys] = [self.xi_x, self.xi_y].map(|v| floats(v));
        let [ms, cx, cy] = [self.morton, self.x, self.y].map(|v| ints(v));
        for (k, lane) in lanes.iter_mut().enumerate().take(16) {
            lane.alive = self.alive & (1 << k) != 0;
            if lane.alive {
                lane.xi = glam::Vec2::new(xs[k], ys[k]);
                lane.morton = ms[k] as usize;
                lane.cell = Cell::new(level, cx[k], cy[k]);
            }
        }
    }

    /// Each live lane's sixteen grandchildren below `level`, [`EMPTY`] for the others.
    #[target_feature(enable = "avx512f")]
    fn blocks<'p>(&self, pyramid: &'p [f32], level: u32) -> [&'p [f32; 16]; 16] {
        let ms = ints(self.morton);
        let (below, _) = pyramid[level_offset(level + 2)..].as_chunks::<16>();
        let mut out = [&EMPTY; 16];
        for k in 0..16 {
            if self.alive & (1 << k) != 0 {
                out[k] = &below[ms[k] as usize];
            }
        }
        out
    }

    /// One two-level step of the live lanes over their grandchildren `blocks`.
    #[target_feature(enable = "avx512f")]
    fn step(&mut self, blocks: [&[f32; 16]; 16]) {
        let m = transpose(blocks);
        let at = |x: usize, y: usize| m[grandchild_index(x as u32, y as u32)];
        let col = |x: usize| _mm512_add_ps(_mm512_add_ps(at(x, 0), at(x, 1)), _mm512_add_ps(at(x, 2), at(x, 3)));
        let column = pick([col(0), col(1), col(2), col(3)], self.xi_x);
        let row_of = |y: usize| select(column.at_least, [at(0, y), at(1, y), at(2, y), at(3, y)]);
        let row = pick([row_of(0), row_of(1), row_of(2), row_of(3)], self.xi_y);
        let nx = clamp_unit(_mm512_div_ps(column.offset, column.weight));
        let ny = clamp_unit(_mm512_div_ps(row.offset, row.weight));
        let (gx, gy) = (column.index(), row.index());
        let one = _mm512_set1_epi32(1);
        let low = |v: __m512i| _mm512_and_si512(v, one);
        let high = |v: __m512i| _mm512_srli_epi32::<1>(v);
        let child = _mm512_or_si512(
            _mm512_or_si512(low(gx), _mm512_slli_epi32::<1>(low(gy))),
            _mm512_or_si512(_mm512_slli_epi32::<2>(high(gx)), _mm512_slli_epi32::<3>(high(gy))),
        );
        let old = *self;
        let ok = column.ok & self.alive;
        self.xi_x = _mm512_mask_blend_ps(ok, self.xi_x, nx);
        self.xi_y = _mm512_mask_blend_ps(ok, self.xi_y, ny);
        let advance =
            |v: __m512i, by: __m512i, shifted: __m512i| _mm512_mask_blend_epi32(ok, v, _mm512_add_epi32(shifted, by));
        self.morton = advance(self.morton, child, _mm512_slli_epi32::<4>(self.morton));
        self.x = advance(self.x, gx, _mm512_slli_epi32::<2>(self.x));
        self.y = advance(self.y, gy, _mm512_slli_epi32::<2>(self.y));
        self.alive = ok;
        let undecided = (column.undecided | row.undecided | !row.ok) & ok;
        if undecided != 0 {
            self.redo_scalar(&old, blocks, undecided);
        }
    }

    /// The scalar step, from the state before it (`old`), for the lanes of `undecided`.
    #[cold]
    #[target_feature(enable = "avx512f")]
    fn redo_scalar(&mut self, old: &Group, blocks: [&[f32; 16]; 16], undecided: u16) {
        let [mut xs, mut ys] = [old.xi_x, old.xi_y].map(|v| floats(v));
        let [mut ms, mut cx, mut cy] = [self.morton, self.x, self.y].map(|v| ints(v));
        let [om, ocx, ocy] = [old.morton, old.x, old.y].map(|v| ints(v));
        let [nx, ny] = [self.xi_x, self.xi_y].map(|v| floats(v));
        for k in 0..16 {
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
        (self.xi_x, self.xi_y) = (load_f(xs), load_f(ys));
        (self.morton, self.x, self.y) = (load_i(ms), load_i(cx), load_i(cy));
    }
}

/// Sixteen f32 into a register.
#[inline]
#[target_feature(enable = "avx512f")]
fn load_f(a: [f32; 16]) -> __m512 {
    // SAFETY: `a` holds sixteen f32.
    unsafe { _mm512_loadu_ps(a.as_ptr()) }
}

/// Sixteen u32 into a register.
#[inline]
#[target_feature(enable = "avx512f")]
fn load_i(a: [u32; 16]) -> __m512i {
    // SAFETY: `a` holds sixteen u32.
    unsafe { _mm512_loadu_si512(a.as_ptr().cast()) }
}

/// The sixteen f32 of a register.
#[inline]
#[target_feature(enable = "avx512f")]
fn floats(v: __m512) -> [f32; 16] {
    let mut out = [0.0; 16];
    // SAFETY: `out` holds sixteen f32.
    unsafe { _mm512_storeu_ps(out.as_mut_ptr(), v) };
    out
}

/// The sixteen u32 of a register.
#[inline]
#[target_feature(enable = "avx512f")]
fn ints(v: __m512i) -> [u32; 16] {
    let mut out = [0u32; 16];
    // SAFETY: `out` holds sixteen u32.
    unsafe { _mm512_storeu_si512(out.as_mut_ptr().cast(), v) };
    out
}

/// The side a [`pick`] chose per lane: as `descent_f32_avx2.rs`'s, with masks.
struct Picked {
    /// Lanes whose side is ≥ j (t ≥ prefix j), for j = 1, 2, 3.
    at_least: [__mmask16; 3],
    offset: __m512,
    weight: __m512,
    ok: u16,
    undecided: u16,
}

impl Picked {
    /// Each lane's side: the largest j whose mask is set (the masks are nested).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn index(&self) -> __m512i {
        let [a, b, c] = self.at_least;
        let i = _mm512_maskz_mov_epi32(a, _mm512_set1_epi32(1));
        let i = _mm512_mask_mov_epi32(i, b, _mm512_set1_epi32(2));
        _mm512_mask_mov_epi32(i, c, _mm512_set1_epi32(3))
    }
}

/// `pick_f32` of sixteen lanes: prefix sums, t = x·total, the side by the prefixes t reached.
#[inline]
#[target_feature(enable = "avx512f")]
fn pick(w: [__m512; 4], x: __m512) -> Picked {
    let zero = _mm512_setzero_ps();
    let p1 = w[0];
    let p2 = _mm512_add_ps(p1, w[1]);
    let p3 = _mm512_add_ps(p2, w[2]);
    let total = _mm512_add_ps(p3, w[3]);
    let t = _mm512_mul_ps(x, total);
    let ge = |p: __m512| _mm512_cmp_ps_mask::<_CMP_GE_OQ>(t, p);
    let at_least = [ge(p1), ge(p2), ge(p3)];
    let weight = select(at_least, w);
    let empty_side = _mm512_cmp_ps_mask::<_CMP_NGT_UQ>(weight, zero);
    let overflow = _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(total, _mm512_set1_ps(f32::INFINITY));
    Picked {
        at_least,
        offset: _mm512_sub_ps(t, select(at_least, [zero, p1, p2, p3])),
        weight,
        ok: _mm512_cmp_ps_mask::<_CMP_GT_OQ>(total, zero),
        undecided: empty_side | overflow,
    }
}

/// Per lane, `v[j]` for the largest j whose mask `at_least[j - 1]` is set (else `v[0]`).
#[inline]
#[target_feature(enable = "avx512f")]
fn select(at_least: [__mmask16; 3], v: [__m512; 4]) -> __m512 {
    let s = _mm512_mask_blend_ps(at_least[0], v[0], v[1]);
    let s = _mm512_mask_blend_ps(at_least[1], s, v[2]);
    _mm512_mask_blend_ps(at_least[2], s, v[3])
}

/// `f32::clamp(v, 0, ONE_MINUS_EPSILON_F32)` per lane.
#[inline]
#[target_feature(enable = "avx512f")]
fn clamp_unit(v: __m512) -> __m512 {
    let (lo, hi) = (_mm512_setzero_ps(), _mm512_set1_ps(ONE_MINUS_EPSILON_F32));
    let v = _mm512_mask_blend_ps(_mm512_cmp_ps_mask::<_CMP_LT_OQ>(v, lo), v, lo);
    _mm512_mask_blend_ps(_mm512_cmp_ps_mask::<_CMP_GT_OQ>(v, hi), v, hi)
}

/// Sixteen lanes' sixteen masses, position by position (a 16×16 transpose).
#[inline]
#[target_feature(enable = "avx512f")]
fn transpose(blocks: [&[f32; 16]; 16]) -> [__m512; 16] {
    let mut r = [_mm512_setzero_ps(); 16];
    for k in 0..16 {
        // SAFETY: each block holds sixteen values.
        r[k] = unsafe { _mm512_loadu_ps(blocks[k].as_ptr()) };
    }
    let mut t = [_mm512_setzero_ps(); 16];
    for j in 0..8 {
        t[2 * j] = _mm512_unpacklo_ps(r[2 * j], r[2 * j + 1]);
        t[2 * j + 1] = _mm512_unpackhi_ps(r[2 * j], r[2 * j + 1]);
    }
    let mut u = [_mm512_setzero_ps(); 16];
    for j in 0..4 {
        u[4 * j] = _mm512_shuffle_ps::<0x44>(t[4 * j], t[4 * j + 2]);
        u[4 * j + 1] = _mm512_shuffle_ps::<0xEE>(t[4 * j], t[4 * j + 2]);
        u[4 * j + 2] = _mm512_shuffle_ps::<0x44>(t[4 * j + 1], t[4 * j + 3]);
        u[4 * j + 3] = _mm512_shuffle_ps::<0xEE>(t[4 * j + 1], t[4 * j + 3]);
    }
    let mut out = [_mm512_setzero_ps(); 16];
    for m in 0..4 {
        let a = [u[m], u[4 + m], u[8 + m], u[12 + m]];
        let v0 = _mm512_shuffle_f32x4::<0x44>(a[0], a[1]);
        let v1 = _mm512_shuffle_f32x4::<0xEE>(a[0], a[1]);
        let v2 = _mm512_shuffle_f32x4::<0x44>(a[2], a[3]);
        let v3 = _mm512_shuffle_f32x4::<0xEE>(a[2], a[3]);
        out[m] = _mm512_shuffle_f32x4::<0x88>(v0, v2);
        out[4 + m] = _mm512_shuffle_f32x4::<0xDD>(v0, v2);
        out[8 + m] = _mm512_shuffle_f32x4::<0x88>(v1, v3);
        out[12 + m] = _mm512_shuffle_f32x4::<0xDD>(v1, v3);
    }
    out
}
