//! UsdGeomCamera: the camera looks down its local −Z with +Y up; the field of view follows
//! from focal length and apertures (schema fallbacks 50 and 20.955 × 15.2908). Without a
//! camera, a default view frames the scene's bounds.

use crate::scene::Camera;
use crate::shapes::number;
use crate::stage::{PrimPath, Stage, Value};
use glam::{DMat4, DVec3, Vec3};

/// Reads a Camera prim whose world transform (renderer frame) is `world`.
pub fn read(stage: &Stage, prim: &PrimPath, world: &DMat4) -> Result<(Camera, Vec<String>), String> {
    let mut notes = Vec::new();
    let focal_length = number(stage, prim, "focalLength", 50.0)? as f32;
    let horizontal_aperture = number(stage, prim, "horizontalAperture", 20.955)? as f32;
    let vertical_aperture = number(stage, prim, "verticalAperture", 15.2908)? as f32;
    let near = match stage.value(prim, "clippingRange")? {
        Some(Value::Numbers { values, .. }) if !values.is_empty() => values[0] as f32,
        _ => 1.0,
    };
    if stage.value(prim, "projection")?.as_ref().and_then(Value::token) == Some("orthographic") {
        notes.push("orthographic projection rendered as perspective".into());
    }
    for (attr, what) in [("horizontalApertureOffset", "aperture offset"), ("verticalApertureOffset", "aperture offset")]
    {
        if number(stage, prim, attr, 0.0)? != 0.0 {
            notes.push(format!("{what} ignored"));
        }
    }
    if number(stage, prim, "fStop", 0.0)? > 0.0 {
        notes.push("depth of field (fStop) ignored".into());
    }
    let origin = world.transform_point3(DVec3::ZERO);
    let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
    let up = world.transform_vector3(DVec3::Y).normalize_or_zero();
    if forward == DVec3::ZERO || up == DVec3::ZERO || !origin.is_finite() {
        return Err("the camera's transform is degenerate".into());
    }
    let valid = |x: f32| x.is_finite() && x > 0.0;
    if !valid(focal_length) || !valid(horizontal_aperture) || !valid(vertical_aperture) {
        return Err("focalLength and apertures must be positive".into());
    }
    notes.dedup();
    let camera = Camera {
        path: prim.to_string(),
        origin: origin.as_vec3(),
        forward: forward.as_vec3(),
        up: up.as_vec3(),
        focal_length,
        horizontal_aperture,
        vertical_aperture,
        near: if valid(near) { near } else { 1.0 },
    };
    Ok((camera, notes))
}

/// A camera that frames `bounds` from the front-right, slightly above, with the default
/// lens (a vertical field of view of about 17°).
pub fn framing(bounds: (Vec3, Vec3)) -> Camera {
    let (lo, hi) = bounds;
    let center = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let mut c = Camera {
        path: "<default view>".into(),
        origin: Vec3::ZERO,
        forward: Vec3::ZERO,
        up: Vec3::Y,
        focal_length: 35.0,
        horizontal_aperture: 20.955,
        vertical_aperture: 15.2908,
        near: radius * 1e-3,
    };
    let half_fov = 0.5 * c.fov_y_deg(c.horizontal_aperture / c.vertical_aperture).to_radians();
    let dir = Vec3::new(0.35, 0.3, 1.0).normalize();
    c.origin = center + dir * (1.1 * radius / half_fov.sin());
    c.forward = -dir;
    c
}
