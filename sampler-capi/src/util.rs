//! Helpers an engine needs around the samplers: shading frames, deterministic point sets and
//! lat-long maps resampled into the equal-area square.

use crate::{ppis_frame, ppis_status, ppis_vec3, slice, slice_mut};
use core::ffi::{CStr, c_char};
use sampler_core::frame::Frame;
use sampler_core::glam::{DVec2, Vec3};
use sampler_core::latlong::{self, LatLongError};
use sampler_core::points::sobol02;

/// The frame `sampler-core` builds around a unit normal (continuous, branch-free).
#[unsafe(no_mangle)]
pub extern "C" fn ppis_frame_from_normal(n: ppis_vec3) -> ppis_frame {
    let f = Frame::from_normal(Vec3::from(n));
    ppis_frame { s: f.s.into(), t: f.t.into(), n: f.n.into() }
}

/// Writes points `first .. first + count` of an Owen-scrambled (0,2)-sequence seeded by `seed`
/// into `out` (2 × `count` doubles, (u0, u1) pairs): the points the Rust renderer draws with.
///
/// # Safety
/// `out` must be valid for writes of `2 × count` doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_sobol02(seed: u64, first: u32, count: usize, out: *mut f64) -> ppis_status {
    // SAFETY: the caller vouches for `2 × count` doubles.
    match unsafe { slice_mut(out.cast::<DVec2>(), count) } {
        Ok(points) => {
            sobol02(seed, first, points);
            ppis_status::PPIS_OK
        }
        Err(e) => e,
    }
}

/// The name of an instruction-set extension this library was built to assume throughout that
/// the CPU it runs on lacks (x86-64 builds of the workspace assume x86-64-v3: AVX2, FMA, BMI2…),
/// as a NUL-terminated static string such as `"avx2"`; NULL where the library runs here. Ask
/// before any other call: on such a CPU any other function may stop the process at an illegal
/// instruction. This one is CPUID and integer arithmetic, but it is compiled like the rest, so
/// the build makes no promise about it: a host that must run on such CPUs builds the library
/// portably instead.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_missing_cpu_feature() -> *const c_char {
    sampler_core::cpu::missing_build_feature().map_or(core::ptr::null(), CStr::as_ptr)
}

/// The equal-area level that keeps a `width × height` lat-long map's detail.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_equal_area_level(width: u32, height: u32) -> u32 {
    latlong::equal_area_level(width as usize, height as usize)
}

/// Resamples a row-major RGB lat-long map (`width × height` texels, 3 floats each, sanitized)
/// into the `2^level` equal-area square `dst` (3 × 4^level floats), conserving energy, with
/// `ss × ss` points per texel (2 is a good default). Convention: USD's DomeLight and the scene
/// format's — the top row is +Y, the left edge −Z, a quarter across +X (docs/embedding.md).
///
/// # Safety
/// `src` must be valid for `3 × width × height` floats, `dst` for `dst_floats` floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_latlong_to_equal_area(
    src: *const f32,
    width: u32,
    height: u32,
    level: u32,
    ss: u32,
    dst: *mut f32,
    dst_floats: usize,
) -> ppis_status {
    let (w, h) = (width as usize, height as usize);
    let run = || {
        if !dst_floats.is_multiple_of(3) {
            return Err(ppis_status::PPIS_BAD_SIZE);
        }
        // SAFETY: the caller vouches for the lengths.
        let (src, dst) =
            unsafe { (slice(src.cast::<[f32; 3]>(), w * h)?, slice_mut(dst.cast::<[f32; 3]>(), dst_floats / 3)?) };
        latlong::latlong_to_equal_area(src, w, h, level, ss as usize, dst).map_err(|e| match e {
            LatLongError::SourceSize | LatLongError::DestinationSize => ppis_status::PPIS_BAD_SIZE,
        })
    };
    crate::status(run())
}

/// The unit direction (the map's frame) of a point (u, v) of the equal-area unit square.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_square_to_sphere(p: crate::ppis_vec2) -> ppis_vec3 {
    sampler_core::mapping::square_to_sphere(p.into()).into()
}

/// The point of the equal-area square of a unit direction (the map's frame).
#[unsafe(no_mangle)]
pub extern "C" fn ppis_sphere_to_square(d: ppis_vec3) -> crate::ppis_vec2 {
    sampler_core::mapping::sphere_to_square(Vec3::from(d)).into()
}
