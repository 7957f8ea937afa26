//! The paper's trade-off between BRDF samples and visibility samples at equal time (Clarberg &
//! Akenine-Möller 2008: the error is flat between 100 and 500 BRDF samples, 256 a good
//! default): from a report that sweeps K (`ppis report --brdf-samples 16,32,…`), every
//! method's relMSE at one render time against K, per region, and where its optimum lies — the
//! figure's data as CSV and Markdown ([`plot_k`](crate::report::plot_k) draws it).
//!
//! Each method's curve is at its own time: the method's at the reference K ([`reference_k`],
//! 256 when swept) and its largest spp — the paper's question, which K serves one sampler best
//! at the budget it is given; how methods compare at equal time is the report's other table.
//! Each K's relMSE there is interpolated log-log between its renders ([`relmse_at`]): a larger K
//! costs more per shading point, so in that time it renders fewer visibility samples. Outside
//! a series' renders its error is extended from the nearest one as 1/time (flagged): a
//! segment's own slope, from two renders whose times the per-render overhead dominates, can
//! be anything (`ppis report --bracket` renders on until the time is inside).

use crate::plan::Method;
use crate::report::{Measurement, Series, relmse_at};
use std::fmt::Write as _;

/// A K whose relMSE is within this factor of the optimum's counts as on the optimum's
/// plateau: closer than that, one seed's error and the machine's timing cannot tell them apart.
pub const PLATEAU: f64 = 1.2;

/// The paper's default K.
const PAPER_DEFAULT_K: usize = 256;

/// The K of `ks` a sweep takes its equal time from and compares the others with: the one
/// nearest the paper's default of 256 on a log scale (the larger on a tie).
#[must_use]
pub fn reference_k(ks: &[usize]) -> usize {
    let distance = |k: usize| ((k.max(1) as f64) / PAPER_DEFAULT_K as f64).ln().abs();
    ks.iter().copied().min_by(|&a, &b| distance(a).total_cmp(&distance(b)).then(b.cmp(&a))).unwrap_or(PAPER_DEFAULT_K)
}

/// relMSE over `region` of `series` at time `t`: interpolated log-log between its renders, and
/// outside them the nearest render's scaled by its time over `t` (flagged).
fn relmse_near(measurements: &[Measurement], series: Series, region: &str, t: f64) -> Option<(f64, bool)> {
    let renders = || {
        measurements
            .iter()
            .filter(|m| m.series() == series && m.seconds > 0.0)
            .filter_map(|m| Some((m.seconds, m.relmse_in(region).filter(|e| *e > 0.0)?)))
    };
    let first = renders().min_by(|a, b| a.0.total_cmp(&b.0))?;
    let last = renders().max_by(|a, b| a.0.total_cmp(&b.0))?;
    if t < first.0 {
        return Some((first.1 * first.0 / t, true));
    }
    if t > last.0 {
        return Some((last.1 * last.0 / t, true));
    }
    relmse_at(measurements, series, region, t)
}

/// One point of a curve: relMSE at the curve's time at one K.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KPoint {
    /// The K.
    pub brdf_samples: usize,
    /// relMSE at the curve's time.
    pub relmse: f64,
    /// The time lies outside this K's renders: extrapolated.
    pub extrapolated: bool,
}

/// relMSE at equal time against K for one method over one region.
#[derive(Clone, Debug, PartialEq)]
pub struct KCurve {
    /// The method.
    pub method: Method,
    /// The region ("all": the whole image).
    pub region: String,
    /// The equal time: the method's at the reference K and its largest spp.
    pub seconds: f64,
    /// By increasing K.
    pub points: Vec<KPoint>,
}

impl KCurve {
    /// The point of least relMSE.
    #[must_use]
    pub fn optimum(&self) -> Option<&KPoint> {
        self.points.iter().min_by(|a, b| a.relmse.total_cmp(&b.relmse))
    }

    /// The relMSE at `k`.
    #[must_use]
    pub fn at(&self, k: usize) -> Option<&KPoint> {
        self.points.iter().find(|p| p.brdf_samples == k)
    }

    /// The smallest and the largest K within `PLATEAU` times the optimum's relMSE.
    #[must_use]
    pub fn plateau(&self) -> Option<(usize, usize)> {
        let best = self.optimum()?.relmse;
        let within = self.points.iter().filter(|p| p.relmse <= PLATEAU * best).map(|p| p.brdf_samples);
        within.clone().min().zip(within.max())
    }
}

/// The K sweep of a report: each method's relMSE at its equal time against K, per region.
#[derive(Clone, Debug)]
pub struct KSweep {
    /// The K each curve takes its time from and is compared with ([`reference_k`]).
    pub reference_k: usize,
    /// The swept K, increasing.
    pub ks: Vec<usize>,
    /// Per region ("all" first) and method that reads K, in the measurements' order.
    pub curves: Vec<KCurve>,
}

impl KSweep {
    /// The sweep of the methods that read K (the measurements' `brdf_samples`); `None` when
    /// none was rendered at `reference_k`.
    #[must_use]
    pub fn new(measurements: &[Measurement], reference_k: usize) -> Option<Self> {
        let mut ks: Vec<usize> = measurements.iter().filter_map(|m| m.brdf_samples).collect();
        ks.sort_unstable();
        ks.dedup();
        let mut times: Vec<(Method, f64)> = Vec::new();
        for m in measurements.iter().filter(|m| m.brdf_samples.is_some()) {
            if times.iter().all(|t| t.0 != m.method) {
                let base = Series { method: m.method, brdf_samples: Some(reference_k) };
                let largest = measurements.iter().filter(|x| x.series() == base).max_by_key(|x| x.spp);
                times.extend(largest.map(|x| (m.method, x.seconds)));
            }
        }
        if times.is_empty() {
            return None;
        }
        let regions = measurements.first().map(|m| m.regions.iter().map(|r| r.0.clone()).collect()).unwrap_or_default();
        let mut curves = Vec::new();
        for region in std::iter::once("all".to_string()).chain::<Vec<String>>(regions) {
            for &(method, seconds) in &times {
                let points = ks
                    .iter()
                    .filter_map(|&k| {
                        let series = Series { method, brdf_samples: Some(k) };
                        let (relmse, extrapolated) = relmse_near(measurements, series, &region, seconds)?;
                        Some(KPoint { brdf_samples: k, relmse, extrapolated })
                    })
                    .collect();
                curves.push(KCurve { method, region: region.clone(), seconds, points });
            }
        }
        Some(Self { reference_k, ks, curves })
    }

    /// The regions, "all" first.
    #[must_use]
    pub fn regions(&self) -> Vec<&str> {
        let mut regions: Vec<&str> = Vec::new();
        for c in &self.curves {
            if !regions.contains(&c.region.as_str()) {
                regions.push(&c.region);
            }
        }
        regions
    }

    /// `error_vs_k.csv`: one row per region, method and K.
    #[must_use]
    pub fn csv(&self) -> String {
        let mut s = String::from("region,method,brdf_samples,seconds,relmse,extrapolated\n");
        for c in &self.curves {
            for p in &c.points {
                let (k, e, x) = (p.brdf_samples, p.relmse, p.extrapolated);
                let _ = writeln!(s, "{},{},{k},{:.6},{e:.6e},{x}", c.region, c.method, c.seconds);
            }
        }
        s
    }

    /// `error_vs_k.md`: where each curve's optimum lies, then per region relMSE against K.
    #[must_use]
    pub fn markdown(&self, scene: &str, threads: usize, note: &str) -> String {
        let k_ref = self.reference_k;
        let mut s = format!("# relMSE at equal time against K: {scene}\n\n{threads} threads; reference: {note}.\n");
        let _ = write!(
            s,
            "Each method at its own equal time, its time at K = {k_ref} and its largest spp; each K's relMSE at that time is interpolated log-log between its renders (* = extrapolated as 1/time from the nearest): a larger K builds each product sampler from more BRDF samples and so renders fewer visibility samples in that time.\n\n"
        );
        let _ = write!(
            s,
            "## Optimum\n\nPer region and method: the K of least relMSE, its relMSE over K = {k_ref}'s, and the K within {PLATEAU}× of the optimum.\n\n| region | method | time (s) | optimum K | relMSE there | ÷ K = {k_ref} | K within {PLATEAU}× |\n|---|---|---:|---:|---:|---:|---|\n"
        );
        for c in &self.curves {
            let (Some(best), Some((lo, hi))) = (c.optimum(), c.plateau()) else { continue };
            let ratio = c.at(k_ref).map_or("–".to_string(), |r| format!("{:.2}", best.relmse / r.relmse));
            let (k, e) = (best.brdf_samples, best.relmse);
            let _ =
                writeln!(s, "| {} | {} | {:.3} | {k} | {e:.4e} | {ratio} | {lo}–{hi} |", c.region, c.method, c.seconds);
        }
        for region in self.regions() {
            let curves: Vec<&KCurve> = self.curves.iter().filter(|c| c.region == region).collect();
            let title = if region == "all" { "whole image".to_string() } else { format!("pixels on {region}") };
            let _ = write!(s, "\n## {title}\n\n| K |");
            for c in &curves {
                let _ = write!(s, " {} relMSE at {:.3} s | ÷ K = {k_ref} |", c.method, c.seconds);
            }
            s.push_str("\n|---:|");
            s.push_str(&"---:|---:|".repeat(curves.len()));
            s.push('\n');
            for &k in &self.ks {
                let _ = write!(s, "| {k} |");
                for c in &curves {
                    match (c.at(k), c.at(k_ref)) {
                        (Some(p), Some(r)) => {
                            let star = if p.extrapolated { "*" } else { "" };
                            let _ = write!(s, " {:.4e}{star} | {:.2} |", p.relmse, p.relmse / r.relmse);
                        }
                        _ => s.push_str(" – | – |"),
                    }
                }
                s.push('\n');
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(method: Method, k: Option<usize>, spp: usize, seconds: f64, relmse: f64) -> Measurement {
        let regions = vec![("diffuse".into(), 0.0, 2.0 * relmse)];
        Measurement { method, brdf_samples: k, spp, seconds, rmse: 0.0, relmse, bias: 0.0, regions, plans: Vec::new() }
    }

    #[test]
    fn the_reference_k_is_the_one_nearest_256() {
        assert_eq!(reference_k(&[16, 64, 256, 1024]), 256);
        assert_eq!(reference_k(&[16, 128, 512]), 512, "a tie goes to the larger");
        assert_eq!(reference_k(&[16, 64]), 64);
        assert_eq!(reference_k(&[]), 256);
    }

    #[test]
    fn every_k_is_read_at_its_methods_time_and_the_optimum_found() {
        // Product-MIS at K = 64, 256, 1024: error ∝ 1/time between renders; K = 1024 costs
        // more time per spp. Product at K = 256 only; MIS reads no K.
        let (pm, p) = (Method::ProductMis, Method::Product);
        let ms = [
            m(pm, Some(64), 16, 1.0, 0.4),
            m(pm, Some(64), 64, 4.0, 0.1),
            m(pm, Some(256), 16, 1.0, 0.2),
            m(pm, Some(256), 64, 4.0, 0.05),
            m(pm, Some(1024), 16, 2.0, 0.2),
            m(pm, Some(1024), 64, 8.0, 0.05),
            m(p, Some(256), 16, 10.0, 0.3),
            m(Method::Mis, None, 16, 0.5, 0.8),
        ];
        let sweep = KSweep::new(&ms, 256).unwrap();
        assert_eq!(&sweep.ks[..], &[64, 256, 1024][..]);
        assert_eq!(sweep.curves.len(), 4, "product-MIS and product, over all and diffuse: {:?}", sweep.curves);
        let all = &sweep.curves[0];
        assert_eq!((all.method, all.region.as_str(), all.seconds), (pm, "all", 4.0));
        let at = |k| all.at(k).unwrap();
        assert!((at(64).relmse - 0.1).abs() < 1e-12 && (at(256).relmse - 0.05).abs() < 1e-12);
        assert!((at(1024).relmse - 0.1).abs() < 1e-12, "half the spp in the time: twice the error");
        assert!(!at(64).extrapolated && !at(1024).extrapolated);
        assert_eq!(all.optimum().unwrap().brdf_samples, 256);
        assert_eq!(all.plateau(), Some((256, 256)));
        let product = &sweep.curves[1];
        assert_eq!((product.method, product.seconds, product.points.len()), (p, 10.0, 1));
        assert_eq!((sweep.curves[2].region.as_str(), sweep.curves[2].method), ("diffuse", pm));
        let csv = sweep.csv();
        assert!(csv.contains("all,product-mis,1024,4.000000,1.000000e-1,false"), "{csv}");
        let md = sweep.markdown("t", 2, "test");
        assert!(md.contains("| all | product-mis | 4.000 | 256 | 5.0000e-2 | 1.00 | 256–256 |"), "{md}");
        assert!(md.contains("| 1024 | 1.0000e-1 | 2.00 | – | – |"), "{md}");
        assert!(md.contains("## pixels on diffuse"), "{md}");
        assert!(KSweep::new(&ms[7..], 256).is_none(), "no method reads K");
    }

    #[test]
    fn outside_its_renders_the_error_goes_as_one_over_time() {
        let pm = Method::ProductMis;
        let ms = [m(pm, Some(16), 16, 1.0, 0.4), m(pm, Some(16), 64, 2.0, 0.001)];
        let series = Series { method: pm, brdf_samples: Some(16) };
        let (e, outside) = relmse_near(&ms, series, "all", 8.0).unwrap();
        assert!(outside && (e - 0.001 / 4.0).abs() < 1e-15, "{e}");
        let (e, outside) = relmse_near(&ms, series, "all", 0.5).unwrap();
        assert!(outside && (e - 0.8).abs() < 1e-12, "{e}");
        assert!(!relmse_near(&ms, series, "all", 1.5).unwrap().1);
    }
}
