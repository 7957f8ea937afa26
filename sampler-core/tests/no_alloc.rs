//! The core never allocates: a counting global allocator sees 0 allocations over 10 000
//! shading points of build + product + warp + pdf (and the estimators).

use glam::{DVec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::estimator::lights::{FirstHit, LightRays, LightSet, light_pair};
use sampler_core::estimator::{self, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams, ProductSampler};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ARMED.with(|a| a.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ARMED.with(|a| a.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn ten_thousand_shading_points_allocate_nothing() {
    // Set-up may allocate: the map and the arena are the host's.
    let level = 8;
    let n = 1usize << level;
    let mut rgb = vec![[0.2f32, 0.3, 0.5]; n * n];
    rgb[n * 77 + 140] = [1e6; 3];
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    // With room for a bilinear B̃'s corners: every other quadtree build uses the MIS preset
    // with a bilinear B̃.
    let mut arena: Box<ProductArena<256, 2048, 2048>> = Box::new(ProductArena::new());
    let brdfs: [&dyn Brdf; 4] = [
        &Lambert::new(Vec3::splat(0.5)),
        &Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 1e4),
        &RoughConductor::new(0.01, Vec3::ONE),
        &CarPaint::default(),
    ];
    let mut rng = Pcg32::new(1, 1);
    let mut sink = 0.0f64;
    let mut sat = vec![0.0f64; sampler_core::two_stage::sat_len(level)];
    assert!(sampler_core::two_stage::build_sat(&env, &mut sat));

    let mut cones = vec![sampler_core::cone::Cone::default(); 256];
    assert!(sampler_core::cone::build_cell_cones(&mut cones));
    let mut two_level: Box<sampler_core::two_level::TwoLevelArena> = Box::default();
    let mut above = vec![0.0f32; sampler_core::env::pyramid_len(level)];
    let compensated =
        if env.compensate_into(&mut above).unwrap() { env.with_compensated(&above).unwrap() } else { env };
    ARMED.with(|a| a.set(true));
    for i in 0..10_000u64 {
        let normal = square_to_sphere(glam::Vec2::new(rng.next_f32(), rng.next_f32()));
        let frame = Frame::from_normal(normal);
        let wo = frame.to_world(Vec3::new(0.3, 0.1, 0.9).normalize());
        let brdf = brdfs[(i % 4) as usize];
        let params = match i % 4 {
            0 => ProductParams::default(),
            2 => ProductParams {
                kind: ProductKind::Quadtree { leaves: Leaves::Bilinear, refine_share: 1.0 / 256.0 },
                ..ProductParams::for_mis(256)
            },
            _ => ProductParams { kind: ProductKind::WAVELET, ..ProductParams::default() },
        };
        let sampler = arena.build(&env, brdf, &frame, wo, &params, i).unwrap();
        let mut points = [DVec2::ZERO; 4];
        sobol02(i, 0, &mut points);
        let sp = ShadingPoint { frame, wo, brdf };
        let mut vis = |d: Vec3| d.y > -0.2;
        for u in points {
            if let Some(s) = sampler.sample(u) {
                sink += s.pdf as f64 + sampler.pdf(s.dir) as f64;
            }
            sink += estimator::sampled(&sampler, &sp, u, &mut vis).value.x;
            sink += estimator::sampled(&env, &sp, u, &mut vis).value.x;
            sink += estimator::brdf(&env, &sp, u, &mut vis).value.x;
            let [a, b] = estimator::sampled_mis(&env, &sp, u, u.as_vec2(), &mut vis);
            sink += a.value.x + b.value.x;
            let [a, b] = estimator::sampled_mis(&sampler, &sp, u, u.as_vec2(), &mut vis);
            sink += a.value.x + b.value.x;
            sink += estimator::ris(&env, &sp, &points, u.x, &mut vis).value.x;
            let two: sampler_core::two_stage::TwoStageSampler<'_, '_> =
                sampler_core::two_stage::TwoStageSampler::new(&env, &sat, brdf, &frame, wo);
            sink += estimator::sampled(&two, &sp, u, &mut vis).value.x;
            let two = two_level.build(&env, &cones, brdf, &frame, wo).unwrap();
            sink += two.pdf(wo) as f64;
            sink += estimator::sampled(&two, &sp, u, &mut vis).value.x;
            let [a, b] = estimator::sampled_mis(&two, &sp, u, u.as_vec2(), &mut vis);
            sink += a.value.x + b.value.x;
            let mut many = [None; 4];
            two.sample_many(&points, &mut many);
            sink += many.iter().flatten().map(|d| f64::from(d.pdf)).sum::<f64>();
            let two = two_level.build_for_mis(&compensated, &cones, brdf, &frame, wo).unwrap();
            let [a, b] = estimator::sampled_mis(&two, &sp, u, u.as_vec2(), &mut vis);
            sink += a.value.x + b.value.x;
        }
        sink += batched(&sampler, &env, &sp, &points, &mut vis);
        sink += wavefront(&sampler, &sp, &points);
    }
    ARMED.with(|a| a.set(false));
    let count = COUNT.with(|c| c.get());
    assert!(sink.is_finite());
    assert_eq!(count, 0, "the core allocated {count} times");
}

/// Every light's sampling, density and ray query (shaped lights among them, two with an IES
/// profile, whose power is integrated inside the armed region too), picking a light by power, and the lights' estimator (a light sample and a BRDF sample under the balance heuristic), at 10 000 shading
/// points.
#[test]
fn light_sampling_allocates_nothing() {
    use sampler_core::light::*;
    let l = Vec3::new(1.0, 2.0, 3.0);
    let spot = Shaping::new(Vec3::NEG_Z, 1.0, 0.3, 2.0, Vec3::splat(0.1)).unwrap();
    static VERTICAL: [f32; 3] = [0.0, 1.0, 2.0];
    static HORIZONTAL: [f32; 3] = [0.0, std::f32::consts::FRAC_PI_2, std::f32::consts::PI];
    static CANDELA: [f32; 9] = [5.0, 3.0, 0.0, 5.0, 2.0, 1.0, 5.0, 4.0, 0.5];
    let table = Box::leak(Box::new(IntensityProfile::new(&VERTICAL, &HORIZONTAL, &CANDELA).unwrap()));
    let ies = spot.with_profile(table, Vec3::X, Vec3::Y, 0.7, true).unwrap();
    let lights: [SceneLight; 10] = [
        RectLight::new(Vec3::new(-1.0, -1.0, 2.5), Vec3::Y * 2.0, Vec3::X * 2.0, l).unwrap().with_shaping(ies).into(),
        PointLight::new(Vec3::new(0.5, 0.0, 3.0), l).unwrap().with_shaping(ies).into(),
        PointLight::new(Vec3::new(0.0, 0.0, 3.0), l).unwrap().with_shaping(spot).into(),
        SphereLight::new(Vec3::new(1.0, 0.0, 2.0), 0.5, l).unwrap().with_two_sided(true).with_shaping(spot).into(),
        RectLight::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::X * 2.0, Vec3::Y * 2.0, l)
            .unwrap()
            .with_two_sided(true)
            .into(),
        DiskLight::new(Vec3::new(0.0, 1.0, 1.0), Vec3::NEG_Z, 0.3, l).unwrap().into(),
        TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], l).unwrap().with_two_sided(true).into(),
        TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], l).unwrap().with_sampling(TriangleSampling::Area).into(),
        DistantLight::new(Vec3::new(0.2, 0.3, 1.0), l, 0.01).unwrap().into(),
        DistantLight::new(Vec3::new(0.2, 0.3, 1.0), l, 0.0).unwrap().into(),
    ];
    let mut cdf = [0.0f64; 11];
    let mut rng = Pcg32::new(2, 3);
    let mut sink = 0.0f64;
    ARMED.with(|a| a.set(true));
    let weights = lights.map(|x| x.power(10.0).x);
    let selector = PowerSelector::build(&weights, &mut cdf).unwrap();
    let infinite = [8u32];
    let set = LightSet::new(&lights, selector, &infinite).unwrap();
    let brdf = RoughConductor::new(0.2, Vec3::ONE);
    let sp = ShadingPoint { frame: Frame::from_normal(Vec3::Z), wo: Vec3::Z, brdf: &brdf };
    struct Open;
    impl LightRays for Open {
        fn unoccluded(&mut self, _: Vec3, _: f32) -> bool {
            true
        }
        fn first_hit(&mut self, _: Vec3) -> FirstHit {
            FirstHit::Escapes
        }
    }
    for _ in 0..10_000 {
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - Vec3::splat(2.0);
        let picked = selector.pick(rng.next_f64());
        sink += picked.pmf + selector.pmf(picked.index);
        for light in &lights {
            let u = glam::Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = light.sample(p, u) {
                sink += (s.pdf + light.pdf(p, s.dir)) as f64;
                sink += light.eval(p, s.dir).map_or(0.0, |h| h.distance.min(1e9) as f64);
            }
        }
        let (u, v) = (DVec2::new(rng.next_f64(), rng.next_f64()), glam::Vec2::new(rng.next_f32(), rng.next_f32()));
        sink += light_pair(&set, p, &sp, u, v, &mut Open).x;
    }
    ARMED.with(|a| a.set(false));
    let count = COUNT.with(|c| c.get());
    assert!(sink.is_finite());
    assert_eq!(count, 0, "the light samplers allocated {count} times");
}

/// The batched paths the renderer takes, at one shading point: the sum of what they return.
fn batched(
    sampler: &ProductSampler<'_, '_>,
    env: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, dyn Brdf + '_>,
    points: &[DVec2; 4],
    vis: &mut impl FnMut(Vec3) -> bool,
) -> f64 {
    let mut sink = 0.0;
    let mut pairs = [[estimator::Contribution::default(); 2]; 4];
    let brdf_points = points.map(|p| p.as_vec2());
    estimator::sampled_mis_many(sampler, sp, points, &brdf_points, vis, &mut pairs);
    sink += pairs.iter().map(|[a, b]| a.value.x + b.value.x).sum::<f64>();
    sink += estimator::sampled_mis_split(sampler, sp, &points[..3], &brdf_points[..1], (0.75, 0.25), vis).x;
    sink += estimator::sampled_mis_split(env, sp, &points[..3], &brdf_points[..1], (0.75, 0.25), vis).x;
    estimator::sampled_mis_many(env, sp, points, &brdf_points, vis, &mut pairs);
    sink += pairs.iter().map(|[a, b]| a.value.x + b.value.x).sum::<f64>();
    let mut singles = [estimator::Contribution::default(); 4];
    estimator::sampled_many(env, sp, points, vis, &mut singles);
    sink += singles.iter().map(|c| c.value.x).sum::<f64>();
    estimator::brdf_many(env, sp, &brdf_points, vis, &mut singles);
    sink += singles.iter().map(|c| c.value.x).sum::<f64>();
    let mut many = [None; 4];
    sampler.sample_many(points, &mut many);
    sink += many.iter().flatten().map(|s| s.pdf as f64).sum::<f64>();
    sink
}

/// A wavefront over one shading point, both techniques, alone and in pairs: the sum of its
/// candidates.
fn wavefront(sampler: &ProductSampler<'_, '_>, sp: &ShadingPoint<'_, dyn Brdf + '_>, points: &[DVec2; 4]) -> f64 {
    use estimator::wavefront::{Candidate, Technique, WaveSample, Weighting};
    let wave: [WaveSample; 4] = core::array::from_fn(|k| WaveSample {
        point: 0,
        technique: if k % 2 == 0 { Technique::Sampler } else { Technique::Brdf },
        u: points[k],
    });
    let mut candidates = [Candidate::default(); 4];
    let mut sink = 0.0;
    for w in [Weighting::Single, Weighting::Pairs] {
        estimator::wavefront::wavefront(sampler, core::slice::from_ref(sp), &wave, w, &mut candidates);
        sink += candidates.iter().map(|c| c.value.x).sum::<f64>();
    }
    sink
}

/// The seed's baselines: structured importance sampling's strata and a Lightcuts tree built
/// into caller buffers, and 1 000 cuts.
#[test]
fn sis_strata_and_lightcuts_allocate_nothing() {
    use sampler_core::lightcuts::{CutEntry, CutLight, CutLightKind, CutNode, LightcutTree, lightcut};
    use sampler_core::sis::{SisBuffers, Stratum, build_strata, cells_len};
    let level = 6;
    let n = 1usize << level;
    let mut rgb = vec![[0.2f32, 0.3, 0.5]; n * n];
    rgb[n * 20 + 40] = [1e4; 3];
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let m = cells_len(&env);
    let (mut dirs, mut nearest, mut labels) = (vec![Vec3::ZERO; m], vec![0.0; m], vec![0u32; m]);
    let mut intensity = vec![0.0f32; m];
    let mut strata = vec![Stratum::default(); 300];
    let mut lights = vec![CutLight { kind: CutLightKind::Point, at: Vec3::ZERO, intensity: Vec3::ZERO }; 310];
    let mut order = vec![0u32; lights.len()];
    let mut nodes = vec![CutNode::default(); LightcutTree::nodes_len(lights.len())];
    let mut heap = vec![CutEntry::default(); 1000];
    let brdf = RoughConductor::new(0.2, Vec3::ONE);
    let mut rng = Pcg32::new(4, 5);
    ARMED.with(|a| a.set(true));
    let buffers = SisBuffers {
        dirs: &mut dirs,
        intensity: &mut intensity,
        nearest: &mut nearest,
        labels: &mut labels,
        strata: &mut strata,
    };
    let count = build_strata(&env, buffers).unwrap();
    for (light, s) in lights.iter_mut().zip(&strata[..count]) {
        *light = CutLight { kind: CutLightKind::Directional, at: s.dir, intensity: s.irradiance.as_vec3() };
    }
    for (k, light) in lights.iter_mut().enumerate().skip(count) {
        *light = CutLight { kind: CutLightKind::Point, at: Vec3::new(k as f32, 1.0, 2.0), intensity: Vec3::ONE };
    }
    let tree = LightcutTree::build(&lights, &mut order, &mut nodes).unwrap();
    let mut sink = 0.0f64;
    for _ in 0..1000 {
        let normal = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 1.0).normalize();
        let sp = ShadingPoint { frame: Frame::from_normal(normal), wo: Vec3::Z, brdf: &brdf };
        sink += lightcut(&tree, Vec3::ZERO, &sp, 0.02, &mut heap, |_, _| true).estimate.x;
    }
    ARMED.with(|a| a.set(false));
    let allocations = COUNT.with(|c| c.get());
    assert!(sink.is_finite());
    assert_eq!(allocations, 0, "the baselines allocated {allocations} times");
}
