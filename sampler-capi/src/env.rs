//! The environment: its importance pyramid, built into the caller's buffer, and a view over it
//! that samples directions ∝ radiance (the env-only sampler).

use crate::{borrow, finish, place, ppis_sample, ppis_status, ppis_vec3, slice, slice_mut, status};
use core::ffi::c_void;
use sampler_core::env::{EnvError, EnvHierarchy, MAX_LEVEL, build_pyramid, pyramid_len, sanitize_rgb};
use sampler_core::glam::{DVec2, Mat3, Vec3};

/// An environment map: a borrowed pyramid and radiance, and a rotation into world space.
pub struct ppis_env {
    pub(crate) view: EnvHierarchy<'static>,
}

fn env_error(e: EnvError) -> ppis_status {
    match e {
        EnvError::NotSanitized => ppis_status::PPIS_NOT_SANITIZED,
        _ => ppis_status::PPIS_BAD_SIZE,
    }
}

/// RGB texels as `[f32; 3]`s from a float pointer and a count of floats.
///
/// # Safety
/// `rgb` must be null or valid for reads of `floats` floats.
unsafe fn texels<'a>(rgb: *const f32, floats: usize) -> Result<&'a [[f32; 3]], ppis_status> {
    if !floats.is_multiple_of(3) {
        return Err(ppis_status::PPIS_BAD_SIZE);
    }
    // SAFETY: `[f32; 3]` has the alignment of `f32`; the caller vouches for the floats.
    unsafe { slice(rgb.cast::<[f32; 3]>(), floats / 3) }
}

/// Floats in the pyramid of a `2^level × 2^level` map, or 0 above the largest level (14).
#[unsafe(no_mangle)]
pub extern "C" fn ppis_pyramid_len(level: u32) -> usize {
    if level > MAX_LEVEL { 0 } else { pyramid_len(level) }
}

/// Replaces NaN, infinite and negative components of `texels` RGB texels (3 floats each) by 0,
/// in place; returns how many texels changed. Radiance must be sanitized before it is used.
///
/// # Safety
/// `rgb` must be valid for reads and writes of `3 × texels` floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_sanitize_rgb(rgb: *mut f32, texels: usize) -> usize {
    // SAFETY: the caller vouches for `3 × texels` floats.
    match unsafe { slice_mut(rgb.cast::<[f32; 3]>(), texels) } {
        Ok(t) => sanitize_rgb(t),
        Err(_) => 0,
    }
}

/// Builds the importance pyramid of a `2^level` equal-area map from its row-major RGB radiance
/// (`rgb_floats` = 3 × 4^level, sanitized) into `pyramid` (`ppis_pyramid_len(level)` floats).
///
/// # Safety
/// The pointers must be valid for the lengths given.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_build_pyramid(
    level: u32,
    rgb: *const f32,
    rgb_floats: usize,
    pyramid: *mut f32,
    pyramid_floats: usize,
) -> ppis_status {
    if level > MAX_LEVEL {
        return ppis_status::PPIS_BAD_LEVEL;
    }
    status((|| {
        // SAFETY: the caller vouches for the lengths.
        let (rgb, out) = unsafe { (texels(rgb, rgb_floats)?, slice_mut(pyramid, pyramid_floats)?) };
        build_pyramid(level, rgb, out).map_err(env_error)
    })())
}

/// Bytes a `ppis_env` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_env_size() -> usize {
    size_of::<ppis_env>()
}

/// Alignment a `ppis_env` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_env_align() -> usize {
    align_of::<ppis_env>()
}

/// Makes an environment in `mem` (`mem_size` ≥ `ppis_env_size()` bytes, aligned) over a pyramid
/// from `ppis_build_pyramid` and its RGB radiance, both borrowed until `mem` is dropped. The map
/// starts unrotated (its frame is the world's).
///
/// # Safety
/// The pointers must be valid for the lengths given, and the borrowed buffers outlive `*out`.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn ppis_env_init(
    mem: *mut c_void,
    mem_size: usize,
    level: u32,
    pyramid: *const f32,
    pyramid_floats: usize,
    rgb: *const f32,
    rgb_floats: usize,
    out: *mut *mut ppis_env,
) -> ppis_status {
    if level > MAX_LEVEL {
        return ppis_status::PPIS_BAD_LEVEL;
    }
    let placed = (|| {
        // SAFETY: the caller vouches for the lengths and for the buffers outliving the view.
        let (pyramid, rgb) = unsafe { (slice(pyramid, pyramid_floats)?, texels(rgb, rgb_floats)?) };
        let view = EnvHierarchy::new(level, pyramid, rgb).map_err(env_error)?;
        // SAFETY: `mem` is checked by `place`.
        unsafe { place(mem, mem_size, ppis_env { view }) }
    })();
    // SAFETY: `out` is checked by `finish`.
    unsafe { finish(placed, out) }
}

/// Orients the map: `map_to_world` is a row-major 3 × 3 rotation taking directions of the map's
/// frame to world space.
///
/// # Safety
/// `env` must come from `ppis_env_init`; `map_to_world` must be valid for 9 floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_env_set_rotation(env: *mut ppis_env, map_to_world: *const f32) -> ppis_status {
    status((|| {
        // SAFETY: the caller vouches for both pointers.
        let (env, m) = unsafe { (env.as_mut().ok_or(ppis_status::PPIS_NULL_POINTER)?, slice(map_to_world, 9)?) };
        let rows = Mat3::from_cols_slice(m).transpose();
        let det = rows.determinant();
        if !m.iter().all(|v| v.is_finite()) || (det - 1.0).abs() > 1e-3 {
            return Err(ppis_status::PPIS_BAD_VALUE);
        }
        env.view = env.view.with_rotation(rows);
        Ok(())
    })())
}

/// Draws a direction ∝ the map's importance from the uniform point (u0, u1).
///
/// # Safety
/// `env` must come from `ppis_env_init`; `out` must be valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_env_sample(env: *const ppis_env, u0: f64, u1: f64, out: *mut ppis_sample) -> ppis_status {
    // SAFETY: the caller vouches for both pointers.
    let (Ok(env), Some(out)) = (unsafe { borrow(env) }, unsafe { out.as_mut() }) else {
        return ppis_status::PPIS_NULL_POINTER;
    };
    match env.view.sample(DVec2::new(u0, u1)) {
        Some(s) => {
            *out = ppis_sample { dir: s.dir.into(), uv: s.uv.into(), pdf: s.pdf };
            ppis_status::PPIS_OK
        }
        None => {
            *out = ppis_sample::default();
            ppis_status::PPIS_NOTHING_TO_SAMPLE
        }
    }
}

/// Density (solid angle) of `ppis_env_sample` at world direction `dir`; 0 for a null `env`.
///
/// # Safety
/// `env` must be null or come from `ppis_env_init`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_env_pdf(env: *const ppis_env, dir: ppis_vec3) -> f32 {
    // SAFETY: the caller vouches for `env`.
    unsafe { borrow(env) }.map_or(0.0, |e| e.view.pdf(Vec3::from(dir)))
}

/// RGB radiance arriving from world direction `dir` (nearest texel); 0 for a null `env`.
///
/// # Safety
/// `env` must be null or come from `ppis_env_init`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_env_radiance(env: *const ppis_env, dir: ppis_vec3) -> ppis_vec3 {
    // SAFETY: the caller vouches for `env`.
    unsafe { borrow(env) }.map_or(ppis_vec3::default(), |e| e.view.radiance(Vec3::from(dir)).into())
}

/// RGB radiance at a point of the equal-area square (a sample's `uv`: no round trip through
/// the direction, as the Rust estimators read it); 0 for a null `env`.
///
/// # Safety
/// `env` must be null or come from `ppis_env_init`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_env_radiance_at(env: *const ppis_env, uv: crate::ppis_vec2) -> ppis_vec3 {
    // SAFETY: the caller vouches for `env`.
    unsafe { borrow(env) }.map_or(ppis_vec3::default(), |e| e.view.radiance_at(uv.into()).into())
}
