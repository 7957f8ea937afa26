//! The two-level product: a coarse level's cell cones (shared, built once per level) and a
//! sampler per thread, rebuilt per shading point.

use crate::{
    borrow, finish, place, ppis_brdf, ppis_env, ppis_frame, ppis_sample, ppis_status, ppis_vec3, slice, slice_mut,
};
use core::ffi::c_void;
use sampler_core::cone::{Cone, build_cell_cones, cell_count};
use sampler_core::env::EnvHierarchy;
use sampler_core::glam::{DVec2, Vec3};
use sampler_core::two_level::{TwoLevelArena, TwoLevelError, TwoLevelSampler};

/// The finest coarse level a `ppis_two_level` serves (32 × 32 cells).
pub const PPIS_TWO_LEVEL_MAX_LEVEL: u32 = 5;

/// The bounding cones of every cell of one coarse level (read-only after init: share it): a
/// header followed in the same memory by `4^level` cones.
pub struct ppis_cones {
    level: u32,
}

/// Bytes from a `ppis_cones` to its first cone.
const CONES_OFFSET: usize = size_of::<ppis_cones>().next_multiple_of(align_of::<Cone>());

impl ppis_cones {
    fn cones(&self) -> &[Cone] {
        let first = core::ptr::from_ref(self).cast::<u8>().wrapping_add(CONES_OFFSET).cast::<Cone>();
        // SAFETY: `ppis_cones_init` placed `4^level` cones at `CONES_OFFSET` after the header.
        unsafe { core::slice::from_raw_parts(first, cell_count(self.level)) }
    }
}

/// Bytes a `ppis_cones` of `level` (≤ 5) needs; 0 above.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_cones_size(level: u32) -> usize {
    if level > PPIS_TWO_LEVEL_MAX_LEVEL { 0 } else { CONES_OFFSET + cell_count(level) * size_of::<Cone>() }
}

/// Alignment a `ppis_cones` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_cones_align() -> usize {
    align_of::<ppis_cones>().max(align_of::<Cone>())
}

/// Builds the cell cones of coarse `level` (3 to 5 are useful: 8 × 8 to 32 × 32 cells) in
/// `mem` (`ppis_cones_size(level)` bytes).
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_cones_init(
    mem: *mut c_void,
    mem_size: usize,
    level: u32,
    out: *mut *mut ppis_cones,
) -> ppis_status {
    if level > PPIS_TWO_LEVEL_MAX_LEVEL {
        return ppis_status::PPIS_BAD_LEVEL;
    }
    let placed = (|| {
        if mem_size < ppis_cones_size(level) {
            return Err(ppis_status::PPIS_BAD_SIZE);
        }
        if !(mem as usize).is_multiple_of(ppis_cones_align()) {
            return Err(ppis_status::PPIS_BAD_ALIGNMENT);
        }
        // SAFETY: `place` checks `mem`; the size check above covers the cones after the header.
        let header = unsafe { place(mem, mem_size, ppis_cones { level })? };
        // SAFETY: the memory at `CONES_OFFSET` holds `4^level` cones (size checked), aligned
        // (the offset is a multiple of the cone's alignment, `mem` of both).
        let cones = unsafe {
            let first = header.cast::<u8>().add(CONES_OFFSET).cast::<Cone>();
            for k in 0..cell_count(level) {
                first.add(k).write(Cone::default());
            }
            core::slice::from_raw_parts_mut(first, cell_count(level))
        };
        build_cell_cones(cones);
        Ok(header)
    })();
    // SAFETY: `finish` checks `out`.
    unsafe { finish(placed, out) }
}

/// A two-level sampler's memory: the arena and what the last build borrowed.
pub struct ppis_two_level {
    arena: TwoLevelArena,
    env: *const EnvHierarchy<'static>,
}

/// Bytes a `ppis_two_level` needs (about 8 KB).
#[unsafe(no_mangle)]
pub extern "C" fn ppis_two_level_size() -> usize {
    size_of::<ppis_two_level>()
}

/// Alignment a `ppis_two_level` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_two_level_align() -> usize {
    align_of::<ppis_two_level>()
}

/// Makes an empty two-level sampler in `mem`.
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_two_level_init(
    mem: *mut c_void,
    mem_size: usize,
    out: *mut *mut ppis_two_level,
) -> ppis_status {
    let value = ppis_two_level { arena: TwoLevelArena::new(), env: core::ptr::null() };
    // SAFETY: `place` and `finish` check the pointers.
    unsafe { finish(place(mem, mem_size, value), out) }
}

/// Builds the two-level product of one shading point over the coarse level of `cones`; `wo`
/// is the world direction to the viewer. The environment must stay alive while the sampler is
/// used.
///
/// # Safety
/// Every pointer must come from this library's `init` functions (`frame`: valid for a read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_two_level_build(
    sampler: *mut ppis_two_level,
    env: *const ppis_env,
    cones: *const ppis_cones,
    brdf: *const ppis_brdf,
    frame: *const ppis_frame,
    wo: ppis_vec3,
) -> ppis_status {
    // SAFETY: the caller vouches for every pointer.
    let (Some(s), Ok(env), Ok(cones), Ok(brdf), Ok(frame)) = (
        unsafe { sampler.as_mut() },
        unsafe { borrow(env) },
        unsafe { borrow(cones) },
        unsafe { borrow(brdf) },
        unsafe { borrow(frame) },
    ) else {
        return ppis_status::PPIS_NULL_POINTER;
    };
    s.env = &env.view;
    match s.arena.build(&env.view, cones.cones(), brdf, &frame.into(), Vec3::from(wo)) {
        Ok(_) => ppis_status::PPIS_OK,
        Err(TwoLevelError::FinerThanMap { .. }) => ppis_status::PPIS_BAD_LEVEL,
        Err(TwoLevelError::AboveCapacity { .. }) => ppis_status::PPIS_ABOVE_CAPACITY,
        Err(TwoLevelError::NotALevel { .. }) => ppis_status::PPIS_BAD_SIZE,
    }
}

impl ppis_two_level {
    fn sampler(&self) -> Result<TwoLevelSampler<'_, 'static>, ppis_status> {
        // SAFETY: `env` was live at the build; the caller keeps it alive.
        let env = unsafe { self.env.as_ref() }.ok_or(ppis_status::PPIS_NOT_BUILT)?;
        self.arena.last_built(env).ok_or(ppis_status::PPIS_NOT_BUILT)
    }
}

/// Draws a direction from the last build at the uniform point (u0, u1).
///
/// # Safety
/// `sampler` must come from `ppis_two_level_init`; `out` must be valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_two_level_sample(
    sampler: *const ppis_two_level,
    u0: f64,
    u1: f64,
    out: *mut ppis_sample,
) -> ppis_status {
    // SAFETY: the caller vouches for both pointers.
    let (Ok(s), Some(out)) = (unsafe { borrow(sampler) }, unsafe { out.as_mut() }) else {
        return ppis_status::PPIS_NULL_POINTER;
    };
    *out = ppis_sample::default();
    match s.sampler().map(|s| s.sample(DVec2::new(u0, u1))) {
        Ok(Some(d)) => {
            *out = d.into();
            ppis_status::PPIS_OK
        }
        Ok(None) => ppis_status::PPIS_NOTHING_TO_SAMPLE,
        Err(e) => e,
    }
}

/// Draws `count` directions from the points `u` (2 × `count` doubles); `out[k].pdf` is 0 where
/// nothing was drawn.
///
/// # Safety
/// `sampler` must come from `ppis_two_level_init`; `u` valid for `2 × count` doubles, `out`
/// for `count` samples.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_two_level_sample_many(
    sampler: *const ppis_two_level,
    u: *const f64,
    count: usize,
    out: *mut ppis_sample,
) -> ppis_status {
    let run = || {
        // SAFETY: the caller vouches for every pointer and length.
        let (s, u, out) = unsafe { (borrow(sampler)?, slice(u.cast::<DVec2>(), count)?, slice_mut(out, count)?) };
        let s = s.sampler()?;
        for (u, o) in u.iter().zip(out.iter_mut()) {
            *o = s.sample(*u).map(ppis_sample::from).unwrap_or_default();
        }
        Ok(())
    };
    crate::status(run())
}

/// Density (solid angle) of the last build at world direction `dir`; 0 before a build or for a
/// null `sampler`.
///
/// # Safety
/// `sampler` must be null or come from `ppis_two_level_init`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_two_level_pdf(sampler: *const ppis_two_level, dir: ppis_vec3) -> f32 {
    // SAFETY: the caller vouches for `sampler`.
    unsafe { borrow(sampler) }.ok().and_then(|s| s.sampler().ok()).map_or(0.0, |s| s.pdf(Vec3::from(dir)))
}
