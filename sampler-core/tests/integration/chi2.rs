//! χ² goodness-of-fit of every sampler against its own pdf: 100 000 draws per case, over
//! random and sunny environments, every built-in BRDF, near-normal and grazing views.
//! Also checks that the pdf returned with a sample equals `pdf(ω)`.

use crate::common::*;
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::frame::Frame;
use sampler_core::mapping::SPHERE_AREA;
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::sampler::{ProductArena, ProductParams, ProductSampler};

const SAMPLES: usize = 100_000;

/// The built-in BRDFs, each with the angular width of its sharpest lobe (None: wide).
fn brdfs() -> Vec<(&'static str, Box<dyn Brdf>, Option<f64>)> {
    vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.8))), None),
        ("phong n=10", Box::new(Phong::new(Vec3::splat(0.2), Vec3::splat(0.6), 10.0)), None),
        ("phong n=1e3", Box::new(Phong::new(Vec3::ZERO, Vec3::splat(0.9), 1e3)), Some(2.0 / 1e3f64.sqrt())),
        ("phong n=1e5", Box::new(Phong::new(Vec3::splat(0.1), Vec3::splat(0.9), 1e5)), Some(2.0 / 1e5f64.sqrt())),
        ("ggx a=1", Box::new(RoughConductor::new(1.0, Vec3::ONE)), None),
        ("ggx a=0.3", Box::new(RoughConductor::new(0.3, Vec3::ONE)), None),
        ("ggx a=0.05", Box::new(RoughConductor::new(0.05, Vec3::ONE)), Some(0.1)),
        ("ggx a=1e-3", Box::new(RoughConductor::new(1e-3, Vec3::ONE)), Some(2e-3)),
        ("carpaint", Box::new(CarPaint::default()), Some(0.01)),
    ]
}

/// (label, world normal, local view direction)
fn views() -> Vec<(&'static str, Vec3, Vec3)> {
    let tilt = |c: f32| Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
    vec![
        ("normal +z, 20°", Vec3::Z, tilt(20f32.to_radians().cos())),
        ("normal -x, grazing", Vec3::NEG_X, tilt(0.05)),
        ("normal oblique, 60°", Vec3::new(0.3, -0.5, 0.8).normalize(), tilt(0.5)),
    ]
}

#[test]
fn brdf_samplers_match_their_pdf() {
    let cases = brdfs().len() * views().len();
    let alpha = sidak(cases);
    let mut failures = Vec::new();
    for (name, brdf, width) in brdfs() {
        for (view, _, wo) in views() {
            let axis = Vec3::new(-wo.x, -wo.y, wo.z);
            let chart = match width {
                Some(w) => Chart::Polar { axis, scale: w },
                None => Chart::Polar { axis: Vec3::Z, scale: 1.0 },
            };
            let r = chi_square(
                chart,
                40,
                24,
                SAMPLES,
                7,
                |u| brdf.sample(wo, u.as_vec2()).map(|s| (s.wi, s.pdf)),
                |wi| brdf.pdf(wo, wi),
            );
            if r.p_value < alpha || r.impossible > 0 || r.pdf_mismatch > 1e-3 {
                failures.push(format!("{name} / {view}: {r:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "α = {alpha:.2e}\n{}", failures.join("\n"));
}

#[test]
fn env_sampler_matches_its_pdf() {
    let envs = [
        ("smooth", TestEnv::random_smooth(6, 1)),
        ("sun 1e6", TestEnv::sun(7, (37, 101), 1e6)),
        ("sun on the pole", TestEnv::sun(7, (64, 64), 1e7)),
        ("sun in a corner", TestEnv::sun(7, (0, 127), 1e7)),
        ("1x1", TestEnv::constant(0, 2.0)),
        ("2x2", TestEnv::new(1, vec![[1.0; 3], [0.0; 3], [5.0; 3], [0.5; 3]])),
    ];
    let alpha = sidak(3 * envs.len());
    let views = envs.iter().flat_map(|(name, env)| {
        [
            (name.to_string(), env.view()),
            (format!("{name}, table"), env.table_view()),
            (format!("{name}, compensated"), env.compensated_view()),
        ]
    });
    for (name, e) in views {
        let r = chi_square_dyadic(
            SAMPLES,
            3,
            40.0,
            |u| e.sample(u).map(|s| s.uv),
            |_| e.finest_level(),
            |uv| e.pdf_square(uv),
        );
        assert!(r.p_value >= alpha && r.impossible == 0, "{name}: {r:?}");
        // The batched, branch-free descent: same distribution, same pdf.
        let r = chi_square_dyadic(
            SAMPLES,
            3,
            40.0,
            |u| {
                let mut out = [None];
                e.sample_many(&[u], &mut out);
                out[0].map(|s: sampler_core::direction::DirectionSample| {
                    assert_eq!(s.pdf, e.pdf_square(s.uv) / sampler_core::mapping::SPHERE_AREA);
                    s.uv
                })
            },
            |_| e.finest_level(),
            |uv| e.pdf_square(uv),
        );
        assert!(r.p_value >= alpha && r.impossible == 0, "{name}, sample_many: {r:?}");
        // The direction-level pdf agrees with the one returned.
        let mut mismatch = 0;
        let mut rng = sampler_core::rng::Pcg32::new(5, 5);
        for _ in 0..10_000 {
            let s = e.sample(DVec2::new(rng.next_f64(), rng.next_f64())).unwrap();
            mismatch += usize::from((e.pdf(s.dir) - s.pdf).abs() > 1e-4 * s.pdf);
        }
        assert!(mismatch <= 10, "{name}: {mismatch} of 10000 pdfs differ");
    }
}

fn product_cases(params: ProductParams) -> Vec<String> {
    let envs = [("smooth", TestEnv::random_smooth(6, 2)), ("sun 1e6", TestEnv::sun(7, (90, 40), 1e6))];
    // With room for a bilinear B̃'s corners.
    let mut arena: Box<ProductArena<256, 2048, 2048>> = Box::new(ProductArena::new());
    let cases = envs.len() * brdfs().len() * views().len();
    let alpha = sidak(cases);
    let mut failures = Vec::new();
    for (env_name, env) in &envs {
        let e = env.view();
        for (name, brdf, _) in brdfs() {
            for (seed, (view, normal, wo_local)) in views().into_iter().enumerate() {
                let frame = Frame::from_normal(normal);
                let wo = frame.to_world(wo_local);
                let sampler = arena.build(&e, brdf.as_ref(), &frame, wo, &params, seed as u64).unwrap();
                let bilinear = params.kind.leaves() == Leaves::Bilinear;
                assert_eq!(sampler.is_bilinear(), bilinear && sampler.node_count() > 0);
                let r = chi_square_dyadic(
                    SAMPLES,
                    11 + seed as u64,
                    40.0,
                    |u| sampler.sample(u).map(|s| s.uv),
                    |uv| sampler.constant_depth_at(uv),
                    |uv| sampler.pdf_square(uv),
                );
                // The pdf returned with each sample equals pdf(ω) (up to the rare direction
                // whose round trip through the mapping crosses a texel edge).
                let mut mismatch = 0;
                let tolerance = if bilinear { 1e-2 } else { 1e-4 };
                let mut rng = sampler_core::rng::Pcg32::new(9, seed as u64);
                for _ in 0..10_000 {
                    let s = sampler.sample(DVec2::new(rng.next_f64(), rng.next_f64())).unwrap();
                    assert!(s.dir.is_finite() && s.pdf.is_finite() && s.pdf > 0.0);
                    // At the sample's own point exactly; through its direction up to the round
                    // trip's ~1e-7 shift, which a piecewise-constant density turns into a jump
                    // only at cell edges, a bilinear one also into a small change inside a
                    // cell where it is steep (needle lobes: up to 0.2%).
                    assert_eq!(sampler.pdf_square(s.uv) / SPHERE_AREA, s.pdf);
                    mismatch += usize::from((sampler.pdf(s.dir) - s.pdf).abs() > tolerance * s.pdf);
                }
                let moved = batched_matches_single(&sampler, seed as u64);
                if r.p_value < alpha || r.impossible > 0 || mismatch > 10 || moved > 4 {
                    failures.push(format!(
                        "{env_name} / {name} / {view}: nodes {}, {r:?}, pdf mismatches {mismatch}/10000, batched samples in another cell {moved}/4099",
                        sampler.node_count()
                    ));
                }
            }
        }
    }
    failures
}

/// `sample_many` draws what `sample` draws (the same cell; the point inside may differ in the
/// last bits, rarely across a cell edge — returns how often) with the density `pdf_square`
/// gives at its point, and `pdf_square_many` is `pdf_square` bit for bit.
fn batched_matches_single(sampler: &ProductSampler<'_, '_>, seed: u64) -> usize {
    let mut u = vec![DVec2::ZERO; 4099];
    sampler_core::points::sobol02(seed ^ 0x5a, 0, &mut u);
    u[3] = DVec2::new(1.0, 0.0); // clamped like `sample` clamps
    let mut many = vec![None; u.len()];
    sampler.sample_many(&u, &mut many);
    let mut moved = 0;
    for (u, b) in u.iter().zip(&many) {
        let (a, b) = (sampler.sample(*u).unwrap(), b.unwrap());
        assert!((a.uv - b.uv).abs().max_element() < 1e-5, "{a:?} {b:?}");
        assert_eq!(b.pdf, sampler.pdf_square(b.uv) / SPHERE_AREA);
        moved += usize::from(a.pdf != b.pdf);
    }
    let uvs: Vec<Vec2> = many.iter().map(|s| s.unwrap().uv).chain(u.iter().map(|p| p.as_vec2())).collect();
    let mut pdfs = vec![0.0f32; uvs.len()];
    sampler.pdf_square_many(&uvs, &mut pdfs);
    for (uv, p) in uvs.iter().zip(&pdfs) {
        assert_eq!(*p, sampler.pdf_square(*uv), "{uv}");
    }
    moved
}

#[test]
fn quadtree_product_sampler_matches_its_pdf() {
    let f = product_cases(ProductParams::default());
    assert!(f.is_empty(), "{}", f.join("\n"));
}

#[test]
fn quadtree_product_sampler_with_probed_leaves_matches_its_pdf() {
    let f = product_cases(ProductParams { kind: probed(), ..ProductParams::default() });
    assert!(f.is_empty(), "{}", f.join("\n"));
}

/// Refined heavy leaves (`ProductParams::for_mis`, the host's product-MIS settings): the new leaves below the samples'
/// tree, some deeper than the map's finest level, are sampled as their pdf says.
#[test]
fn quadtree_product_sampler_with_refined_leaves_matches_its_pdf() {
    let f = product_cases(ProductParams::for_mis(256));
    assert!(f.is_empty(), "{}", f.join("\n"));
}

/// The renderer's K per lobe (host-std `render::brdf_samples`: 16 diffuse, 64 one glossy lobe,
/// 128 layered): trees from 16 samples, and product-MIS's refinement at 1/K of the mass from
/// 64, are sampled as their pdf says on every BRDF.
#[test]
fn quadtree_product_sampler_from_the_renderers_smaller_k_matches_its_pdf() {
    for params in [ProductParams { brdf_samples: 16, ..ProductParams::default() }, ProductParams::for_mis(64)] {
        let f = product_cases(params);
        assert!(f.is_empty(), "K = {}: {}", params.brdf_samples, f.join("\n"));
    }
}

/// Bilinear B̃: the density varies inside texels and leaves (linearly along each axis, so a
/// dyadic cell's mass is still its centre's density times its area).
#[test]
fn quadtree_product_sampler_with_bilinear_leaves_matches_its_pdf() {
    let f = product_cases(ProductParams { kind: bilinear(), ..ProductParams::default() });
    assert!(f.is_empty(), "{}", f.join("\n"));
}

/// A bilinear B̃ needs an arena with room for corners; the default arena builds the
/// piecewise-constant B̃ instead (nobody pays for corners they do not use), and its sampler says
/// so.
#[test]
fn bilinear_needs_an_arena_with_corners_and_the_sampler_says_what_was_built() {
    let env = TestEnv::random_smooth(5, 4);
    let e = env.view();
    let brdf = Lambert::new(Vec3::splat(0.5));
    let frame = Frame::from_normal(Vec3::Z);
    let wo = Vec3::new(0.0, 0.6, 0.8);
    let params = ProductParams { kind: bilinear(), ..ProductParams::default() };
    let mut plain: Box<ProductArena> = Box::new(ProductArena::new());
    let built = plain.build(&e, &brdf, &frame, wo, &params, 1).unwrap();
    assert!(!built.is_bilinear());
    assert_eq!(built.kind(), ProductKind::QUADTREE);
    let mut with_corners: Box<ProductArena<256, 2048, 2048>> = Box::new(ProductArena::new());
    let built = with_corners.build(&e, &brdf, &frame, wo, &params, 1).unwrap();
    assert!(built.is_bilinear());
    assert_eq!(built.kind(), bilinear());
}

#[test]
fn wavelet_product_sampler_matches_its_pdf() {
    let f = product_cases(ProductParams { kind: ProductKind::WAVELET, ..ProductParams::default() });
    assert!(f.is_empty(), "{}", f.join("\n"));
}

/// A black-box check of the product sampler on directions (not square points): binned on a
/// grid of the sphere with expected counts from `pdf(ω)`.
#[test]
fn product_sampler_directions_match_pdf_on_a_sphere_grid() {
    let env = TestEnv::random_smooth(5, 4);
    let e = env.view();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let brdf = Lambert::new(Vec3::splat(0.5));
    let frame = Frame::from_normal(Vec3::new(0.2, 0.9, 0.1).normalize());
    let wo = frame.to_world(Vec3::new(0.0, 0.6, 0.8));
    let sampler = arena.build(&e, &brdf, &frame, wo, &ProductParams::default(), 1).unwrap();
    let r = chi_square(
        Chart::EqualArea,
        32,
        16,
        SAMPLES,
        21,
        |u| sampler.sample(u).map(|s| (s.dir, s.pdf)),
        |d| sampler.pdf(d),
    );
    assert!(r.p_value > 0.01 && r.impossible == 0 && r.pdf_mismatch < 1e-3, "{r:?}");
}

/// The quadtree with B probed at its leaves' centres, not refined.
fn probed() -> ProductKind {
    ProductKind::Quadtree { leaves: Leaves::Probed, refine_share: 0.0 }
}

/// The quadtree with bilinear leaves, not refined.
fn bilinear() -> ProductKind {
    ProductKind::Quadtree { leaves: Leaves::Bilinear, refine_share: 0.0 }
}
