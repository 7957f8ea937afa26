//! A light's `shaping` in the scene format (docs/scene-format.md, "lights"): UsdLux ShapingAPI's
//! cone, focus and IES profile, with the same meaning as in USD, about an axis the scene gives
//! (a rectangle's and a disk's default to their front normal). Every value is checked: a shaping
//! that cannot exist is an error saying which field and why, and an IES file that cannot be
//! read or parsed is one naming the file.

use sampler_core::glam::Vec3;
use sampler_core::light::Shaping;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A light's `shaping` object.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct JsonShaping {
    #[serde(default)]
    axis: Option<[f32; 3]>,
    #[serde(default = "no_cutoff")]
    cone_angle_deg: f32,
    #[serde(default)]
    cone_softness: f32,
    #[serde(default)]
    focus: f32,
    #[serde(default)]
    focus_tint: [f32; 3],
    #[serde(default)]
    ies: Option<JsonIes>,
}

/// The `ies` object of a shaping: the file and how its profile sits on the light.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonIes {
    file: PathBuf,
    #[serde(default)]
    x: Option<[f32; 3]>,
    #[serde(default)]
    angle_scale: f32,
    #[serde(default)]
    normalize: bool,
}

fn no_cutoff() -> f32 {
    180.0
}

impl JsonShaping {
    /// The IES file this shaping reads, relative to the scene file.
    pub(super) fn file(&self) -> Option<&Path> {
        self.ies.as_ref().map(|i| i.file.as_path())
    }

    /// The core's shaping; `front` is the light's front normal where it has one (a rectangle,
    /// a disk), the axis's default. IES paths are resolved against `dir`.
    pub(super) fn build(&self, front: Option<Vec3>, dir: &Path) -> Result<Shaping, String> {
        let axis = match (self.axis, front) {
            (Some(a), _) => unit(Vec3::from_array(a)).ok_or("shaping.axis has no direction (zero or not finite)")?,
            (None, Some(n)) => n,
            (None, None) => return Err("shaping.axis is required on a point, sphere or mesh light".into()),
        };
        let cone = self.cone_angle_deg;
        if !(cone.is_finite() && cone >= 0.0) {
            return Err(format!("shaping.cone_angle_deg must be finite and ≥ 0 (180 or more: no cutoff), got {cone}"));
        }
        if !(0.0..=1.0).contains(&self.cone_softness) {
            return Err(format!("shaping.cone_softness must be in [0, 1], got {}", self.cone_softness));
        }
        if !(self.focus.is_finite() && self.focus >= 0.0) {
            return Err(format!("shaping.focus must be finite and ≥ 0, got {}", self.focus));
        }
        let tint = Vec3::from_array(self.focus_tint);
        if !(tint.is_finite() && tint.min_element() >= 0.0) {
            return Err(format!("shaping.focus_tint must be finite and ≥ 0, got {:?}", self.focus_tint));
        }
        let base = Shaping::new(axis, cone.min(180.0).to_radians(), self.cone_softness, self.focus, tint)
            .map_err(|e| format!("shaping: {e}"))?;
        match &self.ies {
            Some(ies) => ies.apply(base, axis, dir),
            None => Ok(base),
        }
    }
}

impl JsonIes {
    /// `base` times this profile, its horizontal 0° towards `x` (default: world +X, or +Y for
    /// an axis along X) and 90° towards x × axis, as UsdLux places it (local +X and +Y, the
    /// axis local −Z).
    fn apply(&self, base: Shaping, axis: Vec3, dir: &Path) -> Result<Shaping, String> {
        let path = dir.join(&self.file);
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: cannot read the IES file: {e}", path.display()))?;
        let profile = crate::scene::ies::parse(&bytes).map_err(|e| format!("{}: {e}", path.display()))?.profile();
        if !self.angle_scale.is_finite() {
            return Err(format!("shaping.ies.angle_scale must be finite, got {}", self.angle_scale));
        }
        let x = match self.x {
            Some(x) => unit(Vec3::from_array(x)).ok_or("shaping.ies.x has no direction (zero or not finite)")?,
            None if axis.x.abs() > 0.9 => Vec3::Y,
            None => Vec3::X,
        };
        let x = x - axis * axis.dot(x);
        if x.length() < 1e-4 {
            return Err("shaping.ies.x is parallel to the axis".into());
        }
        let y = x.cross(axis);
        base.with_profile(profile, x, y, self.angle_scale, self.normalize).map_err(|e| format!("shaping.ies: {e}"))
    }
}

/// The unit vector along `v`, if it has a direction.
fn unit(v: Vec3) -> Option<Vec3> {
    let n = v.normalize_or_zero();
    (v.is_finite() && n != Vec3::ZERO).then_some(n)
}
