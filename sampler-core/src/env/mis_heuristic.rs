//! How MIS weighs a sample of one technique against the other's density: Veach's balance
//! heuristic, or his power heuristic with β = 2. The view env samples are combined with BRDF
//! samples through carries it, beside its compensated pyramid, so that every MIS estimator of a
//! render weighs alike without each call taking it.
//!
//! Neither heuristic wins on every map. The power heuristic hands each direction to the
//! technique that is much the denser there, which pays where nearly all of the light sits in
//! compact bright regions that env samples stratify well (a studio's softboxes) and costs where
//! BRDF samples carry much of it (docs/perf.md, "MIS heuristic"); the split pilot measures the
//! scene (`host-std/src/plan/split.rs`).

use super::EnvHierarchy;

/// Which MIS heuristic weighs a sample against the other technique.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MisHeuristic {
    /// w = p_own / (p_own + p_other).
    #[default]
    Balance,
    /// w = p_own² / (p_own² + p_other²).
    Power,
}

impl MisHeuristic {
    /// The density a sample's f is divided by, w·f/own = f/denominator, for a sample drawn by a
    /// technique of density `own` where the other's is `other` (each scaled by its share of the
    /// samples, for a split budget). Balance: own + other. Power: own + other·(other/own),
    /// written without squares so that neither over- nor underflows; where `own` is zero the
    /// result is infinite or NaN and the sample weighs nothing.
    #[inline(always)]
    #[must_use]
    pub fn denominator(self, own: f32, other: f32) -> f32 {
        match self {
            Self::Balance => own + other,
            Self::Power => own + other * (other / own),
        }
    }
}

impl EnvHierarchy<'_> {
    /// This view with MIS weighing its samples against BRDF samples by `heuristic`.
    #[must_use]
    pub fn with_mis_heuristic(mut self, heuristic: MisHeuristic) -> Self {
        self.mis_heuristic = heuristic;
        self
    }

    /// The heuristic MIS weighs this view's samples and BRDF samples by.
    #[inline]
    #[must_use]
    pub fn mis_heuristic(&self) -> MisHeuristic {
        self.mis_heuristic
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two techniques' weights of one direction sum to one, as each heuristic defines them.
    #[test]
    fn the_weights_of_a_direction_sum_to_one() {
        for h in [MisHeuristic::Balance, MisHeuristic::Power] {
            for (a, b) in [(1.0f32, 1.0f32), (0.3, 7.0), (1e-6, 3e4), (2.5, 0.0)] {
                let w = |own: f32, other: f32| own / h.denominator(own, other);
                assert!((w(a, b) + w(b, a) - 1.0).abs() < 1e-5, "{h:?} {a} {b}");
            }
        }
        let power = |own: f32, other: f32| own / MisHeuristic::Power.denominator(own, other);
        assert!((power(3.0, 1.0) - 0.9).abs() < 1e-6);
        assert_eq!(power(0.0, 1.0).max(0.0), 0.0, "a technique without density weighs nothing");
        assert!(MisHeuristic::Power.denominator(1e-30, 1e30).is_infinite());
    }
}
