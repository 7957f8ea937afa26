//! `ppis report`: error against run time. Each method renders the scene at each sample count
//! (same threads, wall clock of the render alone), is compared with a reference, and the
//! results go to a CSV, a log-log plot (SVG and PNG) and a Markdown equal-time table.
//!
//! Errors are over all pixels and channels: RMSE = √mean (x − r)², relMSE = mean (x − r)²/(r² + ε)
//! with ε = 0.01 (the usual guard for dark pixels).

use crate::plan::Method;
use crate::plan::{self, Settings};
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use sampler_core::env::EnvHierarchy;
use std::fmt::Write as _;
use std::path::Path;

/// One render of the sweep: errors over all pixels (`rmse`, `relmse`) and per region.
#[derive(Clone, Debug)]
pub struct Measurement {
    pub method: Method,
    pub spp: usize,
    pub seconds: f64,
    pub rmse: f64,
    pub relmse: f64,
    /// (region, RMSE, relMSE) for each region of `Regions`.
    pub regions: Vec<(String, f64, f64)>,
    /// `auto`: per material its label and the plan its pilot settled on (empty otherwise).
    pub plans: Vec<(String, String)>,
}

impl Measurement {
    /// relMSE over `region` ("all" for the whole image).
    pub fn relmse_in(&self, region: &str) -> Option<f64> {
        if region == "all" {
            return Some(self.relmse);
        }
        self.regions.iter().find(|r| r.0 == region).map(|r| r.2)
    }
}

/// Pixels grouped by the material their centre ray hits, named by kind and lobe width
/// ("diffuse", "roughconductor α=0.05", "phong n=200", "carpaint"); misses belong to no region.
pub struct Regions {
    pub names: Vec<String>,
    /// Per pixel, the index into `names`, or `None`.
    pub of_pixel: Vec<Option<usize>>,
}

impl Regions {
    pub fn of(scene: &Scene, bvh: &Bvh) -> Self {
        let camera = crate::trace::camera::Camera::new(&scene.camera);
        let (w, h) = (camera.width as usize, camera.height as usize);
        let mut names: Vec<String> = Vec::new();
        let mut of_pixel = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let d = camera.direction(x as f32 + 0.5, y as f32 + 0.5);
                of_pixel.push(bvh.intersect(camera.origin, d, camera.near_clip, f32::INFINITY).map(|hit| {
                    let label = scene.materials[hit.material as usize].bsdf.label();
                    names.iter().position(|n| *n == label).unwrap_or_else(|| {
                        names.push(label);
                        names.len() - 1
                    })
                }));
            }
        }
        Self { names, of_pixel }
    }

    /// RMSE and relMSE of each region.
    pub fn errors(&self, image: &[[f32; 3]], reference: &[[f32; 3]]) -> Vec<(String, f64, f64)> {
        self.names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let (mut se, mut rel, mut n) = (0.0f64, 0.0f64, 0usize);
                for ((p, r), region) in image.iter().zip(reference).zip(&self.of_pixel) {
                    if *region == Some(k) {
                        for c in 0..3 {
                            let d = p[c] as f64 - r[c] as f64;
                            se += d * d;
                            rel += d * d / (r[c] as f64 * r[c] as f64 + 0.01);
                        }
                        n += 3;
                    }
                }
                let n = n.max(1) as f64;
                (name.clone(), (se / n).sqrt(), rel / n)
            })
            .collect()
    }
}

/// RMSE and relMSE of `image` against `reference` (same size).
pub fn errors(image: &[[f32; 3]], reference: &[[f32; 3]]) -> (f64, f64) {
    let (mut se, mut rel) = (0.0f64, 0.0f64);
    for (p, r) in image.iter().zip(reference) {
        for c in 0..3 {
            let d = p[c] as f64 - r[c] as f64;
            se += d * d;
            rel += d * d / (r[c] as f64 * r[c] as f64 + 0.01);
        }
    }
    let n = (3 * image.len()) as f64;
    ((se / n).sqrt(), rel / n)
}

/// Shading points per pixel for a given spp: with `per_point` visibility samples per shading
/// point, P = spp / per_point (so primary rays, and with them the pixel-footprint integration,
/// grow with spp — with a fixed P the antialiasing error of edges and of a visible sun floors
/// every method at the same error); otherwise the requested P if it divides spp, else their
/// greatest common divisor.
pub fn shading_points_per_pixel(spp: usize, requested: usize, per_point: Option<usize>) -> usize {
    match per_point {
        Some(v) => (spp / v.max(1)).max(1),
        None => shading_points_for(spp, requested),
    }
}

/// The requested P if it divides spp, otherwise their greatest common divisor.
pub fn shading_points_for(spp: usize, requested: usize) -> usize {
    fn gcd(a: usize, b: usize) -> usize {
        if b == 0 { a } else { gcd(b, a % b) }
    }
    gcd(spp, requested.max(1)).max(1)
}

/// Renders every (method, spp) pair and measures it against `reference`. With `bracket`
/// (the base method of the equal-time tables), every faster method is then rendered on at
/// doubling spp — at most [`BRACKET_DOUBLINGS`] times — until its time reaches the base's at
/// its largest spp, so that the tables interpolate its error there instead of extrapolating.
/// With `repeat` > 1 every render is timed that many times in all, in rounds over all the
/// (method, spp) pairs — so that a slow spell of the machine falls on all methods alike — and
/// keeps its fastest time (the image, and so its error, is the same each time: renders are
/// deterministic). `progress` is told about each first render.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    methods: &[Method],
    spps: &[usize],
    base: &Settings,
    per_point: Option<usize>,
    reference: &[[f32; 3]],
    bracket: Option<Method>,
    repeat: usize,
    mut progress: impl FnMut(&Measurement),
) -> Vec<Measurement> {
    let regions = Regions::of(scene, bvh);
    let settings = |method: Method, spp: usize| Settings {
        method,
        spp,
        shading_points: shading_points_per_pixel(spp, base.shading_points, per_point),
        ..*base
    };
    let mut measure = |method: Method, spp: usize| {
        let image = plan::render(scene, bvh, env, &settings(method, spp));
        let (rmse, relmse) = errors(&image.pixels, reference);
        let regions = regions.errors(&image.pixels, reference);
        let plans = image
            .pilot
            .iter()
            .map(|r| {
                let changed = if Some(r.chosen) == r.rule { "" } else { " (pilot)" };
                (
                    scene.materials[r.material].bsdf.label(),
                    format!("{}{changed}", crate::plan::pilot::plan_name(r.chosen)),
                )
            })
            .collect();
        let m = Measurement { method, spp, seconds: image.render_seconds, rmse, relmse, regions, plans };
        progress(&m);
        m
    };
    let mut out = Vec::new();
    for &method in methods {
        for &spp in spps {
            out.push(measure(method, spp));
        }
    }
    if let Some(target) = bracket {
        bracket_base(&mut out, methods, target, &mut measure);
    }
    keep_fastest(&mut out, repeat, |method, spp| {
        plan::render(scene, bvh, env, &Settings { progress: false, ..settings(method, spp) }).render_seconds
    });
    out
}

/// Times every measurement `repeat − 1` more times with `time`, in rounds over all of them
/// (a slow spell of the machine falls on every method alike), and keeps each one's fastest.
fn keep_fastest(out: &mut [Measurement], repeat: usize, mut time: impl FnMut(Method, usize) -> f64) {
    for _ in 1..repeat {
        for m in out.iter_mut() {
            m.seconds = m.seconds.min(time(m.method, m.spp));
        }
    }
}

/// Renders every method but `target` on at doubling spp until it reaches `target`'s time at its
/// largest spp (see [`sweep`]).
fn bracket_base(
    out: &mut Vec<Measurement>,
    methods: &[Method],
    target: Method,
    measure: &mut impl FnMut(Method, usize) -> Measurement,
) {
    let slowest = |out: &[Measurement], m: Method| {
        out.iter().filter(|x| x.method == m).max_by_key(|x| x.spp).map(|x| (x.spp, x.seconds))
    };
    let Some((_, goal)) = slowest(out, target) else { return };
    for &method in methods.iter().filter(|&&m| m != target) {
        for _ in 0..BRACKET_DOUBLINGS {
            match slowest(out, method) {
                Some((spp, seconds)) if seconds < goal && spp <= MAX_BRACKET_SPP / 2 => {
                    out.push(measure(method, 2 * spp));
                }
                _ => break,
            }
        }
    }
}

/// Most extra doublings of a method's spp when bracketing the base's time (8× its largest).
pub const BRACKET_DOUBLINGS: usize = 3;

/// No bracketing render goes beyond this many visibility samples per pixel.
const MAX_BRACKET_SPP: usize = 1 << 20;

/// relMSE over `region` of `method` at time `t`, interpolated log-log between its
/// measurements (outside their range: extended along the nearest segment; flagged).
pub fn relmse_at(measurements: &[Measurement], method: Method, region: &str, t: f64) -> Option<(f64, bool)> {
    let mut pts: Vec<(f64, f64)> = measurements
        .iter()
        .filter(|m| m.method == method && m.seconds > 0.0)
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

/// `error_vs_time.csv`: one row per render and region ("all" is the whole image).
pub fn csv(measurements: &[Measurement]) -> String {
    let mut s = String::from("method,spp,seconds,region,rmse,relmse\n");
    for m in measurements {
        let _ = writeln!(s, "{},{},{:.6},all,{:.6e},{:.6e}", m.method, m.spp, m.seconds, m.rmse, m.relmse);
        for (region, rmse, relmse) in &m.regions {
            let _ = writeln!(s, "{},{},{:.6},{region},{rmse:.6e},{relmse:.6e}", m.method, m.spp, m.seconds);
        }
    }
    s
}

/// `report.md`: the measurements, then equal-time tables against `base` (e.g. `product`) for
/// the whole image and for each region.
pub fn markdown(
    scene: &str,
    measurements: &[Measurement],
    base: Method,
    threads: usize,
    reference_note: &str,
) -> String {
    let mut s = format!("# Error against time: {scene}\n\n{threads} threads; reference: {reference_note}.\n");
    s.push_str("relMSE = mean (x − r)²/(r² + 0.01) over pixels and channels; time = wall clock of the render. Regions: pixels whose centre ray hits a material of that kind and lobe width (GGX α, Phong exponent).\n\n");
    let regions: Vec<String> =
        measurements.first().map(|m| m.regions.iter().map(|r| r.0.clone()).collect()).unwrap_or_default();
    s.push_str("| method | spp | seconds | RMSE | relMSE |");
    for r in &regions {
        let _ = write!(s, " relMSE {r} |");
    }
    s.push_str("\n|---|---|---|---|---|");
    s.push_str(&"---|".repeat(regions.len()));
    s.push('\n');
    for m in measurements {
        let _ = write!(s, "| {} | {} | {:.3} | {:.4e} | {:.4e} |", m.method, m.spp, m.seconds, m.rmse, m.relmse);
        for r in &m.regions {
            let _ = write!(s, " {:.4e} |", r.2);
        }
        s.push('\n');
    }
    for m in measurements.iter().filter(|m| !m.plans.is_empty()) {
        let plans: Vec<String> = m.plans.iter().map(|(material, plan)| format!("{material} → {plan}")).collect();
        let _ = writeln!(s, "\n{} at {} spp: {}.", m.method, m.spp, plans.join(", "));
    }
    let mut others: Vec<Method> = Vec::new();
    for m in measurements {
        if m.method != base && !others.contains(&m.method) {
            others.push(m.method);
        }
    }
    let product: Vec<&Measurement> = measurements.iter().filter(|m| m.method == base).collect();
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

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The log-log plot of relMSE against time, one line per method, as SVG and PNG.
pub fn plot(path_svg: &Path, path_png: &Path, title: &str, measurements: &[Measurement]) -> Result<(), String> {
    use plotters::prelude::*;
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let (mut t0, mut t1, mut e0, mut e1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for m in measurements.iter().filter(|m| m.seconds > 0.0 && m.relmse > 0.0) {
        (t0, t1, e0, e1) = (t0.min(m.seconds), t1.max(m.seconds), e0.min(m.relmse), e1.max(m.relmse));
    }
    if !(t0 < t1 && e0 < e1) {
        (t0, t1, e0, e1) = (t0.min(1e-3), t1.max(1.0), e0.min(1e-6), e1.max(1.0));
    }
    let methods: Vec<Method> = {
        let mut v: Vec<Method> = measurements.iter().map(|m| m.method).collect();
        v.dedup();
        v
    };
    fn draw<DB: DrawingBackend>(
        root: DrawingArea<DB, plotters::coord::Shift>,
        title: &str,
        ranges: (f64, f64, f64, f64),
        methods: &[Method],
        measurements: &[Measurement],
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let (t0, t1, e0, e1) = ranges;
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d((t0 / 1.3..t1 * 1.3).log_scale(), (e0 / 1.5..e1 * 1.5).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("render time (s)")
            .y_desc("relMSE")
            .x_label_formatter(&|x| format!("{x:.3}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, &method) in methods.iter().enumerate() {
            let colour = Palette99::pick(k).to_rgba();
            let mut pts: Vec<(f64, f64)> = measurements
                .iter()
                .filter(|m| m.method == method && m.seconds > 0.0 && m.relmse > 0.0)
                .map(|m| (m.seconds, m.relmse))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(method.name())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled()))).map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())
    }
    let ranges = (t0, t1, e0, e1);
    draw(SVGBackend::new(path_svg, (900, 600)).into_drawing_area(), title, ranges, &methods, measurements)?;
    draw(BitMapBackend::new(path_png, (900, 600)).into_drawing_area(), title, ranges, &methods, measurements)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(method: Method, spp: usize, seconds: f64, relmse: f64) -> Measurement {
        let regions = vec![("carpaint".into(), 0.0, relmse / 2.0)];
        Measurement { method, spp, seconds, rmse: relmse.sqrt(), relmse, regions, plans: Vec::new() }
    }

    #[test]
    fn repeats_keep_each_renders_fastest_time_in_rounds() {
        let mut out = [m(Method::Env, 4, 3.0, 0.1), m(Method::Mis, 4, 2.0, 0.1)];
        // Round 1: a slow spell (both slower than their first run); round 2: both faster.
        let times = [9.0, 9.0, 1.5, 0.5];
        let (mut calls, mut order) = (0, Vec::new());
        keep_fastest(&mut out, 3, |method, _| {
            order.push(method);
            calls += 1;
            times[calls - 1]
        });
        assert_eq!(order, [Method::Env, Method::Mis, Method::Env, Method::Mis], "rounds over all renders");
        assert_eq!((out[0].seconds, out[1].seconds), (1.5, 0.5));
        // One run: no more timing.
        keep_fastest(&mut out, 1, |_, _| panic!("timed again"));
    }

    #[test]
    fn equal_time_interpolates_log_log() {
        let ms = [m(Method::Env, 4, 1.0, 0.4), m(Method::Env, 16, 4.0, 0.1), m(Method::Product, 4, 2.0, 0.05)];
        let (e, outside) = relmse_at(&ms, Method::Env, "all", 2.0).unwrap();
        assert!((e - 0.2).abs() < 1e-9 && !outside); // error ∝ 1/t between the points
        let (e, outside) = relmse_at(&ms, Method::Env, "all", 8.0).unwrap();
        assert!((e - 0.05).abs() < 1e-9 && outside);
        let md = markdown("t", &ms, Method::Product, 2, "test");
        assert!(md.contains("| 4 | 2.000 | 5.0000e-2 | 2.0000e-1 | 4.00 |"), "{md}");
        assert!(md.contains("### pixels on carpaint"), "{md}");
        assert!(md.contains("| 4 | 2.000 | 2.5000e-2 | 1.0000e-1 | 4.00 |"), "{md}");
        assert!(!md.contains(" spp: "), "no plans without auto");
        let mut auto = m(Method::Auto, 16, 3.0, 0.08);
        auto.plans = vec![("diffuse".into(), "env (pilot)".into()), ("carpaint".into(), "mis".into())];
        let md = markdown("t", &[auto], Method::Product, 2, "test");
        assert!(md.contains("auto at 16 spp: diffuse → env (pilot), carpaint → mis."), "{md}");
    }

    #[test]
    fn errors_of_an_exact_image_are_zero() {
        let r = vec![[1.0f32, 0.5, 0.0]; 4];
        assert_eq!(errors(&r, &r), (0.0, 0.0));
        let x = vec![[2.0f32, 0.5, 0.0]; 4];
        let (rmse, rel) = errors(&x, &r);
        assert!((rmse - (1.0f64 / 3.0).sqrt()).abs() < 1e-9 && (rel - 1.0 / 1.01 / 3.0).abs() < 1e-9);
    }

    #[test]
    fn shading_points_divide_spp() {
        assert_eq!(shading_points_for(16, 4), 4);
        assert_eq!(shading_points_for(2, 4), 2);
        assert_eq!(shading_points_for(6, 4), 2);
    }
}
