//! The first two dimensions of Sobol's sequence, a (0,2)-sequence, from byte tables and from
//! each point to the next, with Owen scrambling by hashing ([`Sobol02`]) or a digital shift
//! ([`sobol02_shifted`]).

use super::sobol_x4::Fours;
use crate::rng::hash_combine;
use glam::{DVec2, Vec2};

pub(super) const INV_2_32: f64 = 1.0 / 4_294_967_296.0;

/// Generator matrix columns of the first two Sobol' dimensions: the identity (van der
/// Corput, bits reversed) and the primitive polynomial x + 1 (vₖ = vₖ₋₁ ⊕ (vₖ₋₁ >> 1)).
const fn generator(dim: usize) -> [u32; 32] {
    let mut v = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        v[k] = if dim == 0 {
            1 << (31 - k)
        } else if k == 0 {
            1 << 31
        } else {
            v[k - 1] ^ (v[k - 1] >> 1)
        };
        k += 1;
    }
    v
}

/// Sobol' points are linear over GF(2) in the index bits: x(i) = ⊕ over the bytes of i of a
/// 256-entry table per byte. Four byte tables per dimension (8 KB in all), built at compile time.
const fn byte_tables(dim: usize) -> [[u32; 256]; 4] {
    let v = generator(dim);
    let mut t = [[0u32; 256]; 4];
    let mut b = 0;
    while b < 4 {
        let mut i = 0;
        while i < 256 {
            let mut x = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if i & (1 << bit) != 0 {
                    x ^= v[8 * b + bit];
                }
                bit += 1;
            }
            t[b][i] = x;
            i += 1;
        }
        b += 1;
    }
    t
}

static SOBOL_TABLES: [[[u32; 256]; 4]; 2] = [byte_tables(0), byte_tables(1)];

/// The second dimension's byte tables with every entry's bits reversed: bit reversal commutes
/// with XOR, so these give the reversed point that Owen scrambling starts from.
static SOBOL_DIM1_REVERSED: [[u32; 256]; 4] = reversed(byte_tables(1));

/// Per dimension, entry m: the point of the index whose m + 1 lowest bits are set (all 32 for
/// m = 32). From index i to i + 1 the trailing ones of i and the bit above them flip, so by
/// linearity x(i + 1) = x(i) ⊕ `SOBOL_STEPS[dim][trailing_ones(i)]`.
static SOBOL_STEPS: [[u32; 33]; 2] = [steps(0), steps(1)];

/// [`SOBOL_STEPS`] of the second dimension with every entry's bits reversed, the steps of
/// [`SOBOL_DIM1_REVERSED`]'s points.
static SOBOL_DIM1_STEPS_REVERSED: [u32; 33] = reversed_steps(steps(1));

const fn reversed_steps(mut t: [u32; 33]) -> [u32; 33] {
    let mut m = 0;
    while m < 33 {
        t[m] = t[m].reverse_bits();
        m += 1;
    }
    t
}

const fn steps(dim: usize) -> [u32; 33] {
    let v = generator(dim);
    let mut t = [0u32; 33];
    let (mut m, mut x) = (0, 0u32);
    while m < 33 {
        if m < 32 {
            x ^= v[m];
        }
        t[m] = x;
        m += 1;
    }
    t
}

const fn reversed(mut t: [[u32; 256]; 4]) -> [[u32; 256]; 4] {
    let mut b = 0;
    while b < 4 {
        let mut i = 0;
        while i < 256 {
            t[b][i] = t[b][i].reverse_bits();
            i += 1;
        }
        b += 1;
    }
    t
}

#[inline(always)]
fn sobol(dim: usize, index: u32) -> u32 {
    let t = &SOBOL_TABLES[dim];
    let b = index.to_le_bytes();
    t[0][b[0] as usize] ^ t[1][b[1] as usize] ^ t[2][b[2] as usize] ^ t[3][b[3] as usize]
}

/// Point `index` of the first Sobol' dimension (van der Corput) as a 32-bit fraction.
#[inline]
#[must_use]
pub fn sobol_dim0(index: u32) -> u32 {
    sobol(0, index)
}

/// Point `index` of the second Sobol' dimension.
#[inline]
#[must_use]
pub fn sobol_dim1(index: u32) -> u32 {
    sobol(1, index)
}

/// Owen scrambling by hashing (Burley 2020, after Laine & Karras 2011).
#[inline]
#[must_use]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    scramble_reversed(x.reverse_bits(), seed)
}

/// [`nested_uniform_scramble`] of the point whose bits reversed are `v`.
#[inline(always)]
pub(super) fn scramble_reversed(mut v: u32, seed: u32) -> u32 {
    v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v.reverse_bits()
}

/// Points `first .. first + out.len()` of an Owen-scrambled (0,2)-sequence. Any power-of-two
/// run starting at a multiple of its length is a (0,m,2)-net: stratified in every elementary
/// interval. Different seeds give independent randomisations.
pub fn sobol02(seed: u64, first: u32, out: &mut [DVec2]) {
    Sobol02::new(seed).fill(first, out);
}

/// The Owen-scrambled (0,2)-sequence of one seed ([`sobol02`]), its scrambling derived once
/// for callers that take a few points at a time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sobol02 {
    s0: u32,
    s1: u32,
}

impl Sobol02 {
    /// The sequence of `seed`.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self { s0: hash_combine(seed, 0x5eed_0000) as u32, s1: hash_combine(seed, 0x5eed_0001) as u32 }
    }

    /// Points `first .. first + out.len()`, four at a time (`sobol_x4.rs`).
    pub fn fill(&self, first: u32, out: &mut [DVec2]) {
        let seeds = (self.s0, self.s1);
        let mut y_reversed = dim1_reversed(first);
        let mut i = first;
        let (fours, rest) = out.as_chunks_mut::<4>();
        let form = Fours::new();
        for four in fours {
            // The first dimension is the index with its bits reversed, so reversed it is the
            // index; the second steps from each point to the next.
            let ys = core::array::from_fn(|k| {
                let y = y_reversed;
                y_reversed ^= SOBOL_DIM1_STEPS_REVERSED[i.wrapping_add(k as u32).trailing_ones() as usize];
                y
            });
            form.scrambled(i, ys, seeds, four);
            i = i.wrapping_add(4);
        }
        for (p, q) in rest.iter_mut().zip(self.points(i)) {
            *p = q;
        }
    }

    /// Points `first, first + 1, …` (wrapping after index 2³² − 1), for callers that take them
    /// one at a time without a buffer.
    #[inline]
    pub fn points(&self, first: u32) -> impl Iterator<Item = DVec2> + use<> {
        let Self { s0, s1 } = *self;
        // The second dimension's reversed point from the byte tables once, then from each
        // point to the next by one step (`SOBOL_STEPS`, reversed): the same points.
        let mut y_reversed = dim1_reversed(first);
        let mut i = first;
        core::iter::from_fn(move || {
            // The first dimension is the index with its bits reversed, so reversed it is the index.
            let x = scramble_reversed(i, s0);
            let y = scramble_reversed(y_reversed, s1);
            y_reversed ^= SOBOL_DIM1_STEPS_REVERSED[i.trailing_ones() as usize];
            i = i.wrapping_add(1);
            Some(DVec2::new(x as f64 * INV_2_32, y as f64 * INV_2_32))
        })
    }
}

/// Point `index` of the second dimension with its bits reversed, from the byte tables.
#[inline(always)]
fn dim1_reversed(index: u32) -> u32 {
    let b = index.to_le_bytes();
    let t = &SOBOL_DIM1_REVERSED;
    t[0][b[0] as usize] ^ t[1][b[1] as usize] ^ t[2][b[2] as usize] ^ t[3][b[3] as usize]
}

/// Points `first .. first + out.len()` of the (0,2)-sequence randomised by a digital shift
/// (XOR with a random 32-bit word per dimension; Kollig & Keller 2002). Keeps the net
/// property and costs a few operations per point; cheaper but less variance-reducing than
/// [`sobol02`]'s Owen scrambling. Single precision (24 bits): used for the BRDF samples of B̃.
pub fn sobol02_shifted(seed: u64, first: u32, out: &mut [Vec2]) {
    const INV_2_24: f32 = 1.0 / (1u32 << 24) as f32;
    let h = hash_combine(seed, 0x5eed_0002);
    let (s0, s1) = (h as u32, (h >> 32) as u32);
    // Each point from the one before by a single lookup per dimension (`SOBOL_STEPS`): the same
    // points as the byte tables give at every index.
    let (mut x, mut y, mut i) = (sobol_dim0(first) ^ s0, sobol_dim1(first) ^ s1, first);
    for p in out.iter_mut() {
        *p = Vec2::new((x >> 8) as f32 * INV_2_24, (y >> 8) as f32 * INV_2_24);
        let flips = i.trailing_ones() as usize;
        (x, y, i) = (x ^ SOBOL_STEPS[0][flips], y ^ SOBOL_STEPS[1][flips], i.wrapping_add(1));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_match_the_definition() {
        for i in [0u32, 1, 2, 3, 255, 256, 1000, 65_537, u32::MAX] {
            assert_eq!(sobol_dim0(i), i.reverse_bits());
            let mut v = 1u32 << 31;
            let (mut x, mut j) = (0u32, i);
            while j != 0 {
                if j & 1 != 0 {
                    x ^= v;
                }
                j >>= 1;
                v ^= v >> 1;
            }
            assert_eq!(sobol_dim1(i), x, "{i}");
        }
    }

    /// Every elementary interval of area 1/n holds exactly one point.
    fn is_02_net(points: &[DVec2]) -> bool {
        let n = points.len();
        let m = n.trailing_zeros();
        (0..=m).all(|a| {
            let (cx, cy) = (1usize << a, 1usize << (m - a));
            let mut seen = [false; 256];
            points.iter().all(|p| {
                let cell = (p.x * cx as f64) as usize + cx * (p.y * cy as f64) as usize;
                !core::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn the_sequence_is_the_scrambled_sobol_points() {
        let seq = Sobol02::new(77);
        let mut pts = [DVec2::ZERO; 300];
        for first in [0u32, 255, 65_530, 16_777_210, u32::MAX - 299] {
            seq.fill(first, &mut pts);
            for (k, p) in pts.iter().enumerate() {
                let i = first.wrapping_add(k as u32);
                let x = nested_uniform_scramble(sobol_dim0(i), seq.s0) as f64 * INV_2_32;
                let y = nested_uniform_scramble(sobol_dim1(i), seq.s1) as f64 * INV_2_32;
                assert_eq!(*p, DVec2::new(x, y), "point {i}");
            }
        }
    }

    #[test]
    fn the_shifted_sequence_is_the_shifted_sobol_points() {
        let mut pts = [Vec2::ZERO; 300];
        for first in [0u32, 255, 65_530, 16_777_210, u32::MAX - 299, u32::MAX - 5] {
            sobol02_shifted(9, first, &mut pts);
            let h = hash_combine(9, 0x5eed_0002);
            for (k, p) in pts.iter().enumerate() {
                let i = first.wrapping_add(k as u32);
                let at = |x: u32| (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32);
                let expected = Vec2::new(at(sobol_dim0(i) ^ h as u32), at(sobol_dim1(i) ^ (h >> 32) as u32));
                assert_eq!(*p, expected, "point {i} from {first}");
            }
        }
    }

    #[test]
    fn sobol02_is_a_net_scrambled_or_not() {
        let mut pts = [DVec2::ZERO; 64];
        for seed in 0..4 {
            sobol02(seed, 0, &mut pts);
            assert!(is_02_net(&pts));
            sobol02(seed, 64, &mut pts);
            assert!(is_02_net(&pts));
            let mut p32 = [Vec2::ZERO; 64];
            sobol02_shifted(seed, 0, &mut p32);
            let p64: std::vec::Vec<DVec2> = p32.iter().map(|p| p.as_dvec2()).collect();
            assert!(is_02_net(&p64));
        }
    }
}
