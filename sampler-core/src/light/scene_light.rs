//! Any light of a scene behind one type, so that a host keeps its lights in one slice.

use super::{DiskLight, DistantLight, Light, LightHit, LightSample, PointLight, RectLight, SphereLight, TriangleLight};
use glam::{Vec2, Vec3};

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
