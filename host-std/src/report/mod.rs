//! `ppis report`: error against run time. Each method renders the scene at each sample count
//! (same threads, wall clock of the render alone), is compared with a reference, and the
//! results go to a CSV, a log-log plot (SVG and PNG) and a Markdown equal-time table.
//!
//! Errors are over all pixels and channels: RMSE = √mean (x − r)², relMSE = mean (x − r)²/(r² + ε)
//! with ε = 0.01 (the usual guard for dark pixels).

mod errors;
mod plot;
mod tables;

pub use errors::{Regions, errors};
pub use plot::plot;
pub use tables::{csv, markdown, relmse_at};

use crate::plan::{self, Method, Settings, ShadingPoints};
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
    /// Visibility samples per pixel.
    pub spp: usize,
    /// Render time (the fastest of the repeats).
    pub seconds: f64,
    /// RMSE over all pixels and channels.
    pub rmse: f64,
    /// relMSE over all pixels and channels.
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

/// Renders every (method, spp) pair, with `points` shading points per pixel, and measures it
/// against `reference`. With `bracket`
/// (the base method of the equal-time tables), every faster method is then rendered on at
/// doubling spp — at most [`BRACKET_DOUBLINGS`] times — until its time reaches the base's at
/// its largest spp, so that the tables interpolate its error there instead of extrapolating.
/// Renders are timed by `timing.clock`. With `timing.repeat` > 1 every render is timed that many times in all, in rounds over all the
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
    points: ShadingPoints,
    reference: &[[f32; 3]],
    bracket: Option<Method>,
    timing: Timing,
    mut progress: impl FnMut(&Measurement),
) -> Vec<Measurement> {
    let regions = Regions::of(scene, bvh);
    let settings =
        |method: Method, spp: usize| Settings { method, spp, shading_points: points.resolve(method, spp), ..*base };
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
        let m = Measurement { method, spp, seconds: timing.clock.seconds(&image), rmse, relmse, regions, plans };
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
    keep_fastest(&mut out, timing.repeat, |method, spp| {
        timing.clock.seconds(&plan::render(scene, bvh, env, &Settings { progress: false, ..settings(method, spp) }))
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
}
