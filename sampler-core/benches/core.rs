//! `cargo bench -p sampler-core`: mapping transforms, per-shading-point product build + warps
//! (the quadtree product, and the two-level product beside it), and env-only sampling through
//! the same hierarchy as the yardstick. The numbers are in docs/perf.md#mapping-transforms,
//! docs/perf.md#building-a-product-sampler and docs/perf.md#the-two-products.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::cone::{Cone, build_cell_cones, cell_count};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::frame::Frame;
use sampler_core::mapping::{sphere_to_square, sphere_to_square_batch, square_to_sphere, square_to_sphere_batch};
use sampler_core::points::sobol02;
use sampler_core::quadtree::ProductKind;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::two_level::TwoLevelArena;
use std::hint::black_box;
use std::time::Duration;

const BATCH: usize = 1024;

fn mapping(c: &mut Criterion) {
    let mut rng = Pcg32::new(1, 2);
    let pts: Vec<Vec2> = (0..BATCH).map(|_| Vec2::new(rng.next_f32(), rng.next_f32())).collect();
    let dirs: Vec<Vec3> = pts.iter().map(|p| square_to_sphere(*p)).collect();
    let mut g = c.benchmark_group("mapping");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("square_to_sphere scalar", |b| {
        let mut out = vec![Vec3::ZERO; BATCH];
        b.iter(|| {
            for (o, p) in out.iter_mut().zip(black_box(&pts)) {
                *o = square_to_sphere(*p);
            }
            black_box(&out);
        })
    });
    g.bench_function("square_to_sphere batched x4", |b| {
        let mut out = vec![Vec3::ZERO; BATCH];
        b.iter(|| {
            square_to_sphere_batch(black_box(&pts), &mut out);
            black_box(&out);
        })
    });
    g.bench_function("sphere_to_square scalar", |b| {
        let mut out = vec![Vec2::ZERO; BATCH];
        b.iter(|| {
            for (o, d) in out.iter_mut().zip(black_box(&dirs)) {
                *o = sphere_to_square(*d);
            }
            black_box(&out);
        })
    });
    g.bench_function("sphere_to_square batched x4", |b| {
        let mut out = vec![Vec2::ZERO; BATCH];
        b.iter(|| {
            sphere_to_square_batch(black_box(&dirs), &mut out);
            black_box(&out);
        })
    });
    g.finish();
}

/// A sky with a sun of 1e5× the sky radiance, like the paper's outdoor maps.
struct Map {
    level: u32,
    rgb: Vec<[f32; 3]>,
    pyramid: Vec<f32>,
}

fn sunny_map(level: u32) -> Map {
    let n = 1usize << level;
    let mut rgb = vec![[0.0f32; 3]; n * n];
    let sun = Vec3::new(0.4, 0.5, 0.75).normalize();
    for y in 0..n {
        for x in 0..n {
            let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32));
            let sky = 0.3 + 0.7 * d.z.max(0.0);
            let s = if d.dot(sun) > 0.99998 { 1e5 } else { 0.0 };
            rgb[y * n + x] = [0.4 * sky + s, 0.6 * sky + s, sky + s];
        }
    }
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    Map { level, rgb, pyramid }
}

/// 100 shading points with different normals and views, cycled by the benchmarks.
fn shading_point_set() -> Vec<(Frame, Vec3)> {
    let mut rng = Pcg32::new(7, 7);
    (0..100)
        .map(|_| {
            let n = square_to_sphere(Vec2::new(rng.next_f32(), 0.5 * rng.next_f32() + 0.25));
            let f = Frame::from_normal(n);
            (f, f.to_world(Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 1.0).normalize()))
        })
        .collect()
}

fn shading_points(c: &mut Criterion) {
    let brdfs: Vec<(&str, Box<dyn Brdf>)> = vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.5)))),
        ("phong n=1e3", Box::new(Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 1e3))),
        ("ggx a=0.1", Box::new(RoughConductor::new(0.1, Vec3::ONE))),
        ("carpaint", Box::new(CarPaint::default())),
    ];
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let points = shading_point_set();
    for level in [10u32, 12] {
        let map = sunny_map(level);
        let env = EnvHierarchy::new(map.level, &map.pyramid, &map.rgb).unwrap();
        let res = 1 << level;
        let mut g = c.benchmark_group(format!("shading point {res}x{res}"));
        for (name, brdf) in &brdfs {
            for warps in [1usize, 4, 16] {
                for kind in [ProductKind::QUADTREE, ProductKind::WAVELET] {
                    if kind.is_wavelet() && (warps != 16 || level != 12) {
                        continue;
                    }
                    let params = ProductParams { kind, ..ProductParams::default() };
                    let id = BenchmarkId::new(format!("{name} {kind:?}"), format!("{warps} warps"));
                    let mut i = 0u64;
                    g.bench_function(id, |b| {
                        let mut pts = [DVec2::ZERO; 16];
                        b.iter(|| {
                            i += 1;
                            let (frame, wo) = &points[(i % 100) as usize];
                            let s = arena.build(&env, brdf.as_ref(), frame, *wo, &params, i).unwrap();
                            sobol02(i, 0, &mut pts[..warps]);
                            let mut acc = 0.0f32;
                            for u in &pts[..warps] {
                                if let Some(d) = s.sample(*u) {
                                    acc += d.pdf;
                                }
                            }
                            black_box(acc)
                        })
                    });
                }
            }
        }
        // The yardstick: env-only sampling through the same hierarchy, per sample.
        g.bench_function("env-only sample", |b| {
            let mut i = 0u32;
            b.iter(|| {
                i = i.wrapping_add(1);
                let mut p = [DVec2::ZERO; 1];
                sobol02(3, i, &mut p);
                black_box(env.sample(p[0]))
            })
        });
        // Build only (256 BRDF samples + tree + product), no warps.
        g.bench_function("ggx a=0.1 build only", |b| {
            let mut i = 0u64;
            b.iter(|| {
                i += 1;
                let (frame, wo) = &points[(i % 100) as usize];
                let s = arena.build(&env, brdfs[2].1.as_ref(), frame, *wo, &ProductParams::default(), i).unwrap();
                black_box(s.node_count())
            })
        });
        g.finish();
    }
    eprintln!("arena: ProductArena<256, 2048> = {} bytes", std::mem::size_of::<ProductArena>());
}

/// The BRDFs the product benchmarks build for: Lambert, GGX α 0.01 / 0.1 / 0.3, car paint.
fn product_brdfs() -> Vec<(&'static str, Box<dyn Brdf>)> {
    vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.5)))),
        ("ggx a=0.01", Box::new(RoughConductor::new(0.01, Vec3::ONE))),
        ("ggx a=0.1", Box::new(RoughConductor::new(0.1, Vec3::ONE))),
        ("ggx a=0.3", Box::new(RoughConductor::new(0.3, Vec3::ONE))),
        ("carpaint", Box::new(CarPaint::default())),
    ]
}

/// Build + 16 warps per shading point, the two-level product at 8×8, 16×16 and 32×32 cells
/// beside the quadtree product, on the same points (docs/perf.md, "The two products").
fn two_level_points(c: &mut Criterion) {
    let brdfs = product_brdfs();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut two: Box<TwoLevelArena> = Box::default();
    let cones: Vec<Vec<Cone>> = [3u32, 4, 5]
        .iter()
        .map(|&l| {
            let mut v = vec![Cone::default(); cell_count(l)];
            build_cell_cones(&mut v);
            v
        })
        .collect();
    let points = shading_point_set();
    for level in [10u32, 12] {
        let map = sunny_map(level);
        let env = EnvHierarchy::new(map.level, &map.pyramid, &map.rgb).unwrap();
        let res = 1 << level;
        let mut g = c.benchmark_group(format!("two products {res}x{res}"));
        for (name, brdf) in &brdfs {
            let mut i = 0u64;
            g.bench_function(BenchmarkId::new(*name, "quadtree"), |b| {
                let mut pts = [DVec2::ZERO; 16];
                b.iter(|| {
                    i += 1;
                    let (frame, wo) = &points[(i % 100) as usize];
                    let s = arena.build(&env, brdf.as_ref(), frame, *wo, &ProductParams::default(), i).unwrap();
                    sobol02(i, 0, &mut pts);
                    black_box(pts.iter().filter_map(|u| s.sample(*u)).map(|d| d.pdf).sum::<f32>())
                })
            });
            for cones in &cones {
                let side = 1 << (cones.len().trailing_zeros() / 2);
                g.bench_function(BenchmarkId::new(*name, format!("two-level {side}x{side}")), |b| {
                    let mut pts = [DVec2::ZERO; 16];
                    b.iter(|| {
                        i += 1;
                        let (frame, wo) = &points[(i % 100) as usize];
                        let s = two.build(&env, cones, brdf.as_ref(), frame, *wo).unwrap();
                        sobol02(i, 0, &mut pts);
                        black_box(pts.iter().filter_map(|u| s.sample(*u)).map(|d| d.pdf).sum::<f32>())
                    })
                });
            }
        }
        g.finish();
    }
}

/// Build + 16 warps of the quadtree product from fewer BRDF samples (K = 256 is "two
/// products"), 1024² map: what a K per lobe width would cost (docs/perf.md, "Building a product
/// sampler"; error at equal time against K in docs/tuning.md).
fn quadtree_k(c: &mut Criterion) {
    let brdfs = product_brdfs();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let points = shading_point_set();
    let map = sunny_map(10);
    let env = EnvHierarchy::new(map.level, &map.pyramid, &map.rgb).unwrap();
    let mut g = c.benchmark_group("quadtree K 1024x1024");
    for (name, brdf) in &brdfs {
        for k in [32usize, 64, 128] {
            let params = ProductParams { brdf_samples: k, ..ProductParams::default() };
            let mut i = 0u64;
            g.bench_function(BenchmarkId::new(*name, format!("K={k}")), |b| {
                let mut pts = [DVec2::ZERO; 16];
                b.iter(|| {
                    i += 1;
                    let (frame, wo) = &points[(i % 100) as usize];
                    let s = arena.build(&env, brdf.as_ref(), frame, *wo, &params, i).unwrap();
                    sobol02(i, 0, &mut pts);
                    black_box(pts.iter().filter_map(|u| s.sample(*u)).map(|d| d.pdf).sum::<f32>())
                })
            });
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_millis(500)).sample_size(30);
    targets = mapping, shading_points, two_level_points, quadtree_k
}
criterion_main!(benches);
