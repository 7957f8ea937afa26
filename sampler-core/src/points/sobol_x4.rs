//! Four consecutive points of the scrambled (0,2)-sequence at once: both dimensions' four
//! hashes in one AVX2 register (eight 32-bit lanes), the bit reversal by byte shuffles and a
//! nibble table, the conversion to doubles exact — the same points as one at a time, bit for
//! bit. Where the CPU lacks AVX2 the four take the scalar hash.

use super::sobol::{INV_2_32, scramble_reversed};
use glam::DVec2;

/// Which form of the four-point hash a batch of points takes, asked once per batch (the
/// register form where [`has_avx2`](crate::cpu::has_avx2) says so, else the scalar one).
#[derive(Clone, Copy, Debug)]
pub(super) struct Fours {
    #[cfg(target_arch = "x86_64")]
    avx2: bool,
}

impl Fours {
    /// The form this CPU (and the process's choice of paths) takes now.
    #[inline]
    pub(super) fn new() -> Self {
        Self {
            #[cfg(target_arch = "x86_64")]
            avx2: crate::cpu::has_avx2(),
        }
    }

    /// The points whose dimension-0 points reversed are `i, i + 1, i + 2, i + 3` (wrapping) and
    /// whose dimension-1 points reversed are `y_reversed`, Owen-scrambled with seeds `s0`,
    /// `s1`, into `out`.
    #[inline]
    pub(super) fn scrambled(self, i: u32, y_reversed: [u32; 4], (s0, s1): (u32, u32), out: &mut [DVec2; 4]) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where `has_avx2` says the CPU has AVX2.
            unsafe { avx2::scrambled_four(i, y_reversed, (s0, s1), out) };
            return;
        }
        *out = scalar(i, y_reversed, (s0, s1));
    }
}

/// [`Fours::scrambled`] one point at a time: the reference the register path reproduces.
#[inline]
fn scalar(i: u32, y_reversed: [u32; 4], (s0, s1): (u32, u32)) -> [DVec2; 4] {
    core::array::from_fn(|k| {
        let x = scramble_reversed(i.wrapping_add(k as u32), s0);
        let y = scramble_reversed(y_reversed[k], s1);
        DVec2::new(x as f64 * INV_2_32, y as f64 * INV_2_32)
    })
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::INV_2_32;
    use core::arch::x86_64::*;
    use glam::DVec2;

    /// [`Fours::scrambled`](super::Fours::scrambled) in AVX2: lanes 0–3 dimension 0, lanes 4–7 dimension 1.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn scrambled_four(i: u32, y: [u32; 4], (s0, s1): (u32, u32), out: &mut [DVec2; 4]) {
        let lane = |v: u32| v as i32;
        let mut v = _mm256_setr_epi32(
            lane(i),
            lane(i.wrapping_add(1)),
            lane(i.wrapping_add(2)),
            lane(i.wrapping_add(3)),
            lane(y[0]),
            lane(y[1]),
            lane(y[2]),
            lane(y[3]),
        );
        // `scramble_reversed`'s hash, lane-wise (32-bit products keep their low halves).
        let (a, b) = (lane(s0), lane(s1));
        v = _mm256_add_epi32(v, _mm256_setr_epi32(a, a, a, a, b, b, b, b));
        for m in [0x6c50_b47cu32, 0xb82f_1e52, 0xc7af_e638, 0x8d22_f6e6] {
            v = _mm256_xor_si256(v, _mm256_mullo_epi32(v, _mm256_set1_epi32(lane(m))));
        }
        let v = reverse_bits(v);
        // u32 → f64 exactly: as i32 with the top bit flipped, then 2³¹ back.
        let top = _mm_set1_epi32(i32::MIN);
        let to_unit = |h: __m128i| {
            let d = _mm256_add_pd(_mm256_cvtepi32_pd(_mm_xor_si128(h, top)), _mm256_set1_pd(2_147_483_648.0));
            _mm256_mul_pd(d, _mm256_set1_pd(INV_2_32))
        };
        let (xs, ys) = (to_unit(_mm256_castsi256_si128(v)), to_unit(_mm256_extracti128_si256::<1>(v)));
        // (x0 y0 x2 y2), (x1 y1 x3 y3) → (x0 y0 x1 y1), (x2 y2 x3 y3).
        let (even, odd) = (_mm256_unpacklo_pd(xs, ys), _mm256_unpackhi_pd(xs, ys));
        let p = out.as_mut_ptr().cast::<f64>();
        // SAFETY: `DVec2` is two f64 (`repr(C)`), so `out` is eight contiguous f64.
        unsafe {
            _mm256_storeu_pd(p, _mm256_permute2f128_pd::<0x20>(even, odd));
            _mm256_storeu_pd(p.add(4), _mm256_permute2f128_pd::<0x31>(even, odd));
        }
    }

    /// Each 32-bit lane's bits reversed: its bytes in reverse order, then each byte's two
    /// nibbles swapped and reversed by table.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn reverse_bits(v: __m256i) -> __m256i {
        let bytes = _mm256_setr_epi8(
            3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12,
        );
        let v = _mm256_shuffle_epi8(v, bytes);
        let nibble = _mm256_setr_epi8(
            0x0, 0x8, 0x4, 0xC, 0x2, 0xA, 0x6, 0xE, 0x1, 0x9, 0x5, 0xD, 0x3, 0xB, 0x7, 0xF, 0x0, 0x8, 0x4, 0xC, 0x2,
            0xA, 0x6, 0xE, 0x1, 0x9, 0x5, 0xD, 0x3, 0xB, 0x7, 0xF,
        );
        let low = _mm256_set1_epi8(0x0F);
        let lo = _mm256_shuffle_epi8(nibble, _mm256_and_si256(v, low));
        let hi = _mm256_shuffle_epi8(nibble, _mm256_and_si256(_mm256_srli_epi16::<4>(v), low));
        _mm256_or_si256(_mm256_slli_epi16::<4>(lo), hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    #[test]
    fn four_at_once_are_four_one_at_a_time() {
        let mut rng = Pcg32::new(11, 12);
        for k in 0..20_000 {
            let i = if k < 8 { u32::MAX - k } else { rng.next_u32() };
            let y = [rng.next_u32(), rng.next_u32(), rng.next_u32(), rng.next_u32()];
            let seeds = (rng.next_u32(), rng.next_u32());
            let mut a = [DVec2::ZERO; 4];
            Fours::new().scrambled(i, y, seeds, &mut a);
            let b = scalar(i, y, seeds);
            assert_eq!(a, b, "{i} {y:?} {seeds:?}");
        }
    }
}
