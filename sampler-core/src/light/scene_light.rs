//! Any light of a scene behind one type, so that a host keeps its lights in one slice.

use super::{
    DiskLight, DistantLight, Light, LightHit, LightSample, PointLight, RectLight, Shaping, SphereLight, TriangleLight,
};
use glam::{Vec2, Vec3};

/// The surface of an area light, for a host that makes it visible to camera rays and lets it
/// occlude: the shape [`Light::eval`] intersects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightSurface {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// The rectangle `p0 + s·e1 + t·e2`, s, t ∈ [0, 1].
    Rect {
        /// A corner.
        p0: Vec3,
        /// The first edge from `p0`.
        e1: Vec3,
        /// The second edge from `p0`.
        e2: Vec3,
    },
    /// A disk.
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit normal of its plane.
        normal: Vec3,
        /// Radius.
        radius: f32,
    },
    /// A triangle.
    Triangle([Vec3; 3]),
}

/// One light of any kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneLight {
    /// A point light.
    Point(PointLight),
    /// A spherical area light.
    Sphere(SphereLight),
    /// A rectangular area light.
    Rect(RectLight),
    /// A disk-shaped area light.
    Disk(DiskLight),
    /// One triangle of a mesh light.
    Triangle(TriangleLight),
    /// A light at infinity.
    Distant(DistantLight),
}

macro_rules! dispatch {
    ($self:ident, $l:ident => $e:expr) => {
        match $self {
            SceneLight::Point($l) => $e,
            SceneLight::Sphere($l) => $e,
            SceneLight::Rect($l) => $e,
            SceneLight::Disk($l) => $e,
            SceneLight::Triangle($l) => $e,
            SceneLight::Distant($l) => $e,
        }
    };
}

impl SceneLight {
    /// The light's surface; `None` for a point or distant light, which nothing can hit.
    #[must_use]
    pub fn surface(&self) -> Option<LightSurface> {
        match self {
            SceneLight::Point(_) | SceneLight::Distant(_) => None,
            SceneLight::Sphere(l) => Some(l.surface()),
            SceneLight::Rect(l) => Some(l.surface()),
            SceneLight::Disk(l) => Some(l.surface()),
            SceneLight::Triangle(l) => Some(l.surface()),
        }
    }

    /// How the light's emission falls off from its shaping axis; `None` for a distant light,
    /// which has no shaping.
    #[must_use]
    pub fn shaping(&self) -> Option<&Shaping> {
        match self {
            SceneLight::Point(l) => Some(l.shaping()),
            SceneLight::Sphere(l) => Some(l.shaping()),
            SceneLight::Rect(l) => Some(l.shaping()),
            SceneLight::Disk(l) => Some(l.shaping()),
            SceneLight::Triangle(l) => Some(l.shaping()),
            SceneLight::Distant(_) => None,
        }
    }

    /// A light at infinity that BRDF-sampled directions can find (a distant light with an
    /// angular size): a ray that escapes the scene receives its radiance.
    #[must_use]
    pub fn is_infinite_area(&self) -> bool {
        matches!(self, SceneLight::Distant(l) if !l.is_delta())
    }
}

impl Light for SceneLight {
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        dispatch!(self, l => l.sample(p, u))
    }
    fn pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        dispatch!(self, l => l.pdf(p, dir))
    }
    fn eval(&self, p: Vec3, dir: Vec3) -> Option<LightHit> {
        dispatch!(self, l => l.eval(p, dir))
    }
    fn is_delta(&self) -> bool {
        dispatch!(self, l => l.is_delta())
    }
    fn power(&self, scene_radius: f32) -> Vec3 {
        dispatch!(self, l => l.power(scene_radius))
    }
}

macro_rules! from_light {
    ($($variant:ident($ty:ty)),*) => {
        $(impl From<$ty> for SceneLight {
            fn from(l: $ty) -> Self {
                Self::$variant(l)
            }
        })*
    };
}

from_light!(
    Point(PointLight),
    Sphere(SphereLight),
    Rect(RectLight),
    Disk(DiskLight),
    Triangle(TriangleLight),
    Distant(DistantLight)
);
