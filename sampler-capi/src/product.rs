//! The quadtree product sampler (the paper's): one per thread, rebuilt per shading point from
//! the environment, the BRDF, the frame and the view.

use crate::{
    borrow, finish, place, ppis_brdf, ppis_env, ppis_frame, ppis_sample, ppis_status, ppis_vec3, slice, slice_mut,
};
use core::ffi::c_void;
use sampler_core::env::EnvHierarchy;
use sampler_core::glam::{DVec2, Vec3};
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::sampler::{ProductArena, ProductError, ProductParams, ProductSampler};

/// BRDF samples a `ppis_product` holds (the paper's K).
pub const PPIS_PRODUCT_CAPACITY: u32 = 256;

/// Settings of a product build (`ppis_product_params_default`, `ppis_product_params_for_mis`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ppis_product_params {
    /// BRDF samples that build B̃, at most `PPIS_PRODUCT_CAPACITY`.
    pub brdf_samples: u32,
    /// Depth cap of the quadtree, at most 24.
    pub max_depth: u32,
    /// Defensive environment-sampling fraction in [0, 1].
    pub defensive: f32,
    /// 0: the quadtree average; 1: the Haar wavelet product (equal in exact arithmetic).
    pub kind: u32,
    /// Non-zero: B probed at the centre of each leaf holding samples.
    pub probe_leaves: i32,
    /// Leaves holding more than this share of the product's mass are split (0: never; the
    /// wavelet product is never refined: with `kind` 1 it must be 0).
    pub refine_share: f32,
}

impl From<ProductParams> for ppis_product_params {
    fn from(p: ProductParams) -> Self {
        Self {
            brdf_samples: p.brdf_samples as u32,
            max_depth: p.max_depth,
            defensive: p.defensive,
            kind: u32::from(p.kind.is_wavelet()),
            probe_leaves: i32::from(p.kind.leaves() == Leaves::Probed),
            refine_share: p.kind.refine_share(),
        }
    }
}

impl TryFrom<&ppis_product_params> for ProductParams {
    type Error = ppis_status;

    fn try_from(p: &ppis_product_params) -> Result<Self, ppis_status> {
        if p.brdf_samples > PPIS_PRODUCT_CAPACITY {
            return Err(ppis_status::PPIS_ABOVE_CAPACITY);
        }
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        let refined_wavelet = p.kind == 1 && p.refine_share != 0.0;
        if p.max_depth > 24 || !unit(p.defensive) || !unit(p.refine_share) || p.kind > 1 || refined_wavelet {
            return Err(ppis_status::PPIS_BAD_VALUE);
        }
        let probe_leaves = p.probe_leaves != 0;
        let kind = if p.kind == 1 {
            ProductKind::Wavelet { probe_leaves }
        } else {
            let leaves = if probe_leaves { Leaves::Probed } else { Leaves::Sampled };
            ProductKind::Quadtree { leaves, refine_share: p.refine_share }
        };
        Ok(Self { brdf_samples: p.brdf_samples as usize, max_depth: p.max_depth, defensive: p.defensive, kind })
    }
}

/// The paper's settings: 256 BRDF samples, B̃ from the samples alone.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_product_params_default() -> ppis_product_params {
    ProductParams::default().into()
}

/// Settings for MIS with BRDF sampling from `brdf_samples` BRDF samples: leaves probed and
/// refined, a defensive fraction of 0.25.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_product_params_for_mis(brdf_samples: u32) -> ppis_product_params {
    ProductParams::for_mis(brdf_samples as usize).into()
}

/// A product sampler's memory: the arena and what the last build borrowed.
pub struct ppis_product {
    arena: ProductArena,
    env: *const EnvHierarchy<'static>,
}

impl ppis_product {
    fn sampler(&self) -> Result<ProductSampler<'_, 'static>, ppis_status> {
        // SAFETY: `env` was a live environment at the build; the caller keeps it alive.
        let env = unsafe { self.env.as_ref() }.ok_or(ppis_status::PPIS_NOT_BUILT)?;
        self.arena.last_built(env).ok_or(ppis_status::PPIS_NOT_BUILT)
    }
}

/// Bytes a `ppis_product` needs (about 45 KB).
#[unsafe(no_mangle)]
pub extern "C" fn ppis_product_size() -> usize {
    size_of::<ppis_product>()
}

/// Alignment a `ppis_product` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_product_align() -> usize {
    align_of::<ppis_product>()
}

/// Makes an empty product sampler in `mem`.
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_product_init(
    mem: *mut c_void,
    mem_size: usize,
    out: *mut *mut ppis_product,
) -> ppis_status {
    let value = ppis_product { arena: ProductArena::new(), env: core::ptr::null() };
    // SAFETY: `place` and `finish` check the pointers.
    unsafe { finish(place(mem, mem_size, value), out) }
}

/// Builds the product of one shading point: `wo` is the world direction to the viewer, `seed`
/// randomises the BRDF samples, `params` may be null (the defaults). The environment must stay
/// alive while the sampler is used.
///
/// # Safety
/// Every non-null pointer must come from this library's `init` functions (`frame`, `params`:
/// valid for reads).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_product_build(
    product: *mut ppis_product,
    env: *const ppis_env,
    brdf: *const ppis_brdf,
    frame: *const ppis_frame,
    wo: ppis_vec3,
    params: *const ppis_product_params,
    seed: u64,
) -> ppis_status {
    // SAFETY: the caller vouches for every pointer.
    let (Some(product), Ok(env), Ok(brdf), Ok(frame)) =
        (unsafe { product.as_mut() }, unsafe { borrow(env) }, unsafe { borrow(brdf) }, unsafe { borrow(frame) })
    else {
        return ppis_status::PPIS_NULL_POINTER;
    };
    // SAFETY: as above.
    let params = match unsafe { params.as_ref() }.map(ProductParams::try_from) {
        None => ProductParams::default(),
        Some(Ok(p)) => p,
        Some(Err(e)) => return e,
    };
    product.env = &env.view;
    match product.arena.build(&env.view, brdf, &frame.into(), Vec3::from(wo), &params, seed) {
        Ok(_) => ppis_status::PPIS_OK,
        Err(ProductError::AboveCapacity { .. }) => ppis_status::PPIS_ABOVE_CAPACITY,
    }
}

/// Draws a direction from the last build at the uniform point (u0, u1).
///
/// # Safety
/// `product` must come from `ppis_product_init`; `out` must be valid for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_product_sample(
    product: *const ppis_product,
    u0: f64,
    u1: f64,
    out: *mut ppis_sample,
) -> ppis_status {
    // SAFETY: the caller vouches for both pointers.
    let (Ok(p), Some(out)) = (unsafe { borrow(product) }, unsafe { out.as_mut() }) else {
        return ppis_status::PPIS_NULL_POINTER;
    };
    *out = ppis_sample::default();
    match p.sampler().map(|s| s.sample(DVec2::new(u0, u1))) {
        Ok(Some(s)) => {
            *out = s.into();
            ppis_status::PPIS_OK
        }
        Ok(None) => ppis_status::PPIS_NOTHING_TO_SAMPLE,
        Err(e) => e,
    }
}

/// Draws `count` directions from the points `u` (2 × `count` doubles, (u0, u1) pairs), several
/// at once, the same bits as `ppis_product_sample` one at a time. `out[k].pdf` is 0 where
/// nothing was drawn.
///
/// # Safety
/// `product` must come from `ppis_product_init`; `u` valid for `2 × count` doubles, `out` for
/// `count` samples.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_product_sample_many(
    product: *const ppis_product,
    u: *const f64,
    count: usize,
    out: *mut ppis_sample,
) -> ppis_status {
    let run = || {
        // SAFETY: the caller vouches for every pointer and length.
        let (p, u, out) = unsafe { (borrow(product)?, slice(u.cast::<DVec2>(), count)?, slice_mut(out, count)?) };
        let s = p.sampler()?;
        let mut drawn = [None; 16];
        for (u, out) in u.chunks(16).zip(out.chunks_mut(16)) {
            s.sample_many(u, &mut drawn[..u.len()]);
            for (o, d) in out.iter_mut().zip(&drawn) {
                *o = d.map(ppis_sample::from).unwrap_or_default();
            }
        }
        Ok(())
    };
    crate::status(run())
}

/// Density (solid angle) of the last build at world direction `dir`, for MIS; 0 before a build
/// or for a null `product`.
///
/// # Safety
/// `product` must be null or come from `ppis_product_init`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_product_pdf(product: *const ppis_product, dir: ppis_vec3) -> f32 {
    // SAFETY: the caller vouches for `product`.
    unsafe { borrow(product) }.ok().and_then(|p| p.sampler().ok()).map_or(0.0, |s| s.pdf(Vec3::from(dir)))
}
