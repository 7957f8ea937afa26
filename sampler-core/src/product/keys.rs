//! The samples' sort keys: points of the square quantised to 24 bits per axis and interleaved
//! into a Morton code, so that sorting the keys makes every node of the quadtree a contiguous
//! run of samples whose four children split it by the next two bits (`digit`).

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
    fn quantize_clamps() {
        assert_eq!(quantize(1.0), (1 << 24) - 1);
        assert_eq!(quantize(-0.5), 0);
        assert_eq!(quantize(f32::NAN), 0);
        assert_eq!(quantize(0.5), 1 << 23);
    }
}
