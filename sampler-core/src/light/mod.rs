//! Light sources besides the environment, each sampling the directions from a shading point by
//! solid angle with an exact density (for MIS with BRDF sampling): a point light, a sphere, a
//! rectangle, a disk, a triangle (the faces of mesh lights) and a distant light with or without an
//! angular size. Radiometry follows the scene format's `lights` section (docs/scene-format.md).
//! Points, spheres, rectangles, disks and triangles may be shaped ([`Shaping`]: UsdLux's cone,
//! focus and IES profile, the last an [`IntensityProfile`] borrowed for the program's life).
//!
//! Every light implements [`Light`]; [`SceneLight`] holds any of them behind one type. Many
//! lights are picked by power ([`PowerSelector`]) or, per shading point, by a light tree
//! ([`LightTree`] over [`LightBounds`]). Area
//! lights emit on their front side only unless made two-sided ([`Emission`]). Positions are world
//! space; directions point from the shading point towards the light.
//!
//! ```
//! use sampler_core::light::{Light, SphereLight};
//! use glam::{Vec2, Vec3};
//!
//! let lamp = SphereLight::new(Vec3::new(0.0, 0.0, 4.0), 1.0, Vec3::splat(10.0)).unwrap();
//! let s = lamp.sample(Vec3::ZERO, Vec2::new(0.3, 0.7)).unwrap();
//! // The shadow ray runs from the shading point to just short of `s.distance`.
//! assert!(s.distance > 2.9 && s.distance < 4.0);
//! assert!((lamp.pdf(Vec3::ZERO, s.dir) - s.pdf).abs() <= 1e-4 * s.pdf);
//! ```

mod bounds;
mod disk;
mod distant;
mod oriented_profile;
mod point;
mod profile;
mod rect;
mod scene_light;
mod select;
mod shaping;
mod sphere;
mod spherical_rect;
mod spherical_triangle;
mod tilted_integral;
mod tree;
mod triangle;

pub use bounds::LightBounds;
pub use disk::DiskLight;
pub use distant::{DistantLight, MIN_DISTANT_ANGLE};
pub use oriented_profile::OrientedProfile;
pub use point::PointLight;
pub use profile::{HorizontalSymmetry, IntensityProfile, ProfileError};
pub use rect::RectLight;
pub use scene_light::{LightSurface, SceneLight};
pub use select::{PowerSelector, SelectedLight};
pub use shaping::Shaping;
pub use sphere::SphereLight;
pub use tilted_integral::{TILTED_GRID_CELLS, TiltedGrid};
pub use tree::{LightNode, LightTree, MAX_DEPTH, TreeError};
pub use triangle::{TriangleLight, TriangleSampling};

use glam::{Vec2, Vec3};

/// A direction drawn towards a light from a shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point towards the light.
    pub dir: Vec3,
    /// Distance to the sampled point of the light: the shadow ray's extent (`f32::INFINITY`
    /// for a distant light).
    pub distance: f32,
    /// Radiance arriving along `dir`. For a delta light (`delta`), the irradiance it delivers
    /// on a surface facing it instead (intensity/d² for a point light), to be used with `pdf` = 1.
    pub radiance: Vec3,
    /// Density with respect to solid angle (the value [`Light::pdf`] gives for `dir`); 1 for a
    /// delta light.
    pub pdf: f32,
    /// The light is a delta distribution: no other technique can find it, so the sample takes no
    /// MIS weight.
    pub delta: bool,
}

/// What a ray from a shading point sees of a light: the radiance it receives and the distance
/// to the light's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightHit {
    /// Radiance arriving along the ray.
    pub radiance: Vec3,
    /// Distance from the ray's origin to the light's surface (`f32::INFINITY` for a distant light).
    pub distance: f32,
}

/// A light source seen from shading points: sampling by solid angle, the density of any
/// direction, and the radiance a ray receives from it.
pub trait Light {
    /// Draws a direction towards the light from `p` with the uniform point `u` ∈ [0,1)². `None`
    /// when no direction can carry light to `p` (behind a one-sided emitter, inside a sphere
    /// that emits outwards, a degenerate configuration).
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample>;

    /// Density with respect to solid angle with which [`Light::sample`] draws the unit `dir`
    /// from `p`; 0 where it never draws and for delta lights.
    fn pdf(&self, p: Vec3, dir: Vec3) -> f32;

    /// What the ray from `p` along the unit `dir` receives from this light alone (no occlusion
    /// by anything else); `None` when it misses the light or sees its dark side.
    fn eval(&self, p: Vec3, dir: Vec3) -> Option<LightHit>;

    /// The light is a delta distribution (a point light, a distant light of angle 0).
    fn is_delta(&self) -> bool;

    /// Total emitted power (RGB, watts in the scene's units). A distant light's power is what
    /// crosses a disk of radius `scene_radius` facing it; the others ignore `scene_radius`.
    fn power(&self, scene_radius: f32) -> Vec3;
}

/// The radiance of an area light and which of its sides emit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Radiance (RGB) leaving each point of an emitting side.
    pub radiance: Vec3,
    /// Both sides emit (the scene format's lights emit on their front side only).
    pub two_sided: bool,
    /// How the radiance falls off away from an axis ([`Shaping::NONE`]: it does not).
    pub shaping: Shaping,
}

impl Emission {
    /// The power leaving a flat surface of area `area` that emits this radiance: π·L·A per
    /// emitting side, times the shaping's cosine-weighted integral over π when shaped.
    #[must_use]
    pub fn power(&self, area: f32) -> Vec3 {
        if self.shaping.is_none() {
            let sides = if self.two_sided { 2.0 } else { 1.0 };
            return self.radiance * (sides * core::f32::consts::PI * area);
        }
        self.radiance * area * self.shaping.integral(true, self.two_sided)
    }

    /// The power leaving a flat surface of area `area` and unit front normal `normal`, whose
    /// shaping axis may differ from its normal (a face of a shaped mesh light).
    #[must_use]
    pub fn power_facing(&self, area: f32, normal: Vec3) -> Vec3 {
        if self.shaping.is_none() {
            return self.power(area);
        }
        self.radiance * area * self.shaping.integral_about(normal, self.two_sided)
    }

    /// The radiance leaving towards `dir` (unit, from the receiver towards the emitter).
    #[inline]
    #[must_use]
    pub fn towards(&self, dir: Vec3) -> Vec3 {
        if self.shaping.is_none() { self.radiance } else { self.radiance * self.shaping.factor(-dir) }
    }
}

/// Why a light cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightError {
    /// A radiance, intensity or irradiance component is negative, NaN or infinite.
    BadRadiance,
    /// A position or size is NaN or infinite.
    NotFinite,
    /// A sphere's or disk's radius is not positive.
    ZeroRadius,
    /// A rectangle's or triangle's area is zero (or its edges are not perpendicular).
    ZeroArea,
    /// A normal or direction has zero length.
    DegenerateDirection,
    /// A distant light's angular diameter is negative or at least 180°.
    BadAngle,
}

impl core::fmt::Display for LightError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::BadRadiance => "radiance, intensity or irradiance is negative or not finite",
            Self::NotFinite => "a position or size is not finite",
            Self::ZeroRadius => "the radius is not positive",
            Self::ZeroArea => "the area is zero or the edges are not perpendicular",
            Self::DegenerateDirection => "a normal or direction has zero length",
            Self::BadAngle => "the angular diameter is not in [0°, 180°)",
        })
    }
}

impl core::error::Error for LightError {}

/// `Ok(v)` when every component of the RGB `v` is finite and non-negative.
fn checked_rgb(v: Vec3) -> Result<Vec3, LightError> {
    if v.is_finite() && v.min_element() >= 0.0 { Ok(v) } else { Err(LightError::BadRadiance) }
}

/// `Ok(v)` when every component of `v` is finite.
fn finite(v: Vec3) -> Result<Vec3, LightError> {
    if v.is_finite() { Ok(v) } else { Err(LightError::NotFinite) }
}

/// The unit vector along `v`, or an error when it has no direction.
fn unit(v: Vec3) -> Result<Vec3, LightError> {
    let v = finite(v)?;
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO { Err(LightError::DegenerateDirection) } else { Ok(n) }
}

/// The radiance `emission` sends along the ray of unit direction `dir` to a receiver that sees
/// the side whose cosine with the front normal (towards the receiver) is `cos_front`; `None`
/// for a dark side or a grazing view.
#[inline]
fn emitted(emission: &Emission, cos_front: f32, dir: Vec3) -> Option<Vec3> {
    (cos_front > 0.0 || (emission.two_sided && cos_front < 0.0)).then(|| emission.towards(dir))
}

/// The sample of a point `q` drawn uniformly on an area `area` of normal `normal`, seen from
/// `p` along the unit `dir` and emitting `radiance(dir)` that way; `None` where the density is
/// not positive and finite (`q` at `p`, or seen edge-on).
#[inline]
fn area_sample(p: Vec3, q: Vec3, normal: Vec3, area: f32, radiance: impl Fn(Vec3) -> Vec3) -> Option<LightSample> {
    let v = q - p;
    let distance = v.length();
    let dir = v / distance;
    let pdf = area_to_solid_angle(distance, dir.dot(normal), area);
    let ok = pdf > 0.0 && pdf.is_finite();
    ok.then(|| LightSample { dir, distance, radiance: radiance(dir), pdf, delta: false })
}

/// The density with respect to solid angle of a point drawn uniformly on an area `area`, seen
/// at `distance` with `|cos|` between the ray and the surface normal: d² / (|cos| A).
#[inline]
fn area_to_solid_angle(distance: f32, cos: f32, area: f32) -> f32 {
    let c = cos.abs();
    if c > 0.0 { distance * distance / (c * area) } else { 0.0 }
}
