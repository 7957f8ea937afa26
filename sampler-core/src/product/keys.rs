//! The samples' sort keys: points of the square quantised to 24 bits per axis and interleaved
//! into a Morton code, so that sorting the keys makes every node of the quadtree a contiguous
//! run of samples whose four children split it by the next two bits (`digit`).

use glam::Vec2;

/// Bits per axis of the quantised square coordinates; also the largest possible depth.
pub const COORD_BITS: u32 = 24;

/// 24-bit fixed-point coordinates of a point of the square.
#[inline]
#[must_use]
pub fn quantize(u: f32) -> u32 {
    let max = (1u32 << COORD_BITS) - 1;
    ((u * (1u32 << COORD_BITS) as f32) as u32).min(max)
}

/// Interleaves two 24-bit coordinates (x in the even bits).
#[inline]
#[must_use]
pub fn morton(x: u32, y: u32) -> u64 {
    spread(x) | (spread(y) << 1)
}

/// The bits of a 24-bit value spread to the even bits, a byte at a time by table (a third
/// of the shifts and masks of spreading the whole word).
#[inline]
fn spread(v: u32) -> u64 {
    let byte = |k: u32| u64::from(SPREAD_BYTE[((v >> (8 * k)) & 0xFF) as usize]) << (16 * k);
    byte(0) | byte(1) | byte(2)
}

/// Each byte's bits spread to the even bits of 16.
const SPREAD_BYTE: [u16; 256] = {
    let mut table = [0u16; 256];
    let mut b = 0;
    while b < 256 {
        let mut bit = 0;
        while bit < 8 {
            table[b] |= (((b >> bit) & 1) << (2 * bit)) as u16;
            bit += 1;
        }
        b += 1;
    }
    table
};

/// Sort key: Morton code in the high 48 bits, sample index in the low 16.
#[inline]
#[must_use]
pub fn sort_key(u: f32, v: f32, index: usize) -> u64 {
    (morton(quantize(u), quantize(v)) << 16) | index as u64
}

/// [`sort_key`] of every point of `uvs` (its index in `uvs` in the low bits) into `keys`, as
/// many as both hold; bit for bit `sort_key`. On x86-64 four points at a time in SSE2 lanes:
/// the quantisation clamped in floats before a signed conversion, the coordinates spread by
/// shifts and masks in 32-bit lanes (the byte tables of [`morton`] cost a load per byte and
/// coordinate, and do not vectorise).
pub fn sort_keys(uvs: &[Vec2], keys: &mut [u64]) {
    let n = uvs.len().min(keys.len());
    let (uvs, keys) = (&uvs[..n], &mut keys[..n]);
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    let done = sse2::sort_keys_x4(uvs, keys);
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    let done = 0;
    for (i, (u, k)) in uvs.iter().zip(keys.iter_mut()).enumerate().skip(done) {
        *k = sort_key(u.x, u.y, i);
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
mod sse2 {
    use super::COORD_BITS;
    use core::arch::x86_64::*;
    use glam::Vec2;

    /// The keys of the leading multiple of four points; returns how many it wrote.
    #[allow(unused_unsafe)]
    pub(super) fn sort_keys_x4(uvs: &[Vec2], keys: &mut [u64]) -> usize {
        let scale = unsafe { _mm_set1_ps((1u32 << COORD_BITS) as f32) };
        let max = unsafe { _mm_set1_ps(((1u32 << COORD_BITS) - 1) as f32) };
        let mut done = 0;
        for (u, k) in uvs.chunks_exact(4).zip(keys.chunks_exact_mut(4)) {
            // SAFETY: SSE2 is enabled (the cfg); the loads read the chunk's eight floats and
            // the stores write the chunk's four keys.
            unsafe {
                let p01 = _mm_loadu_ps(u.as_ptr().cast());
                let p23 = _mm_loadu_ps(u.as_ptr().add(2).cast());
                // `quantize`: `max` returns its second operand (0) for NaN, as `f32::max` does.
                let q =
                    |v: __m128| _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(_mm_mul_ps(v, scale), _mm_setzero_ps()), max));
                let (qx, qy) = (q(_mm_shuffle_ps(p01, p23, 0b10_00_10_00)), q(_mm_shuffle_ps(p01, p23, 0b11_01_11_01)));
                let low16 = _mm_set1_epi32(0xFFFF);
                let interleave = |x: __m128i, y: __m128i| _mm_or_si128(spread16(x), _mm_slli_epi32(spread16(y), 1));
                // The low 16 bits of each axis make the code's low 32 bits, the high 8 its next 16.
                let low = interleave(_mm_and_si128(qx, low16), _mm_and_si128(qy, low16));
                let high = interleave(_mm_srli_epi32(qx, 16), _mm_srli_epi32(qy, 16));
                let i = done as i64;
                let key = |code: __m128i, first: i64| {
                    _mm_or_si128(_mm_slli_epi64(code, 16), _mm_set_epi64x(first + 1, first))
                };
                _mm_storeu_si128(k.as_mut_ptr().cast(), key(_mm_unpacklo_epi32(low, high), i));
                _mm_storeu_si128(k.as_mut_ptr().add(2).cast(), key(_mm_unpackhi_epi32(low, high), i + 2));
            }
            done += 4;
        }
        done
    }

    /// The low 16 bits of each lane spread to its even bits.
    #[inline(always)]
    #[allow(unused_unsafe)]
    fn spread16(v: __m128i) -> __m128i {
        // SAFETY: SSE2 is enabled (the module's cfg).
        unsafe {
            let step =
                |v: __m128i, shifted: __m128i, mask: i32| _mm_and_si128(_mm_or_si128(v, shifted), _mm_set1_epi32(mask));
            let v = step(v, _mm_slli_epi32(v, 8), 0x00FF_00FF);
            let v = step(v, _mm_slli_epi32(v, 4), 0x0F0F_0F0F);
            let v = step(v, _mm_slli_epi32(v, 2), 0x3333_3333);
            step(v, _mm_slli_epi32(v, 1), 0x5555_5555)
        }
    }
}

/// The child digit (dx + 2·dy) of a key at `depth` (the split from depth to depth + 1).
#[inline]
pub(super) fn digit(key: u64, depth: u32) -> usize {
    ((key >> (16 + 2 * (COORD_BITS - 1 - depth))) & 3) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_x_in_even_bits() {
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(0b11, 0b01), 0b0111);
        let top = 1u32 << 23;
        let k = sort_key(0.75, 0.25, 5);
        assert_eq!(digit(k, 0), 1); // right, bottom
        assert_eq!(digit(k, 1), 3); // 0.75 = 0.11b, 0.25 = 0.01b
        assert_eq!(morton(top, top) >> 46, 3);
        // Every bit of both coordinates lands where interleaving puts it.
        for bit in 0..COORD_BITS {
            assert_eq!(morton(1 << bit, 0), 1 << (2 * bit));
            assert_eq!(morton(0, 1 << bit), 1 << (2 * bit + 1));
        }
        assert_eq!(morton(0xFF_FFFF, 0xFF_FFFF), (1 << 48) - 1);
    }

    #[test]
    fn batched_keys_are_sort_key() {
        let edge = [0.0, 1.0, -0.5, 1.5, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.5, 1.0 - f32::EPSILON];
        let mut uvs: std::vec::Vec<Vec2> =
            edge.iter().flat_map(|&u| edge.iter().map(move |&v| Vec2::new(u, v))).collect();
        let mut x = 0x9E37_79B9u32;
        for _ in 0..1000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            uvs.push(Vec2::new(
                (x >> 8) as f32 / (1 << 24) as f32,
                f32::from_bits(0x3F00_0000 | (x & 0x7F_FFFF)) - 0.5,
            ));
        }
        for n in [0, 1, 3, 4, 5, uvs.len()] {
            let mut keys = std::vec![0u64; n];
            sort_keys(&uvs[..n], &mut keys);
            for (i, (uv, k)) in uvs.iter().zip(&keys).enumerate() {
                assert_eq!(*k, sort_key(uv.x, uv.y, i), "{uv:?}");
            }
        }
    }

    #[test]
    fn quantize_clamps() {
        assert_eq!(quantize(1.0), (1 << 24) - 1);
        assert_eq!(quantize(-0.5), 0);
        assert_eq!(quantize(f32::NAN), 0);
        assert_eq!(quantize(0.5), 1 << 23);
    }
}
