//! Four f32 lanes for the leaves' triangle tests, on CPUs without AVX2 the wide nodes' box
//! tests, and the camera's rays four at a time: SSE on x86-64 (part of its baseline, so no run-time detection is needed), plain
//! arrays elsewhere. Both give the same bits: every
//! operation is one IEEE single-precision operation per lane, and `max_or` / `min_or` keep the
//! accumulator where the new value is NaN, as SSE's `maxps` / `minps` do with these operand
//! orders.

#[cfg(target_arch = "x86_64")]
mod imp {
    use std::arch::x86_64::*;

    /// Four lanes.
    #[derive(Clone, Copy)]
    pub(crate) struct F4(__m128);

    impl F4 {
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_set1_ps(x) })
        }

        #[inline(always)]
        pub(crate) fn load(a: &[f32; 4]) -> F4 {
            // SAFETY: `a` is four readable f32s; the load has no alignment requirement.
            F4(unsafe { _mm_loadu_ps(a.as_ptr()) })
        }

        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            let mut out = [0.0; 4];
            // SAFETY: `out` is four writable f32s; the store has no alignment requirement.
            unsafe { _mm_storeu_ps(out.as_mut_ptr(), self.0) };
            out
        }

        #[inline(always)]
        pub(crate) fn add(self, o: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_add_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(crate) fn div(self, o: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_div_ps(self.0, o.0) })
        }

        /// |self| per lane (the sign bit cleared).
        #[inline(always)]
        pub(crate) fn abs(self) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_andnot_ps(_mm_set1_ps(-0.0), self.0) })
        }

        /// Bit k set where lane k of `self` < lane k of `o` (never for NaN).
        #[inline(always)]
        pub(crate) fn lt_mask(self, o: F4) -> u32 {
            // SAFETY: SSE is part of the x86-64 baseline.
            unsafe { _mm_movemask_ps(_mm_cmplt_ps(self.0, o.0)) as u32 }
        }

        #[inline(always)]
        pub(crate) fn sub(self, o: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_sub_ps(self.0, o.0) })
        }

        #[inline(always)]
        pub(crate) fn mul(self, o: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_mul_ps(self.0, o.0) })
        }

        /// Per lane: `self` where it is greater than `acc`, else `acc` (so a NaN `self` keeps `acc`).
        #[inline(always)]
        pub(crate) fn max_or(self, acc: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_max_ps(self.0, acc.0) })
        }

        /// Per lane: `self` where it is less than `acc`, else `acc` (so a NaN `self` keeps `acc`).
        #[inline(always)]
        pub(crate) fn min_or(self, acc: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_min_ps(self.0, acc.0) })
        }

        /// Bit k set where lane k of `self` ≤ lane k of `o`.
        #[inline(always)]
        pub(crate) fn le_mask(self, o: F4) -> u32 {
            // SAFETY: SSE is part of the x86-64 baseline.
            unsafe { _mm_movemask_ps(_mm_cmple_ps(self.0, o.0)) as u32 }
        }

        /// −self per lane (the sign bit flipped, as `f32`'s negation).
        #[inline(always)]
        pub(crate) fn neg(self) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_xor_ps(self.0, _mm_set1_ps(-0.0)) })
        }

        /// √self per lane (correctly rounded, as `f32::sqrt`).
        #[inline(always)]
        pub(crate) fn sqrt(self) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_sqrt_ps(self.0) })
        }

        /// |self| with the sign of `sign` per lane, as `f32::copysign`.
        #[inline(always)]
        pub(crate) fn copysign(self, sign: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe {
                let bit = _mm_set1_ps(-0.0);
                _mm_or_ps(_mm_andnot_ps(bit, self.0), _mm_and_ps(bit, sign.0))
            })
        }

        /// Each lane's sign bit alone (±0).
        #[inline(always)]
        pub(crate) fn sign(self) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_and_ps(_mm_set1_ps(-0.0), self.0) })
        }

        /// The bits of `self` and `o` exclusive-ored per lane: with `o` a [`F4::sign`], `self`
        /// times that sign.
        #[inline(always)]
        pub(crate) fn xor(self, o: F4) -> F4 {
            // SAFETY: SSE is part of the x86-64 baseline.
            F4(unsafe { _mm_xor_ps(self.0, o.0) })
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    /// Four lanes.
    #[derive(Clone, Copy)]
    pub(crate) struct F4([f32; 4]);

    impl F4 {
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> F4 {
            F4([x; 4])
        }

        #[inline(always)]
        pub(crate) fn load(a: &[f32; 4]) -> F4 {
            F4(*a)
        }

        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            self.0
        }

        #[inline(always)]
        pub(crate) fn add(self, o: F4) -> F4 {
            F4(std::array::from_fn(|k| self.0[k] + o.0[k]))
        }

        #[inline(always)]
        pub(crate) fn div(self, o: F4) -> F4 {
            F4(std::array::from_fn(|k| self.0[k] / o.0[k]))
        }

        /// |self| per lane (the sign bit cleared).
        #[inline(always)]
        pub(crate) fn abs(self) -> F4 {
            F4(self.0.map(f32::abs))
        }

        /// Bit k set where lane k of `self` < lane k of `o` (never for NaN).
        #[inline(always)]
        pub(crate) fn lt_mask(self, o: F4) -> u32 {
            (0..4).map(|k| u32::from(self.0[k] < o.0[k]) << k).sum()
        }

        #[inline(always)]
        pub(crate) fn sub(self, o: F4) -> F4 {
            F4(std::array::from_fn(|k| self.0[k] - o.0[k]))
        }

        #[inline(always)]
        pub(crate) fn mul(self, o: F4) -> F4 {
            F4(std::array::from_fn(|k| self.0[k] * o.0[k]))
        }

        /// Per lane: `self` where it is greater than `acc`, else `acc` (so a NaN `self` keeps `acc`).
        #[inline(always)]
        pub(crate) fn max_or(self, acc: F4) -> F4 {
            F4(std::array::from_fn(|k| if self.0[k] > acc.0[k] { self.0[k] } else { acc.0[k] }))
        }

        /// Per lane: `self` where it is less than `acc`, else `acc` (so a NaN `self` keeps `acc`).
        #[inline(always)]
        pub(crate) fn min_or(self, acc: F4) -> F4 {
            F4(std::array::from_fn(|k| if self.0[k] < acc.0[k] { self.0[k] } else { acc.0[k] }))
        }

        /// Bit k set where lane k of `self` ≤ lane k of `o`.
        #[inline(always)]
        pub(crate) fn le_mask(self, o: F4) -> u32 {
            (0..4).map(|k| u32::from(self.0[k] <= o.0[k]) << k).sum()
        }

        /// −self per lane.
        #[inline(always)]
        pub(crate) fn neg(self) -> F4 {
            F4(self.0.map(|x| -x))
        }

        /// √self per lane.
        #[inline(always)]
        pub(crate) fn sqrt(self) -> F4 {
            F4(self.0.map(f32::sqrt))
        }

        /// |self| with the sign of `sign` per lane.
        #[inline(always)]
        pub(crate) fn copysign(self, sign: F4) -> F4 {
            F4(std::array::from_fn(|k| self.0[k].copysign(sign.0[k])))
        }

        /// Each lane's sign bit alone (±0).
        #[inline(always)]
        pub(crate) fn sign(self) -> F4 {
            F4(self.0.map(|x| f32::from_bits(x.to_bits() & 0x8000_0000)))
        }

        /// The bits of `self` and `o` exclusive-ored per lane.
        #[inline(always)]
        pub(crate) fn xor(self, o: F4) -> F4 {
            F4(std::array::from_fn(|k| f32::from_bits(self.0[k].to_bits() ^ o.0[k].to_bits())))
        }
    }
}

pub(crate) use imp::F4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_keeps_the_accumulator_and_comparisons_follow_ieee() {
        let acc = F4::load(&[1.0, 2.0, 3.0, 4.0]);
        let x = F4::load(&[f32::NAN, 5.0, 0.0, f32::NAN]);
        assert_eq!(x.max_or(acc).to_array(), [1.0, 5.0, 3.0, 4.0]);
        assert_eq!(x.min_or(acc).to_array(), [1.0, 2.0, 0.0, 4.0]);
        assert_eq!(x.le_mask(acc), 0b0100);
        assert_eq!(x.lt_mask(acc), 0b0100);
        assert_eq!(F4::splat(2.0).sub(acc).mul(acc).to_array(), [1.0, 0.0, -3.0, -8.0]);
        assert_eq!(F4::splat(-3.0).add(acc).div(acc).abs().to_array(), [2.0, 0.5, 0.0, 0.25]);
        assert_eq!(
            F4::load(&[0.0, -0.0, 1.0, -2.0]).neg().to_array().map(f32::to_bits),
            [-0.0f32, 0.0, -1.0, 2.0].map(f32::to_bits)
        );
        let r = F4::load(&[4.0, -9.0, 2.25, 0.0]).sqrt().to_array();
        assert!(r[0] == 2.0 && r[1].is_nan() && r[2] == 1.5 && r[3] == 0.0);
        let signs = F4::load(&[-1.0, 0.0, -0.0, f32::NAN]);
        let c = F4::load(&[2.0, -3.0, 4.0, -5.0]).copysign(signs).to_array();
        assert_eq!(c.map(f32::to_bits), [-2.0f32, 3.0, -4.0, 5.0f32.copysign(f32::NAN)].map(f32::to_bits));
        let s = F4::load(&[-2.0, 0.0, -0.0, 3.0]).sign();
        assert_eq!(s.to_array().map(f32::to_bits), [-0.0f32, 0.0, -0.0, 0.0].map(f32::to_bits));
        assert_eq!(F4::load(&[1.0, -2.0, 3.0, -0.0]).xor(s).to_array(), [-1.0, -2.0, -3.0, 0.0]);
    }
}
