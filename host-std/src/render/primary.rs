//! What a pixel's camera rays find: at a surface, the shading point of the hit ([`Hit`], from
//! [`surface`]); otherwise the light the ray sees directly, the environment ([`background`],
//! the misses of a group of rays together) or a light's surface ([`emitted`]).

use crate::render::Context;
use crate::render::strategy::Strategy;
use crate::scene::{Bsdf, Scene};
use crate::trace::bvh;
use sampler_core::brdf::Brdf;
use sampler_core::estimator::ShadingPoint;
use sampler_core::frame::Frame;
use sampler_core::glam::{DVec3, Vec2, Vec3};
use sampler_core::light::Light;

/// A primary ray's hit, ready to shade.
pub(crate) struct Hit {
    /// The shading frame.
    pub frame: Frame,
    /// Towards the viewer.
    pub wo: Vec3,
    /// The BRDF at this hit when its material is textured; otherwise the material's.
    pub bsdf: Option<Bsdf>,
    /// Where shadow rays start: the hit, offset along the geometric normal.
    pub origin: Vec3,
    /// The hit's material.
    pub material: usize,
    /// The plane whose product it samples (`Context::planes`), where its material samples
    /// the plane product and it lies on one of the scene's planes.
    pub plane: Option<usize>,
    /// The shading point's index in the pixel.
    pub index: usize,
}

/// The shading point of a primary hit on a surface of material `material`, `None` where
/// nothing is reflected to the viewer (the back of a one-sided surface, or no light to
/// reflect).
pub(crate) fn surface(ctx: &Context<'_, '_>, dir: Vec3, hit: &bvh::Hit, material: usize, index: usize) -> Option<Hit> {
    let m = &ctx.scene.materials[material];
    let wo = -dir;
    let (mut n, mut ns) = (hit.normal, hit.shading_normal);
    if n.dot(wo) < 0.0 {
        // Seen from the back, a one-sided surface reflects nothing.
        if !m.twosided {
            return None;
        }
        (n, ns) = (-n, -ns);
    }
    // The shading frame follows the interpolated normal, kept on the viewer's side of the
    // surface.
    if ns.dot(n) <= 0.0 {
        ns = n;
    }
    if ctx.env.is_none() && ctx.lights.is_none() {
        return None;
    }
    let eps = 1e-4 * (1.0 + hit.point.abs().max_element());
    let plane = match (ctx.planes, ctx.plans[material].strategy) {
        (Some(planes), Strategy::PlaneProduct) => planes.find(ns),
        _ => None,
    };
    Some(Hit {
        frame: Frame::from_normal(ns),
        wo,
        bsdf: match (&m.texture, hit.uv) {
            (Some(t), Some(uv)) => Some(t.0.bsdf_at(uv)),
            _ => None,
        },
        origin: hit.point + n * eps,
        material,
        plane,
        index,
    })
}

/// What the primary rays in directions `dirs` that leave the scene (`found[k]` none) see, into
/// `out[k]`: the environment's radiance, the misses of up to a pixel group's 64 rays mapped to
/// its square together. Returns false, nothing written, where there is no environment or the scene hides
/// it.
pub(crate) fn background(ctx: &Context<'_, '_>, dirs: &[Vec3], found: &[Option<bvh::Hit>], out: &mut [Vec3]) -> bool {
    const CHUNK: usize = 64;
    debug_assert!(dirs.len() == found.len() && dirs.len() == out.len(), "one hit and one value per ray");
    let Some(env) = ctx.env.filter(|_| !ctx.scene.hide_emitters) else {
        return false;
    };
    for ((dirs, found), out) in dirs.chunks(CHUNK).zip(found.chunks(CHUNK)).zip(out.chunks_mut(CHUNK)) {
        let (mut ray_of_miss, mut missed, mut n) = ([0usize; CHUNK], [Vec3::ZERO; CHUNK], 0);
        for (k, (d, h)) in dirs.iter().zip(found).enumerate() {
            if h.is_none() {
                (ray_of_miss[n], missed[n]) = (k, *d);
                n += 1;
            }
        }
        let mut squares = [Vec2::ZERO; CHUNK];
        env.squares_of(&missed[..n], &mut squares[..n]);
        for (&k, uv) in ray_of_miss[..n].iter().zip(&squares[..n]) {
            out[k] = env.radiance_at(*uv);
        }
    }
    true
}

/// What a primary ray sees of the surface of light `light`: its radiance from the front, none
/// from the back or where the scene hides emitters.
pub(crate) fn emitted(ctx: &Context<'_, '_>, light: usize, dir: Vec3) -> DVec3 {
    if ctx.scene.hide_emitters {
        return DVec3::ZERO;
    }
    let seen = ctx.scene.lights[light].eval(ctx.camera.origin, dir);
    seen.map_or(DVec3::ZERO, |h| h.radiance.as_dvec3())
}

/// The hit's shading point: its own BRDF if its material is textured, the material's otherwise.
pub(crate) fn shading_point<'a>(scene: &'a Scene, h: &'a Hit) -> ShadingPoint<'a, dyn Brdf + 'a> {
    let brdf = match &h.bsdf {
        Some(b) => b.as_brdf(),
        None => scene.materials[h.material].bsdf.as_brdf(),
    };
    ShadingPoint { frame: h.frame, wo: h.wo, brdf }
}
