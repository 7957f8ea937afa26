//! One pixel, in named steps: for each of its shading points a camera ray
//! (`Camera::directions`), its intersection with the scene, the shading point there
//! (`primary::surface`) or the light it sees (`primary::background`, `primary::emitted`);
//! then the light sampled at every
//! shading point (`sample_light` for the environment, `shade_lights` for the other lights), and
//! the pixel's mean (`accumulate`).

use crate::render::primary::{Hit, background, emitted, shading_point, surface};
use crate::render::sampler_cache::{Lead, SamplerCache};
use crate::render::shade::{self, CountingVisibility, Run, Sampling};
use crate::render::shade_cuts::shade_cuts;
use crate::render::shade_lights::{budgets, shade_lights};
use crate::render::strategy::Strategy;
use crate::render::wavefront::{self, Shadows, WaveBuffers};
use crate::render::{Context, Counters};
use crate::trace::bvh::{self, Surface};
use sampler_core::brdf::Brdf;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::ShadingPoint;
use sampler_core::glam::{DVec2, DVec3, Vec3};
use sampler_core::lightcuts::CutEntry;
use sampler_core::points::{permutation_element, sobol02};
use sampler_core::rng::hash_combine;

/// Shading points traced together: their hits are grouped by material before shading.
const GROUP: usize = 64;

/// A tile's scratch memory, reused from pixel to pixel.
pub struct Scratch {
    /// The samplers built and kept.
    cache: SamplerCache,
    /// The pixel's primary hits.
    hits: Vec<Hit>,
    /// The wavefronts' buffers.
    waves: WaveBuffers,
    /// Lightcuts' cut.
    cuts: Vec<CutEntry>,
    /// The group's per-point arrays.
    group: GroupBuffers,
    /// What the tile's pixels did so far.
    pub counters: Counters,
}

/// A group of shading points' per-point arrays, kept with the tile so that a pixel neither
/// zero-fills nor copies them: each use writes the entries it reads.
struct GroupBuffers {
    /// The film positions of the group's camera rays.
    film: [DVec2; GROUP],
    /// The camera rays' directions.
    dirs: [Vec3; GROUP],
    /// Where each camera ray hits.
    found: [Option<bvh::Hit>; GROUP],
    /// What each camera ray that misses the scene sees of the environment (written for the
    /// misses only; the other entries are left from earlier groups).
    background: [Vec3; GROUP],
    /// Each hit's estimate, by hit.
    values: [DVec3; GROUP],
    /// Whether a hit is shaded yet, by hit.
    done: [bool; GROUP],
    /// The hits of one material, in order.
    members: [usize; GROUP],
    /// The members' runs of the pixel's sequences.
    runs: [Run; GROUP],
    /// Where the members' shadow rays start.
    origins: [Vec3; GROUP],
    /// The members' estimates.
    out: [DVec3; GROUP],
}

impl Default for GroupBuffers {
    fn default() -> Self {
        Self {
            film: [DVec2::ZERO; GROUP],
            dirs: [Vec3::ZERO; GROUP],
            found: [None; GROUP],
            background: [Vec3::ZERO; GROUP],
            values: [DVec3::ZERO; GROUP],
            done: [false; GROUP],
            members: [0; GROUP],
            runs: [Run { seed: 0, block: 0 }; GROUP],
            origins: [Vec3::ZERO; GROUP],
            out: [DVec3::ZERO; GROUP],
        }
    }
}

impl Scratch {
    /// Scratch for a scene of `materials` materials and pixels of `shading_points` points.
    #[must_use]
    pub fn new(materials: usize, shading_points: usize) -> Self {
        Self {
            cache: SamplerCache::new(materials),
            hits: Vec::with_capacity(shading_points.clamp(1, GROUP)),
            waves: WaveBuffers::default(),
            cuts: Vec::new(),
            group: GroupBuffers::default(),
            counters: Counters::default(),
        }
    }
}

/// The seeds of one pixel.
#[derive(Clone, Copy)]
struct Seeds {
    /// The pixel's: its film positions, and the samplers' builds.
    pixel: u64,
    /// Its light-sample sequences, shared by its shading points (each takes its own run of
    /// them, see [`shade::Run`]).
    light: u64,
}

/// One pixel: the mean over its shading points (product-MIS samplers shared per pixel and
/// material, and reused by the tile's next pixels while their shading points stay within
/// the material's reuse angle; every other sampler built per shading point).
pub fn pixel(ctx: &Context<'_, '_>, x: usize, y: usize, scratch: &mut Scratch) -> [f32; 3] {
    let pixel = hash_combine(ctx.options.seed, (y * ctx.camera.width as usize + x) as u64);
    let seeds = Seeds { pixel, light: hash_combine(pixel, 0x11647) };
    let p = ctx.options.shading_points.max(1);
    // Accumulated in f64: single samples of a 1e30 map can exceed the f32 range.
    let mut sum = DVec3::ZERO;
    let mut done = 0;
    while done < p {
        let m = (p - done).min(GROUP);
        let film = &mut scratch.group.film[..m];
        sobol02(seeds.pixel, done as u32, film);
        let dirs = &mut scratch.group.dirs[..m];
        ctx.camera.directions(x, y, film, dirs);
        scratch.counters.camera_rays += m as u64;
        let found = &mut scratch.group.found[..m];
        ctx.bvh.intersect_from(ctx.camera.origin, dirs, ctx.camera.near_clip, found);
        let env_seen = background(ctx, dirs, found, &mut scratch.group.background[..m]);
        scratch.hits.clear();
        for (k, (&dir, hit)) in dirs.iter().zip(found.iter()).enumerate() {
            let Some(hit) = hit else {
                if env_seen {
                    sum += scratch.group.background[k].as_dvec3();
                }
                continue;
            };
            match hit.surface {
                Surface::Material(material) => {
                    if let Some(h) = surface(ctx, dir, hit, material, done + k) {
                        scratch.hits.push(h);
                    }
                }
                Surface::Emitter(light) => sum += emitted(ctx, light, dir),
            }
        }
        let (env_budget, light_budget) = budgets(ctx);
        if let Some(cuts) = ctx.lightcuts {
            sum += shade_cuts(ctx, cuts, &scratch.hits, &mut scratch.cuts, &mut scratch.counters);
        } else if let Some(env) = ctx.env {
            sample_light(ctx, env, seeds, env_budget, scratch, &mut sum);
        } else {
            scratch.counters.shading_points += scratch.hits.len() as u64;
        }
        if let Some(lights) = ctx.lights {
            let run_of = |h: &Hit| run(seeds, h, p);
            sum += shade_lights(ctx, lights, &scratch.hits, run_of, light_budget, &mut scratch.counters);
        }
        done += m;
    }
    accumulate(sum, p, &mut scratch.counters)
}

/// The run of the pixel's light sequences the shading point `h` takes (see [`shade::Run`]),
/// of a pixel of `p` shading points.
fn run(seeds: Seeds, h: &Hit, p: usize) -> Run {
    Run { seed: seeds.light, block: permutation_element(h.index as u32, p as u32, seeds.light as u32) as usize }
}

/// Samples the environment's light with `budget` samples (or its material plan's own) at every
/// shading point of the group in `scratch`, adding to `sum`: one sampler per shading point, or for product-MIS one per
/// material, built at its first point. Where a material's sampler is the same at all its points (the environment, or the shared
/// product-MIS sampler) and each point takes few samples, its points are shaded as one
/// wavefront. The points' estimates are added in the order of the per-point path: hit order,
/// and a product-MIS material's points together at its first.
fn sample_light(
    ctx: &Context<'_, '_>,
    env: &EnvHierarchy<'_>,
    seeds: Seeds,
    budget: usize,
    scratch: &mut Scratch,
    sum: &mut DVec3,
) {
    let Scratch { cache, hits, waves, group: buffers, counters, .. } = scratch;
    let n = hits.len();
    let p = ctx.options.shading_points.max(1);
    let shadows = ctx.options.shadows;
    let run_of = |h: &Hit| run(seeds, h, p);
    buffers.done[..n].fill(false);
    for first in 0..n {
        if buffers.done[first] {
            continue;
        }
        let lead = &hits[first];
        let group = lead.material;
        let budget = ctx.plans[group].env_budget.unwrap_or(budget);
        let lead_sp = shading_point(ctx.scene, lead);
        let seed = hash_combine(seeds.pixel, 0xb5df ^ (group as u64) << 20);
        // A plane's points sample its product: env-only sampling of the plane's view.
        let plane_view = lead.plane.zip(ctx.planes).map(|(k, planes)| planes.view(env, k));
        let (env, sampling) = match &plane_view {
            Some(view) => (view, Sampling::Env),
            None => (env, cache.sampling(ctx, env, &Lead { hit: lead, sp: &lead_sp, seed })),
        };
        let m = members_of(hits, first, &mut buffers.members);
        let mut rays = 0u64;
        let shaded = if wavefront::fits(&sampling, budget) {
            rays += shade_members(ctx, env, &sampling, hits, m, run_of, budget, waves, buffers);
            let GroupBuffers { values, done, members, out, .. } = buffers;
            for (&k, &o) in members[..m].iter().zip(&out[..m]) {
                (values[k], done[k]) = (o, true);
            }
            m
        } else {
            // One point, or a product-MIS or two-level-MIS material's points through their
            // shared sampler.
            let shared = matches!(sampling, Sampling::ProductMis { .. } | Sampling::TwoLevelMis { .. });
            let shaded = if shared { m } else { 1 };
            for i in 0..shaded {
                let k = buffers.members[i];
                let origin = hits[k].origin;
                let test = |d: Vec3| !shadows || !ctx.bvh.occluded(origin, d, 0.0, f32::INFINITY);
                let mut vis = CountingVisibility { test, rays: 0 };
                let sp = shading_point(ctx.scene, &hits[k]);
                buffers.values[k] = shade::shade(&sampling, env, &sp, budget, run_of(&hits[k]), &mut vis);
                buffers.done[k] = true;
                rays += vis.rays;
            }
            shaded
        };
        counters.shading_points += shaded as u64;
        // Only rays traced count.
        counters.shadow_rays += if shadows { rays } else { 0 };
    }
    add_in_order(ctx, hits, &buffers.values[..n], sum);
}

/// The estimates of the first `m` of `buffers.members` shaded as one wavefront through
/// `sampling` (see [`wavefront::fits`]) into `buffers.out`; returns the shadow rays traced.
/// `run_of` gives each hit's run.
#[allow(clippy::too_many_arguments)]
fn shade_members(
    ctx: &Context<'_, '_>,
    env: &EnvHierarchy<'_>,
    sampling: &Sampling<'_, '_>,
    hits: &[Hit],
    m: usize,
    run_of: impl Fn(&Hit) -> Run,
    budget: usize,
    waves: &mut WaveBuffers,
    buffers: &mut GroupBuffers,
) -> u64 {
    let GroupBuffers { members, runs, origins, out, .. } = buffers;
    // On the stack and filled only as far as the members: a pixel's few points cost no
    // allocation and no fill of a group's full array.
    let mut points: heapless::Vec<ShadingPoint<'_, dyn Brdf + '_>, GROUP> = heapless::Vec::new();
    for (i, &k) in members[..m].iter().enumerate() {
        let h = &hits[k];
        // At most GROUP members: the push cannot fail.
        let _ = points.push(shading_point(ctx.scene, h));
        (runs[i], origins[i]) = (run_of(h), h.origin);
    }
    let shadows = Shadows { origins: &origins[..m], bvh: ctx.options.shadows.then_some(ctx.bvh) };
    wavefront::shade_wavefront(sampling, env, &points, &runs[..m], budget, waves, shadows, &mut out[..m])
        .map_or(0, |r| r as u64)
}

/// Writes the indices of the hits of `hits[first]`'s material (and plane) from `first` on (in
/// order) to `members` and returns their count: the points a wavefront or a shared sampler
/// shades together.
fn members_of(hits: &[Hit], first: usize, members: &mut [usize; GROUP]) -> usize {
    let (material, plane) = (hits[first].material, hits[first].plane);
    let mut m = 0;
    for (k, h) in hits.iter().enumerate().skip(first) {
        if h.material == material && h.plane == plane {
            members[m] = k;
            m += 1;
        }
    }
    m
}

/// Adds the points' estimates to `sum` in hit order, a product-MIS material's points
/// together at its first point.
fn add_in_order(ctx: &Context<'_, '_>, hits: &[Hit], values: &[DVec3], sum: &mut DVec3) {
    for (first, lead) in hits.iter().enumerate() {
        let group = lead.material;
        if !matches!(ctx.plans[group].strategy, Strategy::ProductMis { .. }) {
            *sum += values[first];
        } else if !hits[..first].iter().any(|h| h.material == group) {
            for (k, _) in hits.iter().enumerate().skip(first).filter(|(_, h)| h.material == group) {
                *sum += values[k];
            }
        }
    }
}

/// The pixel's value: the mean of its shading points, or 0 (counted) where the mean exceeds
/// the f32 range of the output or is NaN.
fn accumulate(sum: DVec3, shading_points: usize, counters: &mut Counters) -> [f32; 3] {
    let mean = (sum / shading_points as f64).as_vec3();
    if mean.is_finite() {
        mean.to_array()
    } else {
        counters.non_finite += 1;
        [0.0; 3]
    }
}
