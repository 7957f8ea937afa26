//! What each C call costs, beside the Rust API doing the same work in the same run:
//! `cargo bench -p sampler-capi --bench calls` prints a table (docs/embedding.md, "What a call
//! costs").
//!
//! Each call and its Rust counterpart run in alternating blocks of about 20 ms, eleven rounds
//! each; a block is timed by the thread's CPU time, so other work on a shared machine slows
//! neither side, and the table gives each side's median and their ratio.

use libc::{CLOCK_THREAD_CPUTIME_ID, clock_gettime, timespec};
use sampler_capi::*;
use sampler_core::brdf::RoughConductor;
use sampler_core::cone::{Cone, build_cell_cones, cell_count};
use sampler_core::direction::DirectionSample;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len, sanitize_rgb};
use sampler_core::frame::Frame;
use sampler_core::glam::{DVec2, Vec3};
use sampler_core::latlong::latlong_to_equal_area;
use sampler_core::points::sobol02;
use sampler_core::sampler::{ProductArena, ProductParams, ProductSampler};
use sampler_core::two_level::{TwoLevelArena, TwoLevelSampler};
use std::ffi::c_void;
use std::hint::black_box;
use std::ptr::null_mut;

/// The lat-long sky's size and the equal-area level it is resampled to.
const WIDTH: usize = 2048;
const HEIGHT: usize = 1024;
const LEVEL: u32 = 10;
/// Points (and directions) a per-call block sweeps: enough that the descents leave the caches,
/// as a render's do.
const POINTS: usize = 4096;
/// Shading points the builds cycle through.
const SHADING_POINTS: usize = 16;

/// This thread's CPU time in nanoseconds.
fn thread_ns() -> f64 {
    let mut t = timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `clock_gettime` writes the struct it is handed.
    unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 * 1e9 + t.tv_nsec as f64
}

/// CPU nanoseconds per call of `c` and of `rust`, each a closure making `calls` calls: the
/// medians of alternating blocks.
fn side_by_side(calls: usize, mut c: impl FnMut(), mut rust: impl FnMut()) -> (f64, f64) {
    let time = |f: &mut dyn FnMut(), reps: usize| {
        let t0 = thread_ns();
        for _ in 0..reps {
            f();
        }
        (thread_ns() - t0) / (reps * calls) as f64
    };
    let once = time(&mut c, 1).max(1.0) * calls as f64;
    let reps = ((20e6 / once) as usize).max(1);
    let (mut tc, mut tr) = (Vec::new(), Vec::new());
    for _ in 0..11 {
        tc.push(time(&mut c, reps));
        tr.push(time(&mut rust, reps));
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (median(&mut tc), median(&mut tr))
}

fn row(call: &str, (c, rust): (f64, f64)) {
    let show = |ns: f64| match ns {
        1e5.. => format!("{:.2} ms", ns / 1e6),
        1e3.. => format!("{:.1} µs", ns / 1e3),
        _ => format!("{ns:.0} ns"),
    };
    println!("| {call} | {} | {} | {:.2} |", show(c), show(rust), c / rust);
}

/// A sky of the lat-long convention: a gradient and a small sun.
fn latlong_sky() -> Vec<[f32; 3]> {
    let mut t = vec![[0.0f32; 3]; WIDTH * HEIGHT];
    for (k, p) in t.iter_mut().enumerate() {
        let (i, j) = (k % WIDTH, k / WIDTH);
        let sky = 0.2 + 0.8 * (HEIGHT - j) as f32 / HEIGHT as f32;
        let sun = (600..606).contains(&i) && (320..326).contains(&j);
        *p = if sun { [5e4, 4.8e4, 4.5e4] } else { [0.4 * sky, 0.6 * sky, sky] };
    }
    t
}

/// Engine memory for an object.
fn memory(size: usize) -> Vec<u64> {
    vec![0u64; size.div_ceil(8)]
}

/// The library's objects of the bench, in memory it owns.
struct Objects {
    env: *mut ppis_env,
    brdf: *mut ppis_brdf,
    product: *mut ppis_product,
    two_level: *mut ppis_two_level,
    cones: *mut ppis_cones,
    _memory: [Vec<u64>; 5],
}

impl Objects {
    /// The objects over `pyramid` and `rgb`, which must outlive them.
    fn new(pyramid: &[f32], rgb: &[f32]) -> Self {
        let ok = ppis_status::PPIS_OK;
        let sizes = [ppis_env_size(), ppis_brdf_size(), ppis_product_size(), ppis_two_level_size(), ppis_cones_size(4)];
        let mut memory = sizes.map(memory);
        let [e, b, p, t, c] = memory.each_mut().map(|m| m.as_mut_ptr().cast::<c_void>());
        let (mut env, mut brdf, mut product, mut two_level, mut cones) =
            (null_mut(), null_mut(), null_mut(), null_mut(), null_mut());
        let gold = ppis_vec3 { x: 1.0, y: 0.78, z: 0.34 };
        // SAFETY: the memory is the library's sizes, kept with the objects; the caller keeps
        // the map alive.
        unsafe {
            let (pp, rp) = (pyramid.as_ptr(), rgb.as_ptr());
            assert_eq!(ppis_env_init(e, sizes[0], LEVEL, pp, pyramid.len(), rp, rgb.len(), &mut env), ok);
            assert_eq!(ppis_brdf_init_conductor(b, sizes[1], 0.1, gold, &mut brdf), ok);
            assert_eq!(ppis_product_init(p, sizes[2], &mut product), ok);
            assert_eq!(ppis_two_level_init(t, sizes[3], &mut two_level), ok);
            assert_eq!(ppis_cones_init(c, sizes[4], 4, &mut cones), ok);
        }
        Self { env, brdf, product, two_level, cones, _memory: memory }
    }
}

/// The map's preparation: lat-long resampling and the pyramid.
fn environment_rows(latlong: &[[f32; 3]], rgb: &[[f32; 3]]) {
    let mut rgb_out = vec![0.0f32; 3 << (2 * LEVEL)];
    let mut rgb_rust = vec![[0.0f32; 3]; 1 << (2 * LEVEL)];
    let (ll, rgb_f) = (latlong.as_flattened(), rgb.as_flattened());
    row(
        "lat-long 2048 × 1024 → equal-area 1024², ss 2",
        side_by_side(
            1,
            // SAFETY: the lengths are the buffers'.
            || unsafe {
                let (w, h) = (WIDTH as u32, HEIGHT as u32);
                let s = ppis_latlong_to_equal_area(ll.as_ptr(), w, h, LEVEL, 2, rgb_out.as_mut_ptr(), rgb_out.len());
                black_box(s);
            },
            || latlong_to_equal_area(latlong, WIDTH, HEIGHT, LEVEL, 2, &mut rgb_rust).unwrap(),
        ),
    );
    let mut pyr_out = vec![0.0f32; pyramid_len(LEVEL)];
    let mut pyr_rust = vec![0.0f32; pyramid_len(LEVEL)];
    row(
        "pyramid build, 1024² map",
        side_by_side(
            1,
            // SAFETY: the lengths are the buffers'.
            || unsafe {
                let s = ppis_build_pyramid(LEVEL, rgb_f.as_ptr(), rgb_f.len(), pyr_out.as_mut_ptr(), pyr_out.len());
                black_box(s);
            },
            || build_pyramid(LEVEL, rgb, &mut pyr_rust).unwrap(),
        ),
    );
}

/// Shading frames on a glossy sphere seen along +z, for Rust and for C.
fn shading_frames() -> (Vec<Frame>, Vec<ppis_frame>) {
    let normals: Vec<Vec3> = (0..SHADING_POINTS)
        .map(|k| {
            let a = k as f32 * 2.39996;
            let r = 0.9 * ((k as f32 + 0.5) / SHADING_POINTS as f32).sqrt();
            Vec3::new(r * a.cos(), r * a.sin(), (1.0 - r * r).sqrt())
        })
        .collect();
    (
        normals.iter().map(|n| Frame::from_normal(*n)).collect(),
        normals.iter().map(|n| ppis_frame_from_normal((*n).into())).collect(),
    )
}

/// The builds per shading point: the quadtree product at two K and the two-level product.
fn build_rows(c: &Objects, env: &EnvHierarchy<'_>, cones: &[Cone], arenas: (&mut ProductArena, &mut TwoLevelArena)) {
    let (arena, tl_arena) = arenas;
    let (frames, c_frames) = shading_frames();
    let (metal, wo) = (RoughConductor::new(0.1, Vec3::new(1.0, 0.78, 0.34)), view());
    for k in [64u32, 256] {
        let (params, rust_params) = (ppis_product_params_for_mis(k), ProductParams::for_mis(k as usize));
        let (mut seed, mut rust_seed) = (0u64, 0u64);
        row(
            &format!("product build (quadtree, for MIS, K = {k})"),
            side_by_side(
                SHADING_POINTS,
                // SAFETY: the objects come from their `init`s.
                || unsafe {
                    for f in &c_frames {
                        seed += 1;
                        black_box(ppis_product_build(c.product, c.env, c.brdf, f, wo.into(), &params, seed));
                    }
                },
                || {
                    for f in &frames {
                        rust_seed += 1;
                        black_box(arena.build(env, &metal, f, wo, &rust_params, rust_seed).is_ok());
                    }
                },
            ),
        );
    }
    row(
        "two-level build (16² cells)",
        side_by_side(
            SHADING_POINTS,
            // SAFETY: the objects come from their `init`s.
            || unsafe {
                for f in &c_frames {
                    black_box(ppis_two_level_build(c.two_level, c.env, c.cones, c.brdf, f, wo.into()));
                }
            },
            || {
                for f in &frames {
                    black_box(tl_arena.build(env, cones, &metal, f, wo).is_ok());
                }
            },
        ),
    );
}

/// The direction to the viewer.
fn view() -> Vec3 {
    Vec3::new(0.0, 0.2, 0.98).normalize()
}

fn main() {
    let latlong = latlong_sky();
    let mut rgb = vec![[0.0f32; 3]; 1 << (2 * LEVEL)];
    latlong_to_equal_area(&latlong, WIDTH, HEIGHT, LEVEL, 2, &mut rgb).unwrap();
    sanitize_rgb(&mut rgb);
    let mut pyramid = vec![0.0f32; pyramid_len(LEVEL)];
    build_pyramid(LEVEL, &rgb, &mut pyramid).unwrap();
    let rust_env = EnvHierarchy::new(LEVEL, &pyramid, &rgb).unwrap();
    let c = Objects::new(&pyramid, rgb.as_flattened());
    let mut rust_cones = vec![Cone::default(); cell_count(4)];
    build_cell_cones(&mut rust_cones);

    println!("| call | C ABI | Rust API | C / Rust |");
    println!("|---|---:|---:|---:|");
    environment_rows(&latlong, &rgb);
    let mut arena: Box<ProductArena> = Box::default();
    let mut tl_arena: Box<TwoLevelArena> = Box::default();
    build_rows(&c, &rust_env, &rust_cones, (&mut arena, &mut tl_arena));

    // Sampling from one built shading point, over points that sweep the square.
    let (frames, c_frames) = shading_frames();
    let (metal, wo, params) =
        (RoughConductor::new(0.1, Vec3::new(1.0, 0.78, 0.34)), view(), ppis_product_params_for_mis(64));
    // SAFETY: the objects come from their `init`s.
    unsafe {
        let ok = ppis_status::PPIS_OK;
        assert_eq!(ppis_product_build(c.product, c.env, c.brdf, &c_frames[3], wo.into(), &params, 9), ok);
        assert_eq!(ppis_two_level_build(c.two_level, c.env, c.cones, c.brdf, &c_frames[3], wo.into()), ok);
    }
    let rust_product = arena.build(&rust_env, &metal, &frames[3], wo, &ProductParams::for_mis(64), 9).unwrap();
    let rust_two_level = tl_arena.build(&rust_env, &rust_cones, &metal, &frames[3], wo).unwrap();
    let mut u = vec![DVec2::ZERO; POINTS];
    sobol02(3, 0, &mut u);
    let u_flat: Vec<f64> = u.iter().flat_map(|p| [p.x, p.y]).collect();
    let dirs: Vec<Vec3> = u.iter().map(|p| rust_env.sample(*p).unwrap().dir).collect();
    per_call_rows((c.product, c.two_level, c.env), &rust_product, &rust_two_level, &rust_env, &u, &u_flat, &dirs);
}

/// The calls of a built shading point: sample, sample_many, pdf, and the env-only sampler's.
fn per_call_rows(
    (product, two_level, env): (*mut ppis_product, *mut ppis_two_level, *mut ppis_env),
    rust_product: &ProductSampler<'_, '_>,
    rust_two_level: &TwoLevelSampler<'_, '_>,
    rust_env: &EnvHierarchy<'_>,
    u: &[DVec2],
    u_flat: &[f64],
    dirs: &[Vec3],
) {
    let mut out = vec![ppis_sample::default(); POINTS];
    let mut rust_out: Vec<Option<DirectionSample>> = vec![None; POINTS];
    // SAFETY (every closure below): the objects come from their `init`s, the lengths are the
    // buffers'.
    let each = |f: &dyn Fn(f64, f64) -> ppis_status| {
        for p in u {
            black_box(f(p.x, p.y));
        }
    };
    let mut s = ppis_sample::default();
    let sp: *mut ppis_sample = &mut s;
    row(
        "product sample",
        side_by_side(
            POINTS,
            || each(&|a, b| unsafe { ppis_product_sample(product, a, b, sp) }),
            || u.iter().for_each(|p| _ = black_box(rust_product.sample(*p))),
        ),
    );
    row(
        "product sample_many (4 096 at once), per sample",
        side_by_side(
            POINTS,
            || unsafe { _ = black_box(ppis_product_sample_many(product, u_flat.as_ptr(), POINTS, out.as_mut_ptr())) },
            || rust_product.sample_many(u, &mut rust_out),
        ),
    );
    row(
        "product pdf",
        side_by_side(
            POINTS,
            || dirs.iter().for_each(|d| _ = black_box(unsafe { ppis_product_pdf(product, (*d).into()) })),
            || dirs.iter().for_each(|d| _ = black_box(rust_product.pdf(*d))),
        ),
    );
    row(
        "two-level sample",
        side_by_side(
            POINTS,
            || each(&|a, b| unsafe { ppis_two_level_sample(two_level, a, b, sp) }),
            || u.iter().for_each(|p| _ = black_box(rust_two_level.sample(*p))),
        ),
    );
    row(
        "two-level pdf",
        side_by_side(
            POINTS,
            || dirs.iter().for_each(|d| _ = black_box(unsafe { ppis_two_level_pdf(two_level, (*d).into()) })),
            || dirs.iter().for_each(|d| _ = black_box(rust_two_level.pdf(*d))),
        ),
    );
    row(
        "env-only sample",
        side_by_side(
            POINTS,
            || each(&|a, b| unsafe { ppis_env_sample(env, a, b, sp) }),
            || u.iter().for_each(|p| _ = black_box(rust_env.sample(*p))),
        ),
    );
    row(
        "env-only pdf",
        side_by_side(
            POINTS,
            || dirs.iter().for_each(|d| _ = black_box(unsafe { ppis_env_pdf(env, (*d).into()) })),
            || dirs.iter().for_each(|d| _ = black_box(rust_env.pdf(*d))),
        ),
    );
}
