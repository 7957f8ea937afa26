//! BRDFs: the built-in materials by their parameters, and an engine's own material given as
//! callbacks. All directions are in the local shading frame (normal = +z).

use crate::callbacks::{Callbacks, ppis_brdf_callbacks};
use crate::{borrow, finish, place, ppis_status, ppis_vec2, ppis_vec3};
use core::ffi::c_void;
use sampler_core::brdf::{Brdf, BrdfDraw, BrdfSample, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::cone::Cone;
use sampler_core::glam::{Vec2, Vec3, Vec4};

/// A BRDF: built-in or an engine's callbacks.
pub struct ppis_brdf(Kind);

/// What a `ppis_brdf` holds.
enum Kind {
    /// Lambertian.
    Lambert(Lambert),
    /// GGX conductor.
    Conductor(RoughConductor),
    /// Car paint.
    CarPaint(CarPaint),
    /// Modified Phong.
    Phong(Phong),
    /// An engine's own.
    Callbacks(Callbacks),
}

impl ppis_brdf {
    fn inner(&self) -> &dyn Brdf {
        match &self.0 {
            Kind::Lambert(b) => b,
            Kind::Conductor(b) => b,
            Kind::CarPaint(b) => b,
            Kind::Phong(b) => b,
            Kind::Callbacks(b) => b,
        }
    }
}

impl Brdf for ppis_brdf {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.inner().eval(wo, wi)
    }
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        self.inner().sample(wo, u)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.inner().pdf(wo, wi)
    }
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        self.inner().eval_pdf(wo, wi)
    }
    fn sample_many(&self, wo: Vec3, u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        self.inner().sample_many(wo, u, out)
    }
    fn eval_pdf_many(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        self.inner().eval_pdf_many(wo, wi, out)
    }
    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        self.inner().sample_batch(wo, u, out)
    }
    fn eval_luminance_x4(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        self.inner().eval_luminance_x4(wo, wi)
    }
    fn is_diffuse(&self) -> bool {
        self.inner().is_diffuse()
    }
    fn lobe_width(&self) -> f32 {
        self.inner().lobe_width()
    }
    fn has_cone_bounds(&self) -> bool {
        self.inner().has_cone_bounds()
    }
    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        self.inner().cone_bounds(wo, cones, out)
    }
    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        self.inner().reflectance_bound(wo)
    }
}

/// Bytes a `ppis_brdf` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_brdf_size() -> usize {
    size_of::<ppis_brdf>()
}

/// Alignment a `ppis_brdf` needs.
#[unsafe(no_mangle)]
pub extern "C" fn ppis_brdf_align() -> usize {
    align_of::<ppis_brdf>()
}

fn finite(v: &[f32]) -> Result<(), ppis_status> {
    if v.iter().all(|x| x.is_finite() && *x >= 0.0) { Ok(()) } else { Err(ppis_status::PPIS_BAD_VALUE) }
}

fn parts(v: ppis_vec3) -> [f32; 3] {
    [v.x, v.y, v.z]
}

/// Places a checked BRDF.
///
/// # Safety
/// `mem` valid for `mem_size` bytes, `out` for a write (both may be null: an error).
unsafe fn init(
    mem: *mut c_void,
    mem_size: usize,
    make: impl FnOnce() -> Result<ppis_brdf, ppis_status>,
    out: *mut *mut ppis_brdf,
) -> ppis_status {
    // SAFETY: forwarded to `place` and `finish`, which check the pointers.
    unsafe { finish(make().and_then(|b| place(mem, mem_size, b)), out) }
}

/// A Lambertian BRDF of RGB `albedo` (each in [0, 1]).
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_init_lambert(
    mem: *mut c_void,
    mem_size: usize,
    albedo: ppis_vec3,
    out: *mut *mut ppis_brdf,
) -> ppis_status {
    let make = || finite(&parts(albedo)).map(|()| ppis_brdf(Kind::Lambert(Lambert::new(albedo.into()))));
    // SAFETY: forwarded.
    unsafe { init(mem, mem_size, make, out) }
}

/// A GGX conductor of roughness `alpha` (α, not squared; clamped to ≥ 1e-4) and RGB
/// `specular` reflectance.
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_init_conductor(
    mem: *mut c_void,
    mem_size: usize,
    alpha: f32,
    specular: ppis_vec3,
    out: *mut *mut ppis_brdf,
) -> ppis_status {
    let make = || {
        finite(&[alpha])?;
        finite(&parts(specular)).map(|()| ppis_brdf(Kind::Conductor(RoughConductor::new(alpha, specular.into()))))
    };
    // SAFETY: forwarded.
    unsafe { init(mem, mem_size, make, out) }
}

/// A car paint: Lambertian `base`, GGX flakes of colour `flake` and roughness `flake_alpha`,
/// under a clear coat of weight `coat` ∈ [0, 1] and roughness `coat_alpha`.
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn ppis_brdf_init_carpaint(
    mem: *mut c_void,
    mem_size: usize,
    base: ppis_vec3,
    flake: ppis_vec3,
    flake_alpha: f32,
    coat: f32,
    coat_alpha: f32,
    out: *mut *mut ppis_brdf,
) -> ppis_status {
    let make = || {
        finite(&parts(base))?;
        finite(&parts(flake))?;
        finite(&[flake_alpha, coat, coat_alpha])?;
        if coat > 1.0 {
            return Err(ppis_status::PPIS_BAD_VALUE);
        }
        Ok(ppis_brdf(Kind::CarPaint(CarPaint::new(base.into(), flake.into(), flake_alpha, coat, coat_alpha))))
    };
    // SAFETY: forwarded.
    unsafe { init(mem, mem_size, make, out) }
}

/// A modified Phong BRDF: diffuse `kd`, specular `ks`, exponent (clamped to [0, 1e7]).
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes and `out` for a write.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_init_phong(
    mem: *mut c_void,
    mem_size: usize,
    kd: ppis_vec3,
    ks: ppis_vec3,
    exponent: f32,
    out: *mut *mut ppis_brdf,
) -> ppis_status {
    let make = || {
        finite(&parts(kd))?;
        finite(&parts(ks))?;
        finite(&[exponent])?;
        Ok(ppis_brdf(Kind::Phong(Phong::new(kd.into(), ks.into(), exponent))))
    };
    // SAFETY: forwarded.
    unsafe { init(mem, mem_size, make, out) }
}

/// An engine's own BRDF from its callbacks (`eval`, `sample` and `pdf` required; `lobe_width`
/// finite and ≥ 0). The two-level product bounds it by `cone_bounds` if given, by evaluation
/// otherwise.
///
/// # Safety
/// `mem` must be valid for `mem_size` bytes, `callbacks` for a read and `out` for a write; the
/// callbacks and `user` must stay valid while the BRDF is used.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_init_callbacks(
    mem: *mut c_void,
    mem_size: usize,
    callbacks: *const ppis_brdf_callbacks,
    out: *mut *mut ppis_brdf,
) -> ppis_status {
    let make = || {
        // SAFETY: the caller vouches for `callbacks`.
        let c = unsafe { borrow(callbacks)? };
        Callbacks::try_from(c).map(|c| ppis_brdf(Kind::Callbacks(c)))
    };
    // SAFETY: forwarded.
    unsafe { init(mem, mem_size, make, out) }
}

/// BRDF × cosθi (RGB) at local directions; 0 for a null `brdf`.
///
/// # Safety
/// `brdf` must be null or come from a `ppis_brdf_init_*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_eval(brdf: *const ppis_brdf, wo: ppis_vec3, wi: ppis_vec3) -> ppis_vec3 {
    // SAFETY: the caller vouches for `brdf`.
    unsafe { borrow(brdf) }.map_or(ppis_vec3::default(), |b| b.eval(wo.into(), wi.into()).into())
}

/// Density of the BRDF's own sampling at local `wi`; 0 for a null `brdf`.
///
/// # Safety
/// `brdf` must be null or come from a `ppis_brdf_init_*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_pdf(brdf: *const ppis_brdf, wo: ppis_vec3, wi: ppis_vec3) -> f32 {
    // SAFETY: the caller vouches for `brdf`.
    unsafe { borrow(brdf) }.map_or(0.0, |b| b.pdf(wo.into(), wi.into()))
}

/// Draws a local direction from the BRDF's own sampling with `u` ∈ [0,1)², writing it, BRDF ×
/// cosθi there and its density (0 and `PPIS_NOTHING_TO_SAMPLE` when nothing can be drawn).
///
/// # Safety
/// `brdf` must come from a `ppis_brdf_init_*`; the out-pointers must be valid for writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_sample(
    brdf: *const ppis_brdf,
    wo: ppis_vec3,
    u: ppis_vec2,
    wi: *mut ppis_vec3,
    value: *mut ppis_vec3,
    pdf: *mut f32,
) -> ppis_status {
    // SAFETY: the caller vouches for every pointer.
    let (Ok(b), Some(wi), Some(value), Some(pdf)) =
        (unsafe { borrow(brdf) }, unsafe { wi.as_mut() }, unsafe { value.as_mut() }, unsafe { pdf.as_mut() })
    else {
        return ppis_status::PPIS_NULL_POINTER;
    };
    match b.sample(wo.into(), u.into()) {
        Some(s) => {
            (*wi, *value, *pdf) = (s.wi.into(), s.value.into(), s.pdf);
            ppis_status::PPIS_OK
        }
        None => {
            (*wi, *value, *pdf) = (ppis_vec3::default(), ppis_vec3::default(), 0.0);
            ppis_status::PPIS_NOTHING_TO_SAMPLE
        }
    }
}

/// Angular width in radians, roughly, of the BRDF's sharpest lobe: GGX α, Phong √(2/(n+2)),
/// a car paint's coat, π/2 for a diffuse BRDF, a callback BRDF's own `lobe_width`. An engine
/// scales by it how far shading points may be apart and still share a sampler; 0 for a null
/// `brdf`.
///
/// # Safety
/// `brdf` must be null or come from a `ppis_brdf_init_*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_lobe_width(brdf: *const ppis_brdf) -> f32 {
    // SAFETY: the caller vouches for `brdf`.
    unsafe { borrow(brdf) }.map_or(0.0, |b| b.lobe_width())
}

/// 1 when the BRDF is as smooth as a Lambertian one (product sampling gains little over
/// environment sampling there), 0 otherwise or for a null `brdf`.
///
/// # Safety
/// `brdf` must be null or come from a `ppis_brdf_init_*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_is_diffuse(brdf: *const ppis_brdf) -> i32 {
    // SAFETY: the caller vouches for `brdf`.
    unsafe { borrow(brdf) }.map_or(0, |b| i32::from(b.is_diffuse()))
}

/// 1 when the BRDF bounds itself over cones of directions (every built-in BRDF; a callback
/// BRDF with `cone_bounds`), so the two-level product weighs cells by true bounds; 0
/// otherwise or for a null `brdf`.
///
/// # Safety
/// `brdf` must be null or come from a `ppis_brdf_init_*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ppis_brdf_has_cone_bounds(brdf: *const ppis_brdf) -> i32 {
    // SAFETY: the caller vouches for `brdf`.
    unsafe { borrow(brdf) }.map_or(0, |b| i32::from(b.has_cone_bounds()))
}
