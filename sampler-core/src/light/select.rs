//! Picking one light of many in proportion to its power: a cumulative distribution over a
//! caller-owned buffer and a binary search (no alias table: the CDF gives every light's
//! probability exactly as the search uses it, and it needs one buffer of n + 1 values).

/// Lights picked in proportion to given weights (their powers, as luminance).
#[derive(Clone, Copy, Debug)]
pub struct PowerSelector<'a> {
    /// cdf[0] = 0 ≤ cdf[1] ≤ … ≤ cdf[n] = 1. In f64 so that a light a billion times dimmer
    /// than the total keeps a non-zero probability.
    cdf: &'a [f64],
}

/// A light picked by [`PowerSelector::pick`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectedLight {
    /// Index of the light.
    pub index: usize,
    /// Probability with which it was picked.
    pub pmf: f64,
    /// The uniform number `u` rescaled to [0, 1) within the light's interval: a fresh uniform
    /// for the light's own sampling.
    pub u_remapped: f64,
}

impl<'a> PowerSelector<'a> {
    /// Builds the distribution of `weights` into `cdf`, which must hold `weights.len() + 1`
    /// values. `None` when the lengths disagree, a weight is negative or not finite, or all are
    /// zero (nothing to pick).
    pub fn build(weights: &[f32], cdf: &'a mut [f64]) -> Option<Self> {
        if cdf.len() != weights.len() + 1 || weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return None;
        }
        cdf[0] = 0.0;
        for (i, w) in weights.iter().enumerate() {
            cdf[i + 1] = cdf[i] + *w as f64;
        }
        let total = cdf[weights.len()];
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        for c in cdf.iter_mut() {
            *c /= total;
        }
        // Exactly 1 at the end, whatever the rounding of the division.
        cdf[weights.len()] = 1.0;
        Some(Self { cdf })
    }

    /// The selector over a distribution [`PowerSelector::build`] made before (kept by the
    /// caller, e.g. for a whole render): `None` unless `cdf` starts at 0, never decreases and
    /// ends at 1.
    #[must_use]
    pub fn from_cdf(cdf: &'a [f64]) -> Option<Self> {
        let valid =
            cdf.len() >= 2 && cdf[0] == 0.0 && cdf[cdf.len() - 1] == 1.0 && cdf.windows(2).all(|w| w[0] <= w[1]);
        valid.then_some(Self { cdf })
    }

    /// Number of lights.
    #[must_use]
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// There are no lights (never true of a built selector).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The light whose interval of the CDF holds the uniform `u` ∈ [0, 1): the last i with
    /// `cdf[i] ≤ u`, which skips lights of weight 0.
    #[must_use]
    pub fn pick(&self, u: f64) -> SelectedLight {
        let n = self.len();
        let u = u.clamp(0.0, 1.0 - f64::EPSILON / 2.0);
        // The number of cdf[1..=n] values ≤ u is the index, with lights of zero width skipped.
        let index = self.cdf[1..].partition_point(|&c| c <= u).min(n - 1);
        let (lo, hi) = (self.cdf[index], self.cdf[index + 1]);
        let pmf = hi - lo;
        let u_remapped = if pmf > 0.0 { ((u - lo) / pmf).clamp(0.0, 1.0 - f64::EPSILON / 2.0) } else { 0.0 };
        SelectedLight { index, pmf, u_remapped }
    }

    /// The probability that [`PowerSelector::pick`] returns light `index` (0 out of range).
    #[must_use]
    pub fn pmf(&self, index: usize) -> f64 {
        if index < self.len() { self.cdf[index + 1] - self.cdf[index] } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_in_proportion_to_weight_and_skips_dark_lights() {
        let weights = [1.0, 0.0, 3.0, 0.0, 4.0, 1e-9];
        let mut cdf = [0.0; 7];
        let s = PowerSelector::build(&weights, &mut cdf).unwrap();
        let mut counts = [0usize; 6];
        let n = 80_000;
        for k in 0..n {
            let p = s.pick((k as f64 + 0.5) / n as f64);
            assert_eq!(p.pmf, s.pmf(p.index));
            assert!(p.pmf > 0.0 && (0.0..1.0).contains(&p.u_remapped));
            counts[p.index] += 1;
        }
        assert_eq!(counts[1] + counts[3], 0);
        for (i, w) in weights.iter().enumerate() {
            let expect = *w as f64 / 8.000_000_001 * n as f64;
            assert!((counts[i] as f64 - expect).abs() <= 1.0, "{i}: {counts:?}");
        }
        assert!(s.pmf(5) > 0.0 && s.pick(1.0).index == 5);
        assert!(PowerSelector::build(&[0.0, 0.0], &mut [0.0; 3]).is_none());
        assert!(PowerSelector::build(&[1.0, f32::NAN], &mut [0.0; 3]).is_none());
        assert!(PowerSelector::build(&[1.0], &mut [0.0; 3]).is_none());
        let again = PowerSelector::from_cdf(&cdf).unwrap();
        assert_eq!(again.pick(0.3), PowerSelector::from_cdf(&cdf).unwrap().pick(0.3));
        assert!(PowerSelector::from_cdf(&[0.0, 0.6, 0.5, 1.0]).is_none());
        assert!(PowerSelector::from_cdf(&[0.0, 0.5]).is_none() && PowerSelector::from_cdf(&[1.0]).is_none());
    }
}
