//! `cargo bench -p host-std --bench bvh [--features embree]`: closest-hit and shadow-ray
//! throughput on one thread of our BVH, `obvhs`'s CWBVH and (with the `embree` feature,
//! Debian's `libembree-dev`) Embree 3, on the scenes of docs/scenes/ and a 100k-triangle mesh.
//! The figures are in docs/bvh.md.

mod cpu_time;
mod scenes;
#[cfg(feature = "embree")]
mod theirs_embree;
mod theirs_obvhs;

use cpu_time::ThreadCpu;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use host_std::trace::bvh::{RaysAhead, ShadowRay};
use sampler_core::glam::Vec3;
use scenes::{Case, Ray};
use std::hint::black_box;
use std::time::Duration;

/// What the benchmark asks of each hierarchy.
trait Tracer {
    fn closest(&self, r: &Ray) -> Option<f32>;
    fn occluded(&self, r: &Ray) -> bool;
}

struct Ours<'a>(&'a host_std::trace::bvh::Bvh);

impl Tracer for Ours<'_> {
    fn closest(&self, r: &Ray) -> Option<f32> {
        self.0.intersect(r.o, r.d, r.t_min, f32::INFINITY).map(|h| h.t)
    }
    fn occluded(&self, r: &Ray) -> bool {
        self.0.occluded(r.o, r.d, r.t_min, f32::INFINITY)
    }
}

impl Tracer for theirs_obvhs::Obvhs {
    fn closest(&self, r: &Ray) -> Option<f32> {
        theirs_obvhs::Obvhs::closest(self, r.o, r.d, r.t_min)
    }
    fn occluded(&self, r: &Ray) -> bool {
        theirs_obvhs::Obvhs::occluded(self, r.o, r.d, r.t_min)
    }
}

#[cfg(feature = "embree")]
impl Tracer for theirs_embree::Embree {
    fn closest(&self, r: &Ray) -> Option<f32> {
        theirs_embree::Embree::closest(self, r.o, r.d, r.t_min)
    }
    fn occluded(&self, r: &Ray) -> bool {
        theirs_embree::Embree::occluded(self, r.o, r.d, r.t_min)
    }
}

/// Prints how many answers `t` shares with ours, once per case, so that a fast wrong answer
/// shows.
fn agreement(case: &Case, name: &str, t: &impl Tracer) {
    let ours = Ours(&case.bvh);
    let close = |a: Option<f32>, b: Option<f32>| match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() <= 1e-4 * a.max(1.0),
        (None, None) => true,
        _ => false,
    };
    let hits = case.camera.iter().filter(|r| close(ours.closest(r), t.closest(r))).count();
    let shadows = case.shadow.iter().filter(|r| ours.occluded(r) == t.occluded(r)).count();
    eprintln!(
        "{}: {name} agrees with ours on {hits} of {} closest hits, {shadows} of {} shadow rays",
        case.name,
        case.camera.len(),
        case.shadow.len()
    );
}

/// One tracer's two measurements on a case.
fn measure(c: &mut Criterion<ThreadCpu>, case: &Case, name: &str, t: &impl Tracer) {
    agreement(case, name, t);
    let mut g = c.benchmark_group(format!("closest/{}", case.name));
    g.throughput(Throughput::Elements(case.camera.len() as u64));
    g.bench_function(name, |b| b.iter(|| count(&case.camera, |r| t.closest(r).is_some())));
    g.finish();
    let mut g = c.benchmark_group(format!("shadow/{}", case.name));
    g.throughput(Throughput::Elements(case.shadow.len() as u64));
    g.bench_function(name, |b| b.iter(|| count(&case.shadow, |r| t.occluded(r))));
    g.finish();
}

/// Our rays through the batched calls, in batches as the renderer hands them.
fn many(c: &mut Criterion<ThreadCpu>, case: &Case) {
    let rays: Vec<ShadowRay> =
        case.shadow.iter().map(|r| ShadowRay { origin: r.o, dir: r.d, t_min: r.t_min, t_max: f32::INFINITY }).collect();
    let mut out = vec![false; 256];
    let mut g = c.benchmark_group(format!("shadow/{}", case.name));
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("ours-many", |b| {
        b.iter(|| {
            let mut n = 0;
            for batch in rays.chunks(256) {
                let out = &mut out[..batch.len()];
                case.bvh.occluded_many(black_box(batch), out);
                n += out.iter().filter(|&&o| o).count();
            }
            black_box(n)
        })
    });
    g.finish();
    // The batches the renderer hands over: a wavefront's shadow rays over (0, ∞) as structure
    // of arrays, and a pixel group's camera rays from the camera's origin.
    let mut ahead = RaysAhead::default();
    let mut blocked = vec![false; 256];
    let mut g = c.benchmark_group(format!("shadow/{}", case.name));
    g.throughput(Throughput::Elements(case.shadow.len() as u64));
    g.bench_function("ours-ahead", |b| {
        b.iter(|| {
            let mut n = 0;
            for batch in case.shadow.chunks(256) {
                ahead.clear_for(batch.len());
                batch.iter().for_each(|r| ahead.push_if(r.o, r.d, true));
                let out = &mut blocked[..batch.len()];
                case.bvh.occluded_ahead_many(black_box(&ahead), out);
                n += out.iter().filter(|&&o| o).count();
            }
            black_box(n)
        })
    });
    g.finish();
    let (origin, t_min) = (case.camera[0].o, case.camera[0].t_min);
    let dirs: Vec<Vec3> = case.camera.iter().map(|r| r.d).collect();
    let mut found = vec![None; 64];
    let mut g = c.benchmark_group(format!("closest/{}", case.name));
    g.throughput(Throughput::Elements(dirs.len() as u64));
    g.bench_function("ours-from", |b| {
        b.iter(|| {
            let mut n = 0;
            for batch in dirs.chunks(64) {
                let out = &mut found[..batch.len()];
                case.bvh.intersect_from(origin, black_box(batch), t_min, out);
                n += out.iter().filter(|h| h.is_some()).count();
            }
            black_box(n)
        })
    });
    g.finish();
}

fn group(c: &mut Criterion<ThreadCpu>, case: &Case) {
    eprintln!(
        "{}: {} primitives, {} camera rays, {} shadow rays",
        case.name,
        case.bvh.primitive_count(),
        case.camera.len(),
        case.shadow.len()
    );
    measure(c, case, "ours", &Ours(&case.bvh));
    many(c, case);
    measure(c, case, "obvhs", &theirs_obvhs::Obvhs::build(&case.bvh));
    #[cfg(feature = "embree")]
    measure(c, case, "embree", &theirs_embree::Embree::build(&case.bvh));
}

/// How many rays `f` says yes to, kept from being optimised away.
fn count(rays: &[Ray], f: impl Fn(&Ray) -> bool) -> usize {
    black_box(rays.iter().filter(|r| f(black_box(r))).count())
}

fn bvh(c: &mut Criterion<ThreadCpu>) {
    for case in scenes::cases() {
        group(c, &case);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(cpu_time::ThreadCpu).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3)).sample_size(20);
    targets = bvh
}
criterion_main!(benches);
