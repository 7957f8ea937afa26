//! χ² goodness-of-fit harnesses (after Mitsuba 3's `ChiSquareTest`): binned on a chart of
//! the sphere, or on an adaptive dyadic partition of the equal-area square.

use super::quadrature::Chart;
use glam::{DVec2, Vec2, Vec3};
use sampler_core::rng::Pcg32;
use std::f64::consts::PI;

/// Upper regularised incomplete gamma Q(a, x) (Numerical Recipes gammq).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let (mut ap, mut sum) = (a, 1.0 / a);
        let mut del = sum;
        for _ in 0..10_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * (-x + a * x.ln() - gln).exp()
    } else {
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / 1e-300;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < 1e-300 {
                d = 1e-300;
            }
            c = b + an / c;
            if c.abs() < 1e-300 {
                c = 1e-300;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (-x + a * x.ln() - gln).exp() * h
    }
}

fn ln_gamma(x: f64) -> f64 {
    // Lanczos approximation (g = 7, n = 9).
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Result of a χ² test.
#[derive(Debug)]
pub struct ChiSquare {
    pub stat: f64,
    pub dof: usize,
    pub p_value: f64,
    /// Samples the sampler drew where the pdf integrates to (numerically) nothing.
    pub impossible: usize,
    /// Fraction of samples whose returned pdf differs from pdf(dir) by more than 1e-4 relative.
    pub pdf_mismatch: f64,
    /// Fraction of draws that returned no direction.
    pub failed: f64,
}

/// χ² goodness-of-fit of `samples` draws of `sample` against `pdf`, binned on a `res`×`res`
/// grid of `chart`; expected counts integrate the pdf with `sub`×`sub` points per bin. Bins
/// expecting fewer than 5 samples are pooled. The mass the pdf misses (failed draws) is a bin
/// of its own.
pub fn chi_square(
    chart: Chart,
    res: usize,
    sub: usize,
    samples: usize,
    seed: u64,
    mut sample: impl FnMut(DVec2) -> Option<(Vec3, f32)>,
    pdf: impl Fn(Vec3) -> f32,
) -> ChiSquare {
    let mut observed = vec![0.0f64; res * res];
    let mut rng = Pcg32::new(seed, 0x0c41_5eed);
    let (mut failed, mut mismatch) = (0usize, 0usize);
    for _ in 0..samples {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        match sample(u) {
            Some((d, p)) => {
                assert!(d.is_finite() && p.is_finite() && p > 0.0, "bad sample {d:?} pdf {p}");
                let q = pdf(d);
                if (q - p).abs() > 1e-4 * p.max(q) {
                    mismatch += 1;
                }
                let c = chart.point_of(d);
                let i = ((c.x * res as f64) as usize).min(res - 1);
                let j = ((c.y * res as f64) as usize).min(res - 1);
                observed[j * res + i] += 1.0;
            }
            None => failed += 1,
        }
    }
    let mut expected = vec![0.0f64; res * res];
    let m = res * sub;
    for j in 0..m {
        for i in 0..m {
            let c = DVec2::new((i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64);
            let (d, jac) = chart.dir_jacobian(c);
            expected[(j / sub) * res + i / sub] += pdf(d) as f64 * jac / (m * m) as f64 * samples as f64;
        }
    }
    let impossible =
        observed.iter().zip(&expected).filter(|(o, e)| **e == 0.0 && **o > 0.0).map(|(o, _)| *o as usize).sum();
    let (stat, dof) = pooled_statistic(observed.into_iter().zip(expected), failed as f64, samples as f64);
    ChiSquare {
        stat,
        dof,
        p_value: gamma_q(dof as f64 / 2.0, stat / 2.0),
        impossible,
        pdf_mismatch: mismatch as f64 / samples as f64,
        failed: failed as f64 / samples as f64,
    }
}

/// Exact χ² test of a density that is piecewise constant on dyadic cells of the equal-area
/// square: `depth_at(uv)` tells the depth of the constant cell around `uv` and `pdf_square(uv)`
/// its density per unit area. Bins are an adaptive dyadic partition refined until each expects
/// at most `per_bin` samples (down to depth 24), so needle-sharp products are resolved.
pub fn chi_square_dyadic(
    samples: usize,
    seed: u64,
    per_bin: f64,
    mut sample: impl FnMut(DVec2) -> Option<Vec2>,
    depth_at: impl Fn(Vec2) -> u32,
    pdf_square: impl Fn(Vec2) -> f32,
) -> ChiSquare {
    use std::collections::HashMap;
    let n = samples as f64;
    let centre = |d: u32, x: u64, y: u64| {
        let s = 1.0 / (1u64 << d) as f64;
        Vec2::new(((x as f64 + 0.5) * s) as f32, ((y as f64 + 0.5) * s) as f32)
    };
    // Exact mass of a dyadic cell.
    fn mass(
        d: u32,
        x: u64,
        y: u64,
        centre: &dyn Fn(u32, u64, u64) -> Vec2,
        depth_at: &dyn Fn(Vec2) -> u32,
        pdf: &dyn Fn(Vec2) -> f32,
    ) -> f64 {
        let c = centre(d, x, y);
        if depth_at(c) <= d || d >= 24 {
            return pdf(c) as f64 / (1u64 << (2 * d)) as f64;
        }
        (0..4).map(|k| mass(d + 1, 2 * x + (k & 1), 2 * y + (k >> 1), centre, depth_at, pdf)).sum()
    }
    let mut bins: HashMap<(u32, u64, u64), (f64, f64)> = HashMap::new();
    let mut stack = vec![(0u32, 0u64, 0u64)];
    while let Some((d, x, y)) = stack.pop() {
        let m = mass(d, x, y, &centre, &depth_at, &pdf_square);
        if m * n > per_bin && d < 24 {
            for k in 0..4 {
                stack.push((d + 1, 2 * x + (k & 1), 2 * y + (k >> 1)));
            }
        } else {
            bins.insert((d, x, y), (0.0, m * n));
        }
    }
    let mut rng = Pcg32::new(seed, 0xd1ad);
    let mut failed = 0;
    let mut impossible = 0;
    for _ in 0..samples {
        let u = DVec2::new(rng.next_f64(), rng.next_f64());
        let Some(uv) = sample(u) else {
            failed += 1;
            continue;
        };
        let q = |v: f32| ((v as f64 * (1u64 << 24) as f64) as u64).min((1 << 24) - 1);
        let (qx, qy) = (q(uv.x), q(uv.y));
        let key = (0..=24u32).map(|d| (d, qx >> (24 - d), qy >> (24 - d))).find(|k| bins.contains_key(k));
        match key.and_then(|k| bins.get_mut(&k)) {
            Some(b) if b.1 > 0.0 => b.0 += 1.0,
            _ => impossible += 1,
        }
    }
    let (stat, dof) = pooled_statistic(bins.values().copied(), failed as f64, n);
    ChiSquare {
        stat,
        dof,
        p_value: gamma_q(dof as f64 / 2.0, stat / 2.0),
        impossible,
        pdf_mismatch: 0.0,
        failed: failed as f64 / n,
    }
}

/// Pearson's statistic and degrees of freedom of (observed, expected) cells: cells expecting
/// fewer than 5 samples are pooled, together with the mass the pdf misses (`failed` draws of
/// `samples`, against the expected count not covered by the cells).
fn pooled_statistic(cells: impl Iterator<Item = (f64, f64)>, failed: f64, samples: f64) -> (f64, usize) {
    let mut kept: Vec<(f64, f64)> = Vec::new();
    let (mut pool_o, mut pool_e, mut total_e) = (failed, 0.0, 0.0);
    for (o, e) in cells {
        total_e += e;
        if e < 5.0 {
            pool_o += o;
            pool_e += e;
        } else {
            kept.push((o, e));
        }
    }
    pool_e += (samples - total_e).max(0.0);
    if pool_e >= 5.0 {
        kept.push((pool_o, pool_e));
    } else if let Some(last) = kept.last_mut() {
        last.0 += pool_o;
        last.1 += pool_e;
    }
    let stat = kept.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    (stat, kept.len().saturating_sub(1).max(1))
}

/// Šidák-corrected significance level for one of `tests` tests at overall level 1%.
pub fn sidak(tests: usize) -> f64 {
    1.0 - 0.99f64.powf(1.0 / tests as f64)
}
