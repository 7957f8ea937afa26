//! UsdLux `colorTemperature`: the colour of a blackbody at a temperature, in linear sRGB
//! (Rec. 709 primaries, D65 white), normalised as the LightAPI schema says: 6500 K is white
//! (1, 1, 1). Planck's law is integrated against the CIE 1931 2° observer (the multi-lobe
//! Gaussian fit of Wyman, Sloan and Shirley 2013, accurate to the tables' own rounding for
//! this use), the result scaled to unit luminance and divided, channel by channel, by the
//! same colour at 6500 K.
//!
//! Pixar's `UsdLuxBlackbodyTemperatureAsRgb` normalises to unit luminance only, so its 6500 K
//! is slightly off white; the two agree on every other temperature up to that one per-channel
//! factor (`host-usd/tests/integration/lights.rs` compares them).

use glam::DVec3;

/// The temperature the schema makes white.
pub const WHITE_KELVIN: f64 = 6500.0;

/// The schema's valid range of `colorTemperature`; values outside are clamped to it.
pub const KELVIN_RANGE: (f64, f64) = (1000.0, 10000.0);

/// One lobe of the fit: a Gaussian with different widths below and above its centre.
fn lobe(lambda: f64, mu: f64, below: f64, above: f64) -> f64 {
    let s = if lambda < mu { below } else { above };
    let t = (lambda - mu) / s;
    (-0.5 * t * t).exp()
}

/// The CIE 1931 colour matching functions at `lambda` nm.
fn cie_xyz(lambda: f64) -> DVec3 {
    let x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7)
        - 0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    DVec3::new(x, y, z)
}

/// Planck's spectral radiance at `lambda` nm and `kelvin`, up to a constant factor (the
/// colour is normalised afterwards).
fn planck(lambda: f64, kelvin: f64) -> f64 {
    // c2 = hc/k in nm·K.
    const C2: f64 = 1.438_776_877e7;
    let l = lambda * 1e-3;
    1.0 / (l.powi(5) * ((C2 / (lambda * kelvin)).exp_m1()))
}

/// The blackbody's linear sRGB colour at unit luminance; negative channels (outside the
/// gamut, blue below about 1900 K) are clipped to 0.
fn unit_luminance_rgb(kelvin: f64) -> DVec3 {
    let mut xyz = DVec3::ZERO;
    for nm in (360..=830).map(f64::from) {
        xyz += cie_xyz(nm) * planck(nm, kelvin);
    }
    let xyz = xyz / xyz.y;
    let rgb = DVec3::new(
        3.240_454_2 * xyz.x - 1.537_138_5 * xyz.y - 0.498_531_4 * xyz.z,
        -0.969_266_0 * xyz.x + 1.876_010_8 * xyz.y + 0.041_556_0 * xyz.z,
        0.055_643_4 * xyz.x - 0.204_025_9 * xyz.y + 1.057_225_2 * xyz.z,
    );
    rgb.max(DVec3::ZERO)
}

/// The multiplier `colorTemperature = kelvin` puts on a light's colour: white at 6500 K,
/// warmer below, cooler above; `kelvin` is clamped to [`KELVIN_RANGE`].
pub fn rgb(kelvin: f64) -> DVec3 {
    let k = kelvin.clamp(KELVIN_RANGE.0, KELVIN_RANGE.1);
    unit_luminance_rgb(k) / unit_luminance_rgb(WHITE_KELVIN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_at_6500_warm_below_cool_above() {
        assert!((rgb(6500.0) - DVec3::ONE).length() < 1e-12);
        let warm = rgb(3000.0);
        assert!(warm.x > warm.y && warm.y > warm.z);
        let cool = rgb(9000.0);
        assert!(cool.z > cool.y && cool.y > cool.x);
        assert_eq!(rgb(500.0), rgb(1000.0));
        assert_eq!(rgb(20000.0), rgb(10000.0));
    }
}
