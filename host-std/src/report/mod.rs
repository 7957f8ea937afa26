//! `ppis report`: error against run time. Each method renders the scene at each sample count
//! (same threads, wall clock of the render alone), is compared with a reference, and the
//! results go to a CSV, a log-log plot (SVG and PNG) and a Markdown equal-time table.
//!
//! Errors are over all pixels and channels: RMSE = √mean (x − r)², relMSE = mean (x − r)²/(r² + ε)
//! with ε = 0.01 (the usual guard for dark pixels).

mod errors;
mod k_plot;
mod k_sweep;
mod plot;
mod series;
mod tables;

pub use errors::{Regions, errors};
pub use k_plot::plot_k;
pub use k_sweep::{KCurve, KPoint, KSweep, reference_k};
pub use plot::plot;
pub use series::Series;
pub use tables::{csv, markdown, relmse_at};

use crate::plan::method::Lighting;
use crate::plan::prepass::render_planned;
use crate::plan::{self, Method, Rendered, Settings, ShadingPoints};
use crate::render::brdf_samples::BrdfSamples;
use crate::render::crop::Crop;
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use sampler_core::env::EnvHierarchy;

/// What a sweep's renders are timed by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Clock {
    /// Wall-clock seconds of the render: its latency, on an otherwise idle machine.
    #[default]
    Wall,
    /// CPU seconds of every render thread: its cost in cores, which does not grow while its
    /// threads wait for a core on a machine shared with other work (wall clock where the
    /// platform does not say).
    Cpu,
}

impl Clock {
    /// A render's time by this clock.
    fn seconds(self, image: &plan::Rendered) -> f64 {
        match self {
            Clock::Wall => image.render_seconds,
            Clock::Cpu => image.render_cpu_seconds.unwrap_or(image.render_seconds),
        }
    }
}

/// How a sweep times its renders: by which clock, and the fastest of how many runs.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    /// The clock.
    pub clock: Clock,
    /// Runs per render, the fastest kept (at least 1).
    pub repeat: usize,
}

/// One render of the sweep: errors over all pixels (`rmse`, `relmse`) and per region.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// The method.
    pub method: Method,
    /// BRDF samples per product sampler, where the sweep varies them and the method reads
    /// them (`None`: the sweep's one K, or a method that builds no product sampler).
    pub brdf_samples: Option<usize>,
    /// Visibility samples per pixel.
    pub spp: usize,
    /// Render time (the fastest of the repeats).
    pub seconds: f64,
    /// RMSE over all pixels and channels.
    pub rmse: f64,
    /// relMSE over all pixels and channels.
    pub relmse: f64,
    /// The image's mean over the reference's, less one: the bias of a converged deterministic
    /// method (SIS, Lightcuts), noise otherwise.
    pub bias: f64,
    /// (region, RMSE, relMSE) for each region of `Regions`.
    pub regions: Vec<(String, f64, f64)>,
    /// `auto`: per material its label and the plan its pilot settled on (empty otherwise).
    pub plans: Vec<(String, String)>,
}

impl Measurement {
    /// The method and K of this render: the line it belongs to in the plots and tables.
    #[must_use]
    pub fn series(&self) -> Series {
        Series { method: self.method, brdf_samples: self.brdf_samples }
    }

    /// relMSE over `region` ("all" for the whole image).
    pub fn relmse_in(&self, region: &str) -> Option<f64> {
        if region == "all" {
            return Some(self.relmse);
        }
        self.regions.iter().find(|r| r.0 == region).map(|r| r.2)
    }
}

/// Renders every (method, K, spp) triple — every K of `brdf_samples` for the methods that read
/// it, one render per spp for the others — with `points` shading points per pixel, and
/// measures it against `reference`. With `bracket` (the base series of the equal-time tables),
/// every other series is then rendered on at doubling spp — at most [`BRACKET_DOUBLINGS`]
/// times — until its time reaches the base's at its largest spp, and at halving spp while its
/// fastest render is still slower than that, so that the tables interpolate its error there
/// instead of extrapolating; in a sweep over K, each K is bracketed so against its method at
/// the reference K (`reference_k`, the time of the K figure: [`KSweep`]). Renders are timed by `timing.clock`. With `timing.repeat` > 1
/// every render is timed that many times in all, in rounds over all the renders — so that a
/// slow spell of the machine falls on all series alike — and keeps its fastest time (the
/// image, and so its error, is the same each time: renders are deterministic). `progress` is
/// told about each first render.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    methods: &[Method],
    spps: &[usize],
    brdf_samples: &[usize],
    base: &Settings,
    points: ShadingPoints,
    reference: &[[f32; 3]],
    bracket: Option<Series>,
    timing: Timing,
    mut progress: impl FnMut(&Measurement),
) -> Vec<Measurement> {
    let regions = Regions::of(scene, bvh);
    let frame = Crop::full(scene.camera.width as usize, scene.camera.height as usize);
    let lighting = Lighting::of(env.is_some(), scene.lights.len());
    let settings = |series: Series, spp: usize| Settings {
        method: series.method,
        spp,
        shading_points: points.resolve(series.method, spp, lighting),
        brdf_samples: series.brdf_samples.map_or(base.brdf_samples, BrdfSamples::Fixed),
        ..*base
    };
    let mut measure = |series: Series, spp: usize| {
        let (image, _) = render_planned(scene, bvh, env, &settings(series, spp), points, frame);
        let (rmse, relmse) = errors(&image.pixels, reference);
        let bias = errors::relative_bias(&image.pixels, reference);
        let regions = regions.errors(&image.pixels, reference);
        let plans = auto_plans(scene, &image);
        let (method, k) = (series.method, series.brdf_samples);
        let seconds = timing.clock.seconds(&image);
        let m = Measurement { method, brdf_samples: k, spp, seconds, rmse, relmse, bias, regions, plans };
        progress(&m);
        m
    };
    let mut all: Vec<Series> = Vec::new();
    for &method in methods {
        for &k in brdf_samples {
            let series = Series::of(method, brdf_samples, k);
            if !all.contains(&series) {
                all.push(series);
            }
        }
    }
    let mut out = Vec::new();
    for &series in &all {
        for &spp in spps {
            out.push(measure(series, spp));
        }
    }
    if let Some(target) = bracket {
        bracket_base(&mut out, &all, target, &mut measure);
        if brdf_samples.len() > 1 {
            let k_ref = reference_k(brdf_samples);
            for &method in methods.iter().filter(|m| m.reads_brdf_samples()) {
                let own: Vec<Series> = all.iter().copied().filter(|s| s.method == method).collect();
                bracket_base(&mut out, &own, Series::of(method, brdf_samples, k_ref), &mut measure);
            }
        }
    }
    keep_fastest(&mut out, timing.repeat, |series, spp| {
        let settings = Settings { progress: false, ..settings(series, spp) };
        timing.clock.seconds(&render_planned(scene, bvh, env, &settings, points, frame).0)
    });
    out
}

/// Times every measurement `repeat − 1` more times with `time`, in rounds over all of them
/// (a slow spell of the machine falls on every series alike), and keeps each one's fastest.
fn keep_fastest(out: &mut [Measurement], repeat: usize, mut time: impl FnMut(Series, usize) -> f64) {
    for _ in 1..repeat {
        for m in out.iter_mut() {
            m.seconds = m.seconds.min(time(m.series(), m.spp));
        }
    }
}

/// Renders every series but `target` on at doubling spp until it reaches `target`'s time at
/// its largest spp, and at halving spp while it is slower than that everywhere (see [`sweep`]).
fn bracket_base(
    out: &mut Vec<Measurement>,
    all: &[Series],
    target: Series,
    measure: &mut impl FnMut(Series, usize) -> Measurement,
) {
    let of = |out: &[Measurement], s: Series| -> Vec<(usize, f64)> {
        out.iter().filter(|x| x.series() == s).map(|x| (x.spp, x.seconds)).collect()
    };
    let Some((_, goal)) = of(out, target).into_iter().max_by_key(|x| x.0) else { return };
    for &series in all.iter().filter(|&&s| s != target) {
        for _ in 0..BRACKET_DOUBLINGS {
            match of(out, series).into_iter().max_by_key(|x| x.0) {
                Some((spp, seconds)) if seconds < goal && spp <= MAX_BRACKET_SPP / 2 => {
                    out.push(measure(series, 2 * spp));
                }
                _ => break,
            }
        }
        for _ in 0..BRACKET_DOUBLINGS {
            match of(out, series).into_iter().min_by_key(|x| x.0) {
                Some((spp, seconds)) if seconds > goal && spp >= 2 => out.push(measure(series, spp / 2)),
                _ => break,
            }
        }
    }
}

/// Most extra doublings of a method's spp when bracketing the base's time (8× its largest).
pub const BRACKET_DOUBLINGS: usize = 3;

/// No bracketing render goes beyond this many visibility samples per pixel.
const MAX_BRACKET_SPP: usize = 1 << 20;

/// `auto`'s plan per material as the report lists it, `(material, plan)`: its light samples per
/// shading point (which its cost and the pacing set), and " (pilot)" where the pilot overrode
/// the rules; materials with the same label, plan and samples listed once.
fn auto_plans(scene: &Scene, image: &Rendered) -> Vec<(String, String)> {
    let mut plans: Vec<(String, String)> = Vec::new();
    for (m, plan, samples, pilot) in image.auto_choices() {
        let changed = if pilot.is_some_and(|r| Some(r.chosen) != r.rule) { " (pilot)" } else { "" };
        let entry = (scene.materials[m].bsdf.label(), format!("{plan}, {samples} samples per shading point{changed}"));
        if !plans.contains(&entry) {
            plans.push(entry);
        }
    }
    plans
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(method: Method, spp: usize, seconds: f64, relmse: f64) -> Measurement {
        let regions = vec![("carpaint".into(), 0.0, relmse / 2.0)];
        Measurement {
            method,
            brdf_samples: None,
            spp,
            seconds,
            rmse: relmse.sqrt(),
            relmse,
            bias: 0.0,
            regions,
            plans: Vec::new(),
        }
    }

    #[test]
    fn repeats_keep_each_renders_fastest_time_in_rounds() {
        let mut out = [m(Method::Env, 4, 3.0, 0.1), m(Method::Mis, 4, 2.0, 0.1)];
        // Round 1: a slow spell (both slower than their first run); round 2: both faster.
        let times = [9.0, 9.0, 1.5, 0.5];
        let (mut calls, mut order) = (0, Vec::new());
        keep_fastest(&mut out, 3, |series, _| {
            order.push(series.method);
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
        let (e, outside) = relmse_at(&ms, Method::Env.into(), "all", 2.0).unwrap();
        assert!((e - 0.2).abs() < 1e-9 && !outside); // error ∝ 1/t between the points
        let (e, outside) = relmse_at(&ms, Method::Env.into(), "all", 8.0).unwrap();
        assert!((e - 0.05).abs() < 1e-9 && outside);
        let md = markdown("t", &ms, Method::Product.into(), 2, "test");
        assert!(md.contains("| 4 | 2.000 | 5.0000e-2 | 2.0000e-1 | 4.00 |"), "{md}");
        assert!(md.contains("### pixels on carpaint"), "{md}");
        assert!(md.contains("| 4 | 2.000 | 2.5000e-2 | 1.0000e-1 | 4.00 |"), "{md}");
        assert!(!md.contains(" spp: "), "no plans without auto");
        let mut auto = m(Method::Auto, 16, 3.0, 0.08);
        auto.plans = vec![("diffuse".into(), "env (pilot)".into()), ("carpaint".into(), "mis".into())];
        let md = markdown("t", &[auto], Method::Product.into(), 2, "test");
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
}
