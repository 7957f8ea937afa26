//! Env-only densities of a batch of points of the square ([`EnvHierarchy::pdf_square_many`]):
//! over the pyramid eight points to an AVX2 register — texel, Morton index and a gather — the
//! same bits as one at a time; the texel table's, and the rest, one at a time.

use super::EnvHierarchy;
#[cfg(target_arch = "x86_64")]
use super::pyramid::level_offset;
use glam::Vec2;

impl EnvHierarchy<'_> {
    /// [`pdf_square`](Self::pdf_square) for every point of `uv` (as many as both hold), the
    /// same bits.
    pub fn pdf_square_many(&self, uv: &[Vec2], out: &mut [f32]) {
        let len = uv.len().min(out.len());
        let done = self.pdf_square_eights(&uv[..len], &mut out[..len]);
        for (o, p) in out[done..len].iter_mut().zip(&uv[done..len]) {
            *o = self.pdf_square(*p);
        }
    }

    /// The densities of the leading groups of eight points over the pyramid where the CPU has
    /// AVX2; how many points it wrote (none under a texel table, or without AVX2).
    #[cfg(target_arch = "x86_64")]
    fn pdf_square_eights(&self, uv: &[Vec2], out: &mut [f32]) -> usize {
        if self.cdf.is_some() || !crate::cpu::has_avx2() {
            return 0;
        }
        let n = self.resolution();
        let start = level_offset(self.finest);
        let finest = &self.pyramid[start..start + (n as usize) * (n as usize)];
        let (eights, _) = uv.as_chunks::<8>();
        for (p, o) in eights.iter().zip(out.as_chunks_mut::<8>().0) {
            // SAFETY: AVX2 is available (checked above).
            *o = unsafe { avx2::densities(finest, n, self.inv_mean, p) };
        }
        8 * eights.len()
    }

    #[cfg(not(target_arch = "x86_64"))]
    fn pdf_square_eights(&self, _uv: &[Vec2], _out: &mut [f32]) -> usize {
        0
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use core::arch::x86_64::*;
    use glam::Vec2;

    /// The densities of eight points over the finest level `finest` (`n × n` texels in Morton
    /// order): `texel_of`'s clamps in f32 before the truncation, `morton2`'s interleaving by
    /// shifts and masks, the texels gathered and scaled by `inv_mean`.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn densities(finest: &[f32], n: u32, inv_mean: f32, p: &[Vec2; 8]) -> [f32; 8] {
        // SAFETY: eight `Vec2` are sixteen contiguous f32.
        let (a, b) = unsafe {
            let f = p.as_ptr().cast::<f32>();
            (_mm256_loadu_ps(f), _mm256_loadu_ps(f.add(8)))
        };
        // (x0 x1 x4 x5 | x2 x3 x6 x7) → (x0 … x7); the same for y.
        let order = |v: __m256| _mm256_castpd_ps(_mm256_permute4x64_pd::<0xD8>(_mm256_castps_pd(v)));
        let (xs, ys) = (order(_mm256_shuffle_ps::<0x88>(a, b)), order(_mm256_shuffle_ps::<0xDD>(a, b)));
        // `(p · n) as u32` then `min(n − 1)`: NaN and negatives to 0 (`max` returns its second
        // operand for NaN), the top clamped before truncating, which truncates to the same.
        let (nf, top) = (_mm256_set1_ps(n as f32), _mm256_set1_ps((n - 1) as f32));
        let texel = |v: __m256| {
            let c = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(v, nf), _mm256_setzero_ps()), top);
            spread(_mm256_cvttps_epi32(c))
        };
        let morton = _mm256_or_si256(texel(xs), _mm256_slli_epi32::<1>(texel(ys)));
        let mut idx = [0u32; 8];
        // SAFETY: `idx` holds eight u32.
        unsafe { _mm256_storeu_si256(idx.as_mut_ptr().cast(), morton) };
        // Scalar loads, each bounds-checked: no texel outside `finest` is read.
        let texels: [f32; 8] = core::array::from_fn(|k| finest[idx[k] as usize]);
        // SAFETY: eight f32 in, eight out.
        let v = unsafe { _mm256_loadu_ps(texels.as_ptr()) };
        let mut out = [0.0f32; 8];
        // SAFETY: `out` holds eight f32.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), _mm256_mul_ps(v, _mm256_set1_ps(inv_mean))) };
        out
    }

    /// Each lane's low 16 bits spread to the even bits (`morton2`'s spread).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn spread(v: __m256i) -> __m256i {
        let v = _mm256_and_si256(_mm256_or_si256(v, _mm256_slli_epi32::<8>(v)), _mm256_set1_epi32(0x00FF_00FF));
        let v = _mm256_and_si256(_mm256_or_si256(v, _mm256_slli_epi32::<4>(v)), _mm256_set1_epi32(0x0F0F_0F0F));
        let v = _mm256_and_si256(_mm256_or_si256(v, _mm256_slli_epi32::<2>(v)), _mm256_set1_epi32(0x3333_3333));
        _mm256_and_si256(_mm256_or_si256(v, _mm256_slli_epi32::<1>(v)), _mm256_set1_epi32(0x5555_5555))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{TexelCdf, build_pyramid};

    #[test]
    fn batched_densities_are_the_single_densities() {
        use crate::env::{build_texel_cdf, texel_cdf_len, texel_guide_len};
        let mut rgb = [[0.0f32; 3]; 256];
        for (i, t) in rgb.iter_mut().enumerate() {
            *t = [(i * 7 % 11) as f32, (i % 3) as f32, if i == 40 { 1e5 } else { 0.25 }];
        }
        let mut p = [0.0f32; 341];
        build_pyramid(4, &rgb, &mut p).unwrap();
        let (mut ends, mut guide) = (std::vec![0u32; texel_cdf_len(4)], std::vec![0u32; texel_guide_len(4)]);
        build_texel_cdf(4, &p, &mut ends, &mut guide).unwrap();
        let plain = EnvHierarchy::new(4, &p, &rgb).unwrap();
        let table = plain.with_texel_cdf(TexelCdf::new(4, &ends, &guide).unwrap()).unwrap();
        let mut uv = [Vec2::ZERO; 300];
        for (k, q) in uv.iter_mut().enumerate() {
            *q = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 * 0.414_213_57).fract());
        }
        (uv[0], uv[1], uv[2]) = (Vec2::ONE, Vec2::new(-0.5, f32::NAN), Vec2::splat(2.0));
        for env in [plain, table] {
            let mut out = [0.0f32; 300];
            env.pdf_square_many(&uv, &mut out);
            for (q, o) in uv.iter().zip(out) {
                assert_eq!(o.to_bits(), env.pdf_square(*q).to_bits(), "{q:?}");
            }
        }
    }
}
