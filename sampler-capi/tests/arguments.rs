//! Bad arguments through the C ABI are error codes, never a crash or a silent clamp, and the
//! calls of a shading point allocate nothing (a counting allocator).

use sampler_capi::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::ffi::c_void;
use std::ptr::{null, null_mut};

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
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Engine-owned memory for an object, 64-byte aligned.
fn memory(size: usize) -> Vec<u64> {
    vec![0u64; size.div_ceil(8) + 8]
}

fn aligned(v: &mut [u64]) -> *mut c_void {
    let p = v.as_mut_ptr() as usize;
    (p.next_multiple_of(64)) as *mut c_void
}

/// A 16 × 16 map with a bright texel, its pyramid and an environment over both.
struct Map {
    _rgb: Vec<f32>,
    _pyramid: Vec<f32>,
    _mem: Vec<u64>,
    env: *mut ppis_env,
}

fn map() -> Map {
    let level = 4;
    let mut rgb: Vec<f32> = (0..256 * 3).map(|k| 0.1 + (k % 7) as f32 * 0.05).collect();
    rgb[3 * 77..3 * 78].copy_from_slice(&[500.0, 400.0, 300.0]);
    let mut pyramid = vec![0.0f32; ppis_pyramid_len(level)];
    unsafe {
        assert_eq!(
            ppis_build_pyramid(level, rgb.as_ptr(), rgb.len(), pyramid.as_mut_ptr(), pyramid.len()),
            ppis_status::PPIS_OK
        );
        let mut mem = memory(ppis_env_size());
        let mut env = null_mut();
        let s = ppis_env_init(
            aligned(&mut mem),
            ppis_env_size(),
            level,
            pyramid.as_ptr(),
            pyramid.len(),
            rgb.as_ptr(),
            rgb.len(),
            &mut env,
        );
        assert_eq!(s, ppis_status::PPIS_OK);
        Map { _rgb: rgb, _pyramid: pyramid, _mem: mem, env }
    }
}

#[test]
fn bad_arguments_are_error_codes() {
    use ppis_status::*;
    let m = map();
    unsafe {
        let mut mem = memory(ppis_brdf_size());
        let mut brdf = null_mut();
        let grey = ppis_vec3 { x: 0.5, y: 0.5, z: 0.5 };
        assert_eq!(ppis_brdf_init_conductor(null_mut(), 1024, 0.1, grey, &mut brdf), PPIS_NULL_POINTER);
        assert_eq!(ppis_brdf_init_conductor(aligned(&mut mem), 1, 0.1, grey, &mut brdf), PPIS_BAD_SIZE);
        let odd = (aligned(&mut mem) as *mut u8).add(1).cast();
        assert_eq!(ppis_brdf_init_conductor(odd, ppis_brdf_size(), 0.1, grey, &mut brdf), PPIS_BAD_ALIGNMENT);
        assert_eq!(
            ppis_brdf_init_conductor(aligned(&mut mem), ppis_brdf_size(), f32::NAN, grey, &mut brdf),
            PPIS_BAD_VALUE
        );
        let callbacks = ppis_brdf_callbacks {
            user: null_mut(),
            eval: None,
            sample: None,
            pdf: None,
            is_diffuse: 0,
            lobe_width: 0.1,
            cone_bounds: None,
        };
        assert_eq!(
            ppis_brdf_init_callbacks(aligned(&mut mem), ppis_brdf_size(), &callbacks, &mut brdf),
            PPIS_BAD_VALUE
        );
        assert_eq!(ppis_brdf_init_conductor(aligned(&mut mem), ppis_brdf_size(), 0.1, grey, &mut brdf), PPIS_OK);

        let mut pmem = memory(ppis_product_size());
        let mut product = null_mut();
        assert_eq!(ppis_product_init(aligned(&mut pmem), ppis_product_size(), &mut product), PPIS_OK);
        let mut s = ppis_sample::default();
        assert_eq!(ppis_product_sample(product, 0.5, 0.5, &mut s), PPIS_NOT_BUILT);
        assert_eq!(ppis_product_pdf(product, grey), 0.0);
        let frame = ppis_frame_from_normal(ppis_vec3 { x: 0.0, y: 0.0, z: 1.0 });
        let wo = ppis_vec3 { x: 0.0, y: 0.6, z: 0.8 };
        let mut params = ppis_product_params_default();
        params.brdf_samples = PPIS_PRODUCT_CAPACITY + 1;
        assert_eq!(ppis_product_build(product, m.env, brdf, &frame, wo, &params, 1), PPIS_ABOVE_CAPACITY);
        params.brdf_samples = 64;
        params.defensive = 2.0;
        assert_eq!(ppis_product_build(product, m.env, brdf, &frame, wo, &params, 1), PPIS_BAD_VALUE);
        // The wavelet product is never refined: asking for both is an error, not a silent drop.
        let mut refined_wavelet = ppis_product_params_for_mis(64);
        refined_wavelet.kind = 1;
        assert_eq!(ppis_product_build(product, m.env, brdf, &frame, wo, &refined_wavelet, 1), PPIS_BAD_VALUE);
        assert_eq!(ppis_product_build(product, null(), brdf, &frame, wo, null(), 1), PPIS_NULL_POINTER);
        assert_eq!(ppis_product_build(product, m.env, brdf, &frame, wo, null(), 1), PPIS_OK);
        assert_eq!(ppis_product_sample(product, 0.5, 0.5, &mut s), PPIS_OK);
        assert!(s.pdf > 0.0);
        // Below the surface nothing is drawn, and the sample says so.
        let below = ppis_vec3 { x: 0.0, y: 0.6, z: -0.8 };
        let mut tl_mem = memory(ppis_two_level_size());
        let mut tl = null_mut();
        assert_eq!(ppis_two_level_init(aligned(&mut tl_mem), ppis_two_level_size(), &mut tl), PPIS_OK);
        let mut cones_mem = memory(ppis_cones_size(5));
        let mut cones = null_mut();
        assert_eq!(ppis_cones_size(6), 0);
        assert_eq!(ppis_cones_init(aligned(&mut cones_mem), ppis_cones_size(5), 6, &mut cones), PPIS_BAD_LEVEL);
        assert_eq!(ppis_cones_init(aligned(&mut cones_mem), ppis_cones_size(4), 5, &mut cones), PPIS_BAD_SIZE);
        assert_eq!(ppis_cones_init(aligned(&mut cones_mem), ppis_cones_size(5), 5, &mut cones), PPIS_OK);
        // A coarse level finer than the 16 × 16 map.
        assert_eq!(ppis_two_level_build(tl, m.env, cones, brdf, &frame, wo), PPIS_BAD_LEVEL);
        assert_eq!(ppis_cones_init(aligned(&mut cones_mem), ppis_cones_size(3), 3, &mut cones), PPIS_OK);
        assert_eq!(ppis_two_level_build(tl, m.env, cones, brdf, &frame, below), PPIS_OK);
        assert_eq!(ppis_two_level_sample(tl, 0.5, 0.5, &mut s), PPIS_NOTHING_TO_SAMPLE);
        assert_eq!(s.pdf, 0.0);
        // Sizes that do not fit.
        let rgb = [1.0f32; 12];
        let mut out = [0.0f32; 9];
        assert_eq!(ppis_latlong_to_equal_area(rgb.as_ptr(), 2, 2, 1, 1, out.as_mut_ptr(), out.len()), PPIS_BAD_SIZE);
        assert_eq!(ppis_build_pyramid(15, rgb.as_ptr(), 12, out.as_mut_ptr(), 9), PPIS_BAD_LEVEL);
        let rotation = [2.0f32, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert_eq!(ppis_env_set_rotation(m.env, rotation.as_ptr()), PPIS_BAD_VALUE);
    }
}

#[test]
fn a_thousand_shading_points_allocate_nothing() {
    let m = map();
    unsafe {
        let mut bmem = memory(ppis_brdf_size());
        let mut brdf = null_mut();
        let paint = ppis_vec3 { x: 0.1, y: 0.2, z: 0.5 };
        let s = ppis_brdf_init_carpaint(aligned(&mut bmem), ppis_brdf_size(), paint, paint, 0.2, 1.0, 0.01, &mut brdf);
        assert_eq!(s, ppis_status::PPIS_OK);
        let (mut pmem, mut tmem, mut cmem) =
            (memory(ppis_product_size()), memory(ppis_two_level_size()), memory(ppis_cones_size(3)));
        let (mut product, mut tl, mut cones) = (null_mut(), null_mut(), null_mut());
        assert_eq!(ppis_product_init(aligned(&mut pmem), ppis_product_size(), &mut product), ppis_status::PPIS_OK);
        assert_eq!(ppis_two_level_init(aligned(&mut tmem), ppis_two_level_size(), &mut tl), ppis_status::PPIS_OK);
        assert_eq!(ppis_cones_init(aligned(&mut cmem), ppis_cones_size(3), 3, &mut cones), ppis_status::PPIS_OK);
        let mut u = [0.0f64; 32];
        let mut out = [ppis_sample::default(); 16];
        let mut sink = 0.0f32;
        ARMED.with(|a| a.set(true));
        for i in 0..1000u64 {
            let t = i as f32 * 0.01;
            let frame = ppis_frame_from_normal(ppis_vec3 { x: t.sin() * 0.6, y: 0.0, z: 0.8 });
            let wo = ppis_vec3 { x: 0.0, y: 0.6, z: 0.8 };
            let params = ppis_product_params_for_mis(128);
            ppis_product_build(product, m.env, brdf, &frame, wo, &params, i);
            ppis_two_level_build(tl, m.env, cones, brdf, &frame, wo);
            ppis_sobol02(i, 0, 16, u.as_mut_ptr());
            ppis_product_sample_many(product, u.as_ptr(), 16, out.as_mut_ptr());
            sink += out.iter().map(|s| s.pdf + ppis_product_pdf(product, s.dir)).sum::<f32>();
            ppis_two_level_sample_many(tl, u.as_ptr(), 16, out.as_mut_ptr());
            sink += out.iter().map(|s| s.pdf + ppis_two_level_pdf(tl, s.dir)).sum::<f32>();
            ppis_env_sample(m.env, u[0], u[1], &mut out[0]);
            sink += ppis_env_pdf(m.env, out[0].dir) + ppis_brdf_pdf(brdf, wo, out[0].dir);
        }
        ARMED.with(|a| a.set(false));
        assert!(sink.is_finite());
        assert_eq!(COUNT.with(|c| c.get()), 0, "the C ABI allocated");
    }
}

#[test]
fn the_library_names_no_missing_extension_on_a_cpu_that_runs_it() {
    // The tests run, so this CPU runs the build: the answer is NULL; a CPU without an
    // extension the build assumes is the core's test (`cpu::tests`).
    assert!(ppis_missing_cpu_feature().is_null());
}
