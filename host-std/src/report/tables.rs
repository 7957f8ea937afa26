//! The report's text: the CSV of every render and the Markdown equal-time tables.

use crate::report::{Measurement, Series};
use std::fmt::Write as _;

/// relMSE over `region` of `series` at time `t`, interpolated log-log between its
/// measurements (outside their range: extended along the nearest segment; flagged).
pub fn relmse_at(measurements: &[Measurement], series: Series, region: &str, t: f64) -> Option<(f64, bool)> {
    let mut pts: Vec<(f64, f64)> = measurements
        .iter()
        .filter(|m| m.series() == series && m.seconds > 0.0)
        .filter_map(|m| m.relmse_in(region).filter(|e| *e > 0.0).map(|e| (m.seconds.ln(), e.ln())))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    if pts.is_empty() {
        return None;
    }
    if pts.len() == 1 {
        // One point: assume error ∝ 1/time.
        let (t0, e0) = pts[0];
        return Some(((e0 - (t.ln() - t0)).exp(), (t.ln() - t0).abs() > 1e-9));
    }
    let x = t.ln();
    let k = pts.windows(2).position(|w| x <= w[1].0).unwrap_or(pts.len() - 2);
    let ((x0, y0), (x1, y1)) = (pts[k], pts[k + 1]);
    let outside = x < pts[0].0 || x > pts[pts.len() - 1].0;
    let y = if x1 > x0 { y0 + (y1 - y0) * (x - x0) / (x1 - x0) } else { y0 };
    Some((y.exp(), outside))
}

/// `error_vs_time.csv`: one row per render and region ("all" is the whole image);
/// `brdf_samples` is empty where the report has one K or the method reads none.
pub fn csv(measurements: &[Measurement]) -> String {
    let mut s = String::from("method,spp,seconds,region,rmse,relmse,brdf_samples\n");
    for m in measurements {
        let k = m.brdf_samples.map_or(String::new(), |k| k.to_string());
        let rows = std::iter::once(("all", m.rmse, m.relmse)).chain(m.regions.iter().map(|r| (r.0.as_str(), r.1, r.2)));
        for (region, rmse, relmse) in rows {
            let _ = writeln!(s, "{},{},{:.6},{region},{rmse:.6e},{relmse:.6e},{k}", m.method, m.spp, m.seconds);
        }
    }
    s
}

/// `report.md`: the measurements, then equal-time tables against `base` (e.g. `product`) for
/// the whole image and for each region.
pub fn markdown(
    scene: &str,
    measurements: &[Measurement],
    base: Series,
    threads: usize,
    reference_note: &str,
) -> String {
    let mut s = format!("# Error against time: {scene}\n\n{threads} threads; reference: {reference_note}.\n");
    s.push_str("relMSE = mean (x − r)²/(r² + 0.01) over pixels and channels; bias = the image's mean over the reference's, less one; seconds = the render's time by the clock named above (wall clock unless it says CPU). Regions: pixels whose centre ray hits a material of that kind and lobe width (GGX α, Phong exponent).\n\n");
    let regions: Vec<String> =
        measurements.first().map(|m| m.regions.iter().map(|r| r.0.clone()).collect()).unwrap_or_default();
    s.push_str("| method | spp | seconds | RMSE | relMSE | bias |");
    for r in &regions {
        let _ = write!(s, " relMSE {r} |");
    }
    s.push_str("\n|---|---|---|---|---|---|");
    s.push_str(&"---|".repeat(regions.len()));
    s.push('\n');
    for m in measurements {
        let row = (m.series(), m.spp, m.seconds, m.rmse, m.relmse, 100.0 * m.bias);
        let _ = write!(s, "| {} | {} | {:.3} | {:.4e} | {:.4e} | {:+.2}% |", row.0, row.1, row.2, row.3, row.4, row.5);
        for r in &m.regions {
            let _ = write!(s, " {:.4e} |", r.2);
        }
        s.push('\n');
    }
    for m in measurements.iter().filter(|m| !m.plans.is_empty()) {
        let plans: Vec<String> = m.plans.iter().map(|(material, plan)| format!("{material} → {plan}")).collect();
        let _ = writeln!(s, "\n{} at {} spp: {}.", m.series(), m.spp, plans.join(", "));
    }
    let mut others: Vec<Series> = Vec::new();
    for m in measurements {
        if m.series() != base && !others.contains(&m.series()) {
            others.push(m.series());
        }
    }
    let product: Vec<&Measurement> = measurements.iter().filter(|m| m.series() == base).collect();
    if product.is_empty() || others.is_empty() {
        return s;
    }
    let _ = write!(
        s,
        "\n## Equal time\n\nFor the time {base} takes at each spp, every other method's relMSE at that time (log-log interpolation; * = extrapolated beyond its measured times) and its ratio to {base}'s (> 1: {base} is better).\n"
    );
    for region in std::iter::once("all".to_string()).chain(regions) {
        let _ = write!(
            s,
            "\n### {}\n\n| {base} spp | seconds | {base} relMSE |",
            if region == "all" { "whole image".to_string() } else { format!("pixels on {region}") }
        );
        for o in &others {
            let _ = write!(s, " {o} relMSE | ratio |");
        }
        s.push_str("\n|---|---|---|");
        s.push_str(&"---|---|".repeat(others.len()));
        s.push('\n');
        for p in &product {
            let Some(pe) = p.relmse_in(&region) else { continue };
            let _ = write!(s, "| {} | {:.3} | {:.4e} |", p.spp, p.seconds, pe);
            for &o in &others {
                match relmse_at(measurements, o, &region, p.seconds) {
                    Some((e, outside)) => {
                        let _ = write!(s, " {:.4e}{} | {:.2} |", e, if outside { "*" } else { "" }, e / pe);
                    }
                    None => s.push_str(" – | – |"),
                }
            }
            s.push('\n');
        }
    }
    s
}
