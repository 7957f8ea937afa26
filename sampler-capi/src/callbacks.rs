//! An engine's own BRDF given as C callbacks, with its properties and, optionally, its bounds
//! over cones of directions.

use crate::{ppis_status, ppis_vec2, ppis_vec3};
use core::ffi::c_void;
use sampler_core::brdf::{Brdf, BrdfSample};
use sampler_core::cone::Cone;
use sampler_core::glam::{Vec2, Vec3};

/// An engine's own BRDF: three functions and a pointer they receive. They may be called from
/// any thread that samples with the BRDF, so they must be safe to call concurrently.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct ppis_brdf_callbacks {
    /// Passed to every callback as its first argument.
    pub user: *mut c_void,
    /// BRDF × cosθi (RGB) for the view `wo` and the incident direction `wi`; 0 below the
    /// surface.
    pub eval: Option<unsafe extern "C" fn(user: *mut c_void, wo: ppis_vec3, wi: ppis_vec3) -> ppis_vec3>,
    /// Draws `wi` from the BRDF's sampling density with `u` ∈ [0,1)², writing the direction,
    /// BRDF × cosθi there and its density; returns 0 when nothing can be drawn.
    pub sample: Option<
        unsafe extern "C" fn(
            user: *mut c_void,
            wo: ppis_vec3,
            u: ppis_vec2,
            wi: *mut ppis_vec3,
            value: *mut ppis_vec3,
            pdf: *mut f32,
        ) -> i32,
    >,
    /// Density of `sample` at `wi` with respect to solid angle.
    pub pdf: Option<unsafe extern "C" fn(user: *mut c_void, wo: ppis_vec3, wi: ppis_vec3) -> f32>,
    /// Non-zero when the BRDF is as smooth as a Lambertian one.
    pub is_diffuse: i32,
    /// Angular width in radians, roughly, of the sharpest lobe (GGX α, π/2 for a diffuse
    /// BRDF): how far a shading point may move before a sampler built at another no longer
    /// fits (`ppis_brdf_lobe_width`). 0 is as sharp as a mirror.
    pub lobe_width: f32,
    /// Optional: upper bounds of the luminance of `eval` over `count` cones of incident
    /// directions (local frame), `out[k]` for `cones[k]`. With it the two-level product weighs
    /// its cells by the bounds; without it (null) by evaluating `eval` at five points per cell.
    pub cone_bounds: Option<
        unsafe extern "C" fn(user: *mut c_void, wo: ppis_vec3, cones: *const ppis_cone, count: usize, out: *mut f32),
    >,
}

/// The directions within `angle` radians of the unit vector `axis`, with the angle's cosine
/// and sine.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ppis_cone {
    /// Unit direction at the cone's centre.
    pub axis: ppis_vec3,
    /// Half-angle in radians, in [0, π].
    pub angle: f32,
    /// cos(angle).
    pub cos: f32,
    /// sin(angle).
    pub sin: f32,
}

impl From<&Cone> for ppis_cone {
    fn from(c: &Cone) -> Self {
        Self { axis: c.axis.into(), angle: c.angle, cos: c.cos, sin: c.sin }
    }
}

/// The signature of `ppis_brdf_callbacks::cone_bounds`.
type ConeBounds = unsafe extern "C" fn(*mut c_void, ppis_vec3, *const ppis_cone, usize, *mut f32);

/// Cones handed to a `cone_bounds` callback at once (converted on the stack).
const CONE_CHUNK: usize = 64;

/// Callbacks checked to be present.
#[derive(Clone, Copy)]
pub(crate) struct Callbacks {
    user: *mut c_void,
    eval: unsafe extern "C" fn(*mut c_void, ppis_vec3, ppis_vec3) -> ppis_vec3,
    sample: unsafe extern "C" fn(*mut c_void, ppis_vec3, ppis_vec2, *mut ppis_vec3, *mut ppis_vec3, *mut f32) -> i32,
    pdf: unsafe extern "C" fn(*mut c_void, ppis_vec3, ppis_vec3) -> f32,
    is_diffuse: bool,
    lobe_width: f32,
    cone_bounds: Option<ConeBounds>,
}

impl Brdf for Callbacks {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        // SAFETY: the engine vouches for its callback and `user` at `ppis_brdf_init_callbacks`.
        unsafe { (self.eval)(self.user, wo.into(), wi.into()) }.into()
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        let (mut wi, mut value, mut pdf) = (ppis_vec3::default(), ppis_vec3::default(), 0.0f32);
        // SAFETY: as for `eval`; the out-pointers are live locals.
        let drawn = unsafe { (self.sample)(self.user, wo.into(), u.into(), &mut wi, &mut value, &mut pdf) };
        (drawn != 0 && pdf > 0.0 && pdf.is_finite()).then(|| BrdfSample { wi: wi.into(), value: value.into(), pdf })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        // SAFETY: as for `eval`.
        unsafe { (self.pdf)(self.user, wo.into(), wi.into()) }
    }

    fn is_diffuse(&self) -> bool {
        self.is_diffuse
    }

    fn lobe_width(&self) -> f32 {
        self.lobe_width
    }

    fn has_cone_bounds(&self) -> bool {
        self.cone_bounds.is_some()
    }

    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        let Some(bounds) = self.cone_bounds else {
            out.iter_mut().zip(cones).for_each(|(o, _)| *o = f32::INFINITY);
            return;
        };
        let n = cones.len().min(out.len());
        let mut chunk = [ppis_cone::default(); CONE_CHUNK];
        for (cones, out) in cones[..n].chunks(CONE_CHUNK).zip(out[..n].chunks_mut(CONE_CHUNK)) {
            for (c, cone) in chunk.iter_mut().zip(cones) {
                *c = cone.into();
            }
            // SAFETY: as for `eval`; `chunk` and `out` hold `cones.len()` values.
            unsafe { bounds(self.user, wo.into(), chunk.as_ptr(), cones.len(), out.as_mut_ptr()) };
            // A NaN bound would poison the product's weights: it bounds nothing, so +∞.
            out.iter_mut().filter(|b| b.is_nan()).for_each(|b| *b = f32::INFINITY);
        }
    }
}

impl TryFrom<&ppis_brdf_callbacks> for Callbacks {
    type Error = ppis_status;

    fn try_from(c: &ppis_brdf_callbacks) -> Result<Self, ppis_status> {
        if !c.lobe_width.is_finite() || c.lobe_width < 0.0 {
            return Err(ppis_status::PPIS_BAD_VALUE);
        }
        match (c.eval, c.sample, c.pdf) {
            (Some(eval), Some(sample), Some(pdf)) => Ok(Self {
                user: c.user,
                eval,
                sample,
                pdf,
                is_diffuse: c.is_diffuse != 0,
                lobe_width: c.lobe_width,
                cone_bounds: c.cone_bounds,
            }),
            _ => Err(ppis_status::PPIS_BAD_VALUE),
        }
    }
}
