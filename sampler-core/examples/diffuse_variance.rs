//! Product-MIS against MIS on a Lambert surface under a sky with a sun (elevation `EL`, default
//! 0.1 as sin of the angle): relative variance per sample and over a 64-point (0,2)-net, 400
//! builds. Shows why the product loses on diffuse surfaces in renders although it wins per
//! sample: MIS's integrand is smooth and the nets integrate it well, the product's B/B̃ jumps at
//! every leaf edge. `EL=0.5 cargo run --release -p sampler-core --example diffuse_variance`
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::Lambert;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::estimator::{self, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::sampler::{ProductArena, ProductParams};
fn main() {
    let level = 9;
    let m = 1usize << level;
    let sun_el: f32 = std::env::var("EL").ok().and_then(|v| v.parse().ok()).unwrap_or(0.1);
    let sun = Vec3::new((1.0 - sun_el * sun_el).sqrt(), 0.0, sun_el);
    let mut rgb = vec![[0.0f32; 3]; m * m];
    for y in 0..m {
        for x in 0..m {
            let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / m as f32, (y as f32 + 0.5) / m as f32));
            let sky = 0.2 + d.z.max(0.0);
            let s = if d.dot(sun) > 0.9995 { 2e3 } else { 0.0 };
            rgb[y * m + x] = [sky + s; 3];
        }
    }
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let mut arena: Box<ProductArena<256, 2048, 2048>> = Box::new(ProductArena::new());
    let brdf = Lambert::new(Vec3::splat(0.5));
    let frame = Frame::from_normal(Vec3::Z);
    let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
    let sp = ShadingPoint { frame, wo, brdf: &brdf };
    let mut vis = |_: Vec3| true;
    let lum = |v: glam::DVec3| v.y;
    let (n, reps) = (64, 400);
    for (name, params) in [
        ("for_mis", ProductParams::for_mis(256)),
        ("for_mis noprobe", for_mis_with(Leaves::Sampled, 1.0 / 256.0)),
        ("for_mis norefine", for_mis_with(Leaves::Probed, 0.0)),
        ("for_mis bilinear", for_mis_with(Leaves::Bilinear, 1.0 / 256.0)),
    ] {
        report(name, reps, n, |r, a, b, out| {
            let s = arena.build(&env, &brdf, &frame, wo, &params, r).unwrap();
            for k in 0..a.len() {
                let [x, y] = estimator::sampled_mis(&s, &sp, a[k], b[k].as_vec2(), &mut vis);
                out.push(lum(x.value + y.value));
            }
        });
    }
    report("mis", reps, n, |_, a, b, out| {
        for k in 0..a.len() {
            let [x, y] = estimator::sampled_mis(&env, &sp, a[k], b[k].as_vec2(), &mut vis);
            out.push(lum(x.value + y.value));
        }
    });
}

/// Relative variance per sample and per `n`-point net over `reps` nets; `estimate(r, a, b, out)`
/// pushes net r's values for its two point sets.
fn report(name: &str, reps: u64, n: usize, mut estimate: impl FnMut(u64, &[DVec2], &[DVec2], &mut Vec<f64>)) {
    let (mut s1, mut s2, mut t1, mut t2) = (0.0, 0.0, 0.0, 0.0);
    let mut values = Vec::with_capacity(n);
    for r in 0..reps {
        let (mut a, mut b) = (vec![DVec2::ZERO; n], vec![DVec2::ZERO; n]);
        sobol02(r ^ 77, 0, &mut a);
        sobol02(r ^ 99, 0, &mut b);
        values.clear();
        estimate(r, &a, &b, &mut values);
        let mut net = 0.0;
        for &v in &values {
            s1 += v;
            s2 += v * v;
            net += v;
        }
        net /= n as f64;
        t1 += net;
        t2 += net * net;
    }
    let c = (reps * n as u64) as f64;
    let mean = s1 / c;
    let mn = t1 / reps as f64;
    println!(
        "{name}: mean {mean:.5} relvar/sample {:.4} relvar/net {:.3e}",
        (s2 / c - mean * mean) / (mean * mean),
        (t2 / reps as f64 - mn * mn) / (mn * mn)
    );
}

/// `ProductParams::for_mis(256)` with other leaves or refinement.
fn for_mis_with(leaves: Leaves, refine_share: f32) -> ProductParams {
    ProductParams { kind: ProductKind::Quadtree { leaves, refine_share }, ..ProductParams::for_mis(256) }
}
