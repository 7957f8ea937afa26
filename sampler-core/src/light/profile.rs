//! A measured luminous-intensity distribution (the candela table of an IES LM-63 photometric
//! file, type C): intensities on a grid of vertical angles θ (0 at the luminaire's nadir, its
//! primary axis, up to 180°) and horizontal angles φ about that axis, interpolated bilinearly in
//! (θ, φ). The table holds what the file holds; the usual horizontal symmetries are applied when
//! looking up, so no table is expanded:
//!
//! - one horizontal angle (0°): the same in every direction about the axis;
//! - 0°–90°: symmetric in each quadrant;
//! - 0°–180°: symmetric about the 0°–180° plane;
//! - 90°–270°: symmetric about the 90°–270° plane (LM-63-1995);
//! - 0° to more than 180°: no symmetry; past the last angle the table wraps to 0° (360°).
//!
//! Outside the vertical range the intensity is 0 (a 0°–90° table has no light above the
//! horizon). The table is borrowed: a host keeps it for as long as the lights that use it.

use core::f32::consts::{FRAC_PI_2, PI};

/// What a profile's horizontal angles cover, and so how a direction folds into them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HorizontalSymmetry {
    /// One angle: the intensity does not depend on φ.
    Rotational,
    /// 0°–90°.
    Quadrant,
    /// 0°–180°.
    Bilateral,
    /// 90°–270°.
    Bilateral90,
    /// 0° to more than 180°.
    Full,
}

/// Why a table cannot be a profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProfileError {
    /// Fewer than two vertical angles, or not strictly increasing within [0, π].
    BadVertical,
    /// No horizontal angle, not strictly increasing, or a range that is none of the symmetries.
    BadHorizontal,
    /// The intensities are not one per (horizontal, vertical) pair.
    WrongCount,
    /// An intensity is negative, NaN or infinite.
    BadIntensity,
}

impl core::fmt::Display for ProfileError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::BadVertical => "the vertical angles are fewer than two, not increasing, or outside 0°–180°",
            Self::BadHorizontal => "the horizontal angles are not increasing or cover no symmetry of type C",
            Self::WrongCount => "the intensities are not one per pair of angles",
            Self::BadIntensity => "an intensity is negative or not finite",
        })
    }
}

impl core::error::Error for ProfileError {}

/// Tolerance on angles (radians) when recognising a symmetry.
const ANGLE_EPS: f32 = 1e-4;

/// A luminous-intensity distribution over the sphere of directions about a luminaire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntensityProfile<'a> {
    vertical: &'a [f32],
    horizontal: &'a [f32],
    intensity: &'a [f32],
    symmetry: HorizontalSymmetry,
}

impl<'a> IntensityProfile<'a> {
    /// The profile of `intensity[h · vertical.len() + v]` at the vertical angle `vertical[v]` and
    /// the horizontal angle `horizontal[h]` (radians, each strictly increasing; the horizontal
    /// ones one of the ranges of [`HorizontalSymmetry`]).
    pub fn new(vertical: &'a [f32], horizontal: &'a [f32], intensity: &'a [f32]) -> Result<Self, ProfileError> {
        let increasing = |a: &[f32]| a.windows(2).all(|w| w[1] > w[0]) && a.iter().all(|x| x.is_finite());
        if vertical.len() < 2
            || !increasing(vertical)
            || vertical[0] < -ANGLE_EPS
            || vertical[vertical.len() - 1] > PI + ANGLE_EPS
        {
            return Err(ProfileError::BadVertical);
        }
        if horizontal.is_empty() || !increasing(horizontal) {
            return Err(ProfileError::BadHorizontal);
        }
        let close = |a: f32, b: f32| (a - b).abs() <= ANGLE_EPS;
        let (first, last) = (horizontal[0], horizontal[horizontal.len() - 1]);
        let symmetry = if horizontal.len() == 1 && close(first, 0.0) {
            HorizontalSymmetry::Rotational
        } else if close(first, 0.0) && close(last, FRAC_PI_2) {
            HorizontalSymmetry::Quadrant
        } else if close(first, 0.0) && close(last, PI) {
            HorizontalSymmetry::Bilateral
        } else if close(first, FRAC_PI_2) && close(last, 1.5 * PI) {
            HorizontalSymmetry::Bilateral90
        } else if close(first, 0.0) && last > PI && last <= 2.0 * PI + ANGLE_EPS {
            HorizontalSymmetry::Full
        } else {
            return Err(ProfileError::BadHorizontal);
        };
        if intensity.len() != vertical.len() * horizontal.len() {
            return Err(ProfileError::WrongCount);
        }
        if !intensity.iter().all(|c| c.is_finite() && *c >= 0.0) {
            return Err(ProfileError::BadIntensity);
        }
        Ok(Self { vertical, horizontal, intensity, symmetry })
    }

    /// Which symmetry the horizontal angles describe.
    #[must_use]
    pub fn symmetry(&self) -> HorizontalSymmetry {
        self.symmetry
    }

    /// The vertical angles (radians).
    #[must_use]
    pub fn vertical(&self) -> &'a [f32] {
        self.vertical
    }

    /// The horizontal angles (radians).
    #[must_use]
    pub fn horizontal(&self) -> &'a [f32] {
        self.horizontal
    }

    /// The intensities, `[h · vertical().len() + v]`.
    #[must_use]
    pub fn intensities(&self) -> &'a [f32] {
        self.intensity
    }

    /// The largest intensity of the table.
    #[must_use]
    pub fn max(&self) -> f32 {
        self.intensity.iter().fold(0.0, |m, &c| m.max(c))
    }

    /// The intensity towards the vertical angle `theta` ∈ [0, π] and the horizontal angle `phi`
    /// (radians, any value: it is taken modulo 2π).
    #[must_use]
    pub fn eval(&self, theta: f32, phi: f32) -> f32 {
        let v = self.vertical;
        if !(theta >= v[0] && theta <= v[v.len() - 1]) {
            return 0.0;
        }
        let k = segment(v, theta);
        let t = ((theta - v[k]) / (v[k + 1] - v[k])).clamp(0.0, 1.0);
        let (h0, h1, s) = self.horizontal_cell(phi);
        let row = |h: usize| {
            let r = &self.intensity[h * v.len()..];
            r[k] + t * (r[k + 1] - r[k])
        };
        let (a, b) = (row(h0), row(h1));
        a + s * (b - a)
    }

    /// The rows of the table about the horizontal angle `phi` and the fraction between them.
    fn horizontal_cell(&self, phi: f32) -> (usize, usize, f32) {
        let h = self.horizontal;
        if self.symmetry == HorizontalSymmetry::Rotational {
            return (0, 0, 0.0);
        }
        let folded = self.fold(phi);
        let last = h.len() - 1;
        if folded >= h[last] {
            // Only a full table reaches past its last angle: it wraps to its first, at 2π.
            let span = 2.0 * PI - h[last];
            let s = if span > 0.0 { ((folded - h[last]) / span).clamp(0.0, 1.0) } else { 0.0 };
            return (last, 0, s);
        }
        if folded <= h[0] {
            return (0, 0, 0.0);
        }
        let j = segment(h, folded);
        (j, j + 1, ((folded - h[j]) / (h[j + 1] - h[j])).clamp(0.0, 1.0))
    }

    /// `phi` folded into the horizontal angles the table covers.
    fn fold(&self, phi: f32) -> f32 {
        let mut p = phi % (2.0 * PI);
        if p < 0.0 {
            p += 2.0 * PI;
        }
        match self.symmetry {
            HorizontalSymmetry::Rotational | HorizontalSymmetry::Full => p,
            HorizontalSymmetry::Bilateral => {
                if p > PI {
                    2.0 * PI - p
                } else {
                    p
                }
            }
            HorizontalSymmetry::Quadrant => {
                let half = if p > PI { 2.0 * PI - p } else { p };
                if half > FRAC_PI_2 { PI - half } else { half }
            }
            HorizontalSymmetry::Bilateral90 => {
                // The mirror about the 90°–270° plane takes φ to 180° − φ.
                if (FRAC_PI_2..=1.5 * PI).contains(&p) {
                    p
                } else {
                    let m = PI - p;
                    if m < 0.0 { m + 2.0 * PI } else { m }
                }
            }
        }
    }

    /// The mean over φ of the intensity at the vertical angle `vertical()[k]`: the trapezoid
    /// rule over the table's horizontal angles, exact for its piecewise-linear interpolation.
    #[must_use]
    pub fn mean_over_phi(&self, k: usize) -> f32 {
        let (v, h) = (self.vertical.len(), self.horizontal);
        let at = |j: usize| self.intensity[j * v + k];
        let mut sum = 0.0f64;
        for j in 1..h.len() {
            sum += 0.5 * f64::from(at(j - 1) + at(j)) * f64::from(h[j] - h[j - 1]);
        }
        let covered = match self.symmetry {
            HorizontalSymmetry::Rotational => return at(0),
            HorizontalSymmetry::Quadrant => f64::from(FRAC_PI_2),
            HorizontalSymmetry::Bilateral | HorizontalSymmetry::Bilateral90 => f64::from(PI),
            HorizontalSymmetry::Full => {
                let last = h.len() - 1;
                sum += 0.5 * f64::from(at(last) + at(0)) * f64::from(2.0 * PI - h[last]);
                f64::from(2.0 * PI)
            }
        };
        (sum / covered) as f32
    }

    /// ∫ I dω over the sphere of the bilinear interpolation (exact: it is linear in θ between
    /// vertical angles once averaged over φ): the luminaire's flux for a table in candela.
    #[must_use]
    pub fn flux(&self) -> f32 {
        let v = self.vertical;
        let mut total = 0.0f64;
        for k in 0..v.len() - 1 {
            let (a, b) = (f64::from(v[k]), f64::from(v[k + 1]));
            let (ia, ib) = (f64::from(self.mean_over_phi(k)), f64::from(self.mean_over_phi(k + 1)));
            // ∫ (ia + (ib − ia)(θ − a)/(b − a)) sin θ dθ over [a, b].
            let (d, plain) = (b - a, libm::cos(a) - libm::cos(b));
            let ramp = (libm::sin(b) - libm::sin(a) - d * libm::cos(b)) / d;
            total += ia * plain + (ib - ia) * ramp;
        }
        (2.0 * core::f64::consts::PI * total) as f32
    }

    /// The profile's mean intensity over the directions it describes: its flux over 4π when its
    /// vertical angles span more than a hemisphere (more than 90° + 0.1 rad, the test Pixar's
    /// HdEmbree applies), else over 2π. UsdLux's `shaping:ies:normalize` divides by it.
    #[must_use]
    pub fn mean_intensity(&self) -> f32 {
        let v = self.vertical;
        let sphere = v[v.len() - 1] - v[0] > FRAC_PI_2 + 0.1;
        self.flux() / if sphere { 4.0 * PI } else { 2.0 * PI }
    }

    /// The vertical angle beyond which the intensity is 0 in every horizontal direction (π
    /// when light leaves at 180°).
    #[must_use]
    pub fn lit_extent(&self) -> f32 {
        let v = self.vertical;
        let dark = |k: usize| (0..self.horizontal.len()).all(|j| self.intensity[j * v.len() + k] == 0.0);
        let mut k = v.len() - 1;
        while k > 0 && dark(k) && dark(k - 1) {
            k -= 1;
        }
        if k == 0 { v[0] } else { v[k] }
    }

    /// The vertical-angle segment [k, k + 1] that holds `theta` (from [`IntensityProfile::eval`]'s
    /// callers: within the vertical range).
    #[must_use]
    pub fn vertical_segment(&self, theta: f32) -> usize {
        segment(self.vertical, theta)
    }
}

/// The index k with `a[k] ≤ x ≤ a[k + 1]` for `x` within `a`'s range (`a` increasing, ≥ 2 long).
fn segment(a: &[f32], x: f32) -> usize {
    let k = a.partition_point(|&y| y <= x);
    k.clamp(1, a.len() - 1) - 1
}

#[cfg(test)]
mod tests {
    use super::*;

    const D: f32 = PI / 180.0;

    #[test]
    fn bilinear_between_the_angles_and_zero_outside_the_vertical_range() {
        let v = [0.0, 30.0 * D, 90.0 * D];
        let h = [0.0, 90.0 * D];
        // Row φ = 0: 100, 50, 0; row φ = 90°: 200, 100, 0.
        let c = [100.0, 50.0, 0.0, 200.0, 100.0, 0.0];
        let p = IntensityProfile::new(&v, &h, &c).unwrap();
        assert_eq!(p.symmetry(), HorizontalSymmetry::Quadrant);
        assert!((p.eval(15.0 * D, 0.0) - 75.0).abs() < 1e-3);
        assert!((p.eval(15.0 * D, 45.0 * D) - 112.5).abs() < 1e-3);
        assert_eq!(p.eval(91.0 * D, 0.0), 0.0);
        // Quadrant symmetry: 135° is 45°, 225° is 45°, 300° is 60°.
        for (phi, same) in [(135.0, 45.0), (225.0, 45.0), (300.0, 60.0), (-30.0, 30.0)] {
            assert!((p.eval(10.0 * D, phi * D) - p.eval(10.0 * D, same * D)).abs() < 1e-3, "{phi}");
        }
        assert!((p.lit_extent() - 90.0 * D).abs() < 1e-6);
        assert!(matches!(IntensityProfile::new(&v, &[0.0, 45.0 * D], &c), Err(ProfileError::BadHorizontal)));
        assert!(matches!(IntensityProfile::new(&v, &h, &c[..5]), Err(ProfileError::WrongCount)));
    }

    #[test]
    fn each_symmetry_folds_as_the_standard_says() {
        let v = [0.0, PI];
        let full_h = [0.0, 90.0 * D, 180.0 * D, 270.0 * D];
        let full_c = [1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0];
        let full = IntensityProfile::new(&v, &full_h, &full_c).unwrap();
        assert_eq!(full.symmetry(), HorizontalSymmetry::Full);
        // Past 270° the table wraps back to its 0° row at 360°.
        assert!((full.eval(0.5, 315.0 * D) - 2.5).abs() < 1e-4);
        assert!((full.mean_over_phi(0) - 2.5).abs() < 1e-5);
        let bi_c = [1.0, 1.0, 2.0, 2.0, 3.0, 3.0];
        let bi = IntensityProfile::new(&v, &full_h[..3], &bi_c).unwrap();
        assert!((bi.eval(0.5, 225.0 * D) - bi.eval(0.5, 135.0 * D)).abs() < 1e-5);
        let b90_h = [90.0 * D, 180.0 * D, 270.0 * D];
        let b90 = IntensityProfile::new(&v, &b90_h, &bi_c).unwrap();
        assert_eq!(b90.symmetry(), HorizontalSymmetry::Bilateral90);
        // 0° mirrors to 180°, 45° to 135°, 300° to 240°.
        assert!((b90.eval(0.5, 0.0) - 2.0).abs() < 1e-5);
        assert!((b90.eval(0.5, 45.0 * D) - b90.eval(0.5, 135.0 * D)).abs() < 1e-5);
        assert!((b90.eval(0.5, 300.0 * D) - b90.eval(0.5, 240.0 * D)).abs() < 1e-5);
        let round = IntensityProfile::new(&v, &[0.0], &[5.0, 1.0]).unwrap();
        assert!((round.eval(PI / 2.0, 1.234) - 3.0).abs() < 1e-5);
    }

    #[test]
    fn flux_is_the_integral_over_the_sphere() {
        // Constant 1 cd over the sphere: 4π lm, mean 1.
        let v = [0.0, 60.0 * D, PI];
        let p = IntensityProfile::new(&v, &[0.0], &[1.0, 1.0, 1.0]).unwrap();
        assert!((p.flux() - 4.0 * PI).abs() < 1e-4);
        assert!((p.mean_intensity() - 1.0).abs() < 1e-5);
        // I = 1 − θ/π over the sphere, against a midpoint rule.
        let lin = IntensityProfile::new(&[0.0, PI], &[0.0], &[1.0, 0.0]).unwrap();
        let n = 100_000;
        let quad: f64 = (0..n)
            .map(|i| {
                let t = core::f64::consts::PI * (i as f64 + 0.5) / n as f64;
                (1.0 - t / core::f64::consts::PI) * t.sin()
            })
            .sum::<f64>()
            * core::f64::consts::PI
            / n as f64
            * 2.0
            * core::f64::consts::PI;
        assert!((f64::from(lin.flux()) - quad).abs() < 1e-4 * quad, "{} {quad}", lin.flux());
        // A downlight (0°–90°) is normalised over the hemisphere.
        let down = IntensityProfile::new(&[0.0, PI / 2.0], &[0.0], &[2.0, 2.0]).unwrap();
        assert!((down.mean_intensity() - 2.0).abs() < 1e-5);
        assert_eq!(down.eval(PI / 2.0 + 0.01, 0.0), 0.0);
    }
}
