//! A C engine asks a BRDF for its properties (`ppis_brdf_lobe_width`, `_is_diffuse`,
//! `_has_cone_bounds`) instead of remembering which kind it made, and a callback BRDF supplies
//! its own, cone bounds included: with them the two-level product is the one of the built-in
//! BRDF they describe, bit for bit.

use sampler_capi::*;
use sampler_core::brdf::{Brdf, RoughConductor};
use sampler_core::cone::Cone;
use sampler_core::glam::Vec3;
use std::ffi::c_void;
use std::ptr::null_mut;

/// 8-byte aligned engine memory for one object.
fn memory(size: usize) -> Vec<u64> {
    vec![0u64; size.div_ceil(8)]
}

fn mem(v: &mut [u64]) -> *mut c_void {
    v.as_mut_ptr().cast()
}

const GREY: ppis_vec3 = ppis_vec3 { x: 0.5, y: 0.5, z: 0.5 };
const ALPHA: f32 = 0.08;

/// The conductor the callbacks below describe.
fn conductor() -> RoughConductor {
    RoughConductor::new(ALPHA, Vec3::from(GREY))
}

unsafe extern "C" fn eval(_: *mut c_void, wo: ppis_vec3, wi: ppis_vec3) -> ppis_vec3 {
    conductor().eval(wo.into(), wi.into()).into()
}

unsafe extern "C" fn sample(
    _: *mut c_void,
    wo: ppis_vec3,
    u: ppis_vec2,
    wi: *mut ppis_vec3,
    value: *mut ppis_vec3,
    pdf: *mut f32,
) -> i32 {
    let Some(s) = conductor().sample(wo.into(), u.into()) else { return 0 };
    unsafe { (*wi, *value, *pdf) = (s.wi.into(), s.value.into(), s.pdf) };
    1
}

unsafe extern "C" fn pdf(_: *mut c_void, wo: ppis_vec3, wi: ppis_vec3) -> f32 {
    conductor().pdf(wo.into(), wi.into())
}

/// Counts its calls through `user` (a `usize`), so the test sees the bounds were asked for.
unsafe extern "C" fn cone_bounds(user: *mut c_void, wo: ppis_vec3, cones: *const ppis_cone, n: usize, out: *mut f32) {
    let (cones, out) = unsafe { (std::slice::from_raw_parts(cones, n), std::slice::from_raw_parts_mut(out, n)) };
    let cones: Vec<Cone> =
        cones.iter().map(|c| Cone { axis: Vec3::from(c.axis), angle: c.angle, cos: c.cos, sin: c.sin }).collect();
    conductor().cone_bounds(wo.into(), &cones, out);
    unsafe { *user.cast::<usize>() += 1 };
}

fn callbacks(user: *mut usize, bounds: bool) -> ppis_brdf_callbacks {
    ppis_brdf_callbacks {
        user: user.cast(),
        eval: Some(eval),
        sample: Some(sample),
        pdf: Some(pdf),
        is_diffuse: 0,
        lobe_width: ALPHA,
        cone_bounds: if bounds { Some(cone_bounds) } else { None },
    }
}

#[test]
fn the_built_in_brdfs_answer_what_the_rust_trait_answers() {
    unsafe {
        let mut m = memory(ppis_brdf_size());
        let mut b = null_mut();
        assert_eq!(ppis_brdf_init_lambert(mem(&mut m), ppis_brdf_size(), GREY, &mut b), ppis_status::PPIS_OK);
        assert_eq!(ppis_brdf_lobe_width(b), std::f32::consts::FRAC_PI_2);
        assert_eq!((ppis_brdf_is_diffuse(b), ppis_brdf_has_cone_bounds(b)), (1, 1));
        assert_eq!(ppis_brdf_init_conductor(mem(&mut m), ppis_brdf_size(), ALPHA, GREY, &mut b), ppis_status::PPIS_OK);
        assert_eq!(ppis_brdf_lobe_width(b), conductor().lobe_width());
        assert_eq!((ppis_brdf_is_diffuse(b), ppis_brdf_has_cone_bounds(b)), (0, 1));
        let s = ppis_brdf_init_carpaint(mem(&mut m), ppis_brdf_size(), GREY, GREY, 0.3, 1.0, 0.01, &mut b);
        assert_eq!(s, ppis_status::PPIS_OK);
        assert_eq!(ppis_brdf_lobe_width(b), 0.01, "the coat");
        let s = ppis_brdf_init_phong(mem(&mut m), ppis_brdf_size(), GREY, GREY, 198.0, &mut b);
        assert_eq!(s, ppis_status::PPIS_OK);
        assert!((ppis_brdf_lobe_width(b) - 0.1).abs() < 1e-6);
        let null = std::ptr::null();
        assert_eq!(
            (ppis_brdf_lobe_width(null), ppis_brdf_is_diffuse(null), ppis_brdf_has_cone_bounds(null)),
            (0.0, 0, 0)
        );
    }
}

#[test]
fn a_callback_brdf_says_what_it_is_and_a_bad_width_is_refused() {
    let mut calls = 0usize;
    unsafe {
        let mut m = memory(ppis_brdf_size());
        let mut b = null_mut();
        for (width, bounds) in [(ALPHA, false), (ALPHA, true)] {
            let mut c = callbacks(&mut calls, bounds);
            c.lobe_width = width;
            assert_eq!(ppis_brdf_init_callbacks(mem(&mut m), ppis_brdf_size(), &c, &mut b), ppis_status::PPIS_OK);
            assert_eq!(ppis_brdf_lobe_width(b), ALPHA);
            assert_eq!((ppis_brdf_is_diffuse(b), ppis_brdf_has_cone_bounds(b)), (0, i32::from(bounds)));
        }
        for width in [f32::NAN, -0.1, f32::INFINITY] {
            let mut c = callbacks(&mut calls, true);
            c.lobe_width = width;
            let s = ppis_brdf_init_callbacks(mem(&mut m), ppis_brdf_size(), &c, &mut b);
            assert_eq!(s, ppis_status::PPIS_BAD_VALUE, "lobe width {width}");
        }
    }
}

/// The two-level sampler's first draws and pdfs over a 32 × 32 map, at coarse level 5 (more
/// cells than one call of the bounds callback takes).
fn two_level_draws(brdf: *const ppis_brdf) -> Vec<(ppis_sample, f32)> {
    let level = 5;
    let mut rgb: Vec<f32> = (0..3 << (2 * level)).map(|k| 0.2 + (k % 11) as f32 * 0.03).collect();
    rgb[3 * 300..3 * 301].copy_from_slice(&[900.0, 800.0, 700.0]);
    let mut pyramid = vec![0.0f32; ppis_pyramid_len(level)];
    let (mut env_mem, mut cones_mem, mut tl_mem) =
        (memory(ppis_env_size()), memory(ppis_cones_size(level)), memory(ppis_two_level_size()));
    let (mut env, mut cones, mut tl) = (null_mut(), null_mut(), null_mut());
    unsafe {
        let ok = ppis_status::PPIS_OK;
        assert_eq!(ppis_build_pyramid(level, rgb.as_ptr(), rgb.len(), pyramid.as_mut_ptr(), pyramid.len()), ok);
        let (p, r) = (pyramid.as_ptr(), rgb.as_ptr());
        assert_eq!(
            ppis_env_init(mem(&mut env_mem), ppis_env_size(), level, p, pyramid.len(), r, rgb.len(), &mut env),
            ok
        );
        assert_eq!(ppis_cones_init(mem(&mut cones_mem), ppis_cones_size(level), level, &mut cones), ok);
        assert_eq!(ppis_two_level_init(mem(&mut tl_mem), ppis_two_level_size(), &mut tl), ok);
        let frame = ppis_frame_from_normal(ppis_vec3 { x: 0.3, y: 0.1, z: 0.95 });
        let wo = ppis_vec3 { x: 0.0, y: 0.6, z: 0.8 };
        assert_eq!(ppis_two_level_build(tl, env, cones, brdf, &frame, wo), ok);
        (0..16)
            .map(|k| {
                let mut s = ppis_sample::default();
                ppis_two_level_sample(tl, (k as f64 + 0.5) / 16.0, (k * 7 % 16) as f64 / 16.0, &mut s);
                (s, ppis_two_level_pdf(tl, s.dir))
            })
            .collect()
    }
}

#[test]
fn a_callback_brdf_with_cone_bounds_builds_the_built_in_two_level_product() {
    let mut calls = 0usize;
    let (mut a, mut b, mut c) = (memory(ppis_brdf_size()), memory(ppis_brdf_size()), memory(ppis_brdf_size()));
    let (mut built_in, mut bounded, mut estimated) = (null_mut(), null_mut(), null_mut());
    unsafe {
        let ok = ppis_status::PPIS_OK;
        assert_eq!(ppis_brdf_init_conductor(mem(&mut a), ppis_brdf_size(), ALPHA, GREY, &mut built_in), ok);
        let with = callbacks(&mut calls, true);
        assert_eq!(ppis_brdf_init_callbacks(mem(&mut b), ppis_brdf_size(), &with, &mut bounded), ok);
        let without = callbacks(&mut calls, false);
        assert_eq!(ppis_brdf_init_callbacks(mem(&mut c), ppis_brdf_size(), &without, &mut estimated), ok);
    }
    let expected = two_level_draws(built_in);
    assert_eq!(two_level_draws(bounded), expected, "the callback's bounds are the built-in's");
    assert_eq!(calls, 1024 / 64, "1 024 cells, 64 per call");
    assert_ne!(two_level_draws(estimated), expected, "without bounds the cells are weighed by evaluation");
}
