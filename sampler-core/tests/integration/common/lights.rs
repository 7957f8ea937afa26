//! Lights seen from shading points, for the light samplers' tests: every kind, near and far,
//! face-on and edge-on, with the cone that holds the directions towards each.

use glam::Vec3;
use sampler_core::light::{
    DiskLight, DistantLight, Light, RectLight, SceneLight, Shaping, SphereLight, TriangleLight, TriangleSampling,
};

/// A light seen from `p`: `axis` points towards it and `cone` (radians) holds every direction
/// that reaches it; `scale` sizes a polar chart to it.
pub struct LightCase {
    pub name: &'static str,
    pub light: SceneLight,
    pub p: Vec3,
    pub axis: Vec3,
    pub cone: f64,
    pub scale: f64,
}

fn case(name: &'static str, light: impl Into<SceneLight>, p: Vec3, centre: Vec3, reach: f32) -> LightCase {
    let to = centre - p;
    let half = ((reach / to.length()).min(1.0) as f64).asin();
    let (cone, scale) = if reach >= to.length() {
        (std::f64::consts::PI, 1.0)
    } else {
        // A circular outline of half-angle `half` falls on the boundary between the chart's two
        // halves (tan(θ/2) = scale·tan(π/4)), where the χ² bins' quadrature is exact.
        (half.max(1e-4) * 1.05, (half * 0.5).tan())
    };
    LightCase { name, light: light.into(), p, axis: to.normalize(), cone, scale }
}

/// Every area and distant light in configurations that stress its sampler.
pub fn light_cases() -> Vec<LightCase> {
    let l = Vec3::new(2.0, 1.5, 1.0);
    let sphere = |c: Vec3, r: f32| SphereLight::new(c, r, l).unwrap();
    let rect =
        RectLight::new(Vec3::new(-1.0, -0.5, 2.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, -1.0, 0.0), l).unwrap();
    let disk = DiskLight::new(Vec3::new(0.3, 0.2, 1.5), Vec3::new(0.2, 0.1, -1.0), 0.7, l).unwrap();
    let tri = [Vec3::new(-1.0, 0.0, 1.0), Vec3::new(0.0, 1.5, 1.0), Vec3::new(1.0, -0.5, 1.0)];
    let tri_light = TriangleLight::new(tri, l).unwrap();
    let tri_centre = (tri[0] + tri[1] + tri[2]) / 3.0;
    let solid = TriangleSampling::SolidAngle { min_solid_angle: 1e-6 };
    vec![
        case("sphere far", sphere(Vec3::new(30.0, 40.0, 120.0), 1.0), Vec3::ZERO, Vec3::new(30.0, 40.0, 120.0), 1.0),
        case("sphere near", sphere(Vec3::new(0.0, 0.0, 1.05), 1.0), Vec3::ZERO, Vec3::new(0.0, 0.0, 1.05), 1.0),
        case(
            "sphere inside, two-sided",
            sphere(Vec3::ZERO, 1.0).with_two_sided(true),
            Vec3::new(0.3, -0.5, 0.2),
            Vec3::ZERO,
            1.0,
        ),
        case(
            "sun 0.53°",
            DistantLight::new(Vec3::new(0.3, 0.4, 0.8), l, 0.53f32.to_radians()).unwrap(),
            Vec3::ZERO,
            Vec3::new(0.3, 0.4, 0.8).normalize() * 1e4,
            0.265f32.to_radians().sin() * 1e4,
        ),
        case(
            "distant 40°",
            DistantLight::new(Vec3::Z, l, 40f32.to_radians()).unwrap(),
            Vec3::ZERO,
            Vec3::Z * 10.0,
            10.0 * 20f32.to_radians().sin(),
        ),
        case("rect face-on", rect, Vec3::new(0.2, -0.9, 0.0), Vec3::new(0.0, -1.0, 2.0), 1.2),
        case("rect near, edge-on", rect, Vec3::new(1.6, -0.9, 1.7), Vec3::new(0.0, -1.0, 2.0), 1.2),
        case("rect far", rect, Vec3::new(10.0, 30.0, -40.0), Vec3::new(0.0, -1.0, 2.0), 1.2),
        case("disk", disk, Vec3::new(0.0, 0.0, -0.5), Vec3::new(0.3, 0.2, 1.5), 0.7),
        case("disk near, edge-on", disk, Vec3::new(1.2, 0.3, 1.45), Vec3::new(0.3, 0.2, 1.5), 0.7),
        case(
            "triangle by area",
            tri_light.with_sampling(TriangleSampling::Area),
            Vec3::new(0.2, 0.1, 0.2),
            tri_centre,
            1.7,
        ),
        case("triangle by solid angle", tri_light.with_sampling(solid), Vec3::new(0.2, 0.1, 0.2), tri_centre, 1.7),
        case(
            "triangle by solid angle, near",
            tri_light.with_sampling(solid),
            Vec3::new(-0.5, 0.1, 0.98),
            tri_centre,
            1.7,
        ),
        case(
            "rect shaped (cone 40° soft, focus 2)",
            rect.with_shaping(Shaping::new(rect.normal(), 0.7, 0.5, 2.0, Vec3::new(0.2, 0.5, 1.0)).unwrap()),
            Vec3::new(0.9, -1.0, 0.2),
            Vec3::new(0.0, -1.0, 2.0),
            1.2,
        ),
        case(
            "sphere shaped (cone 30°)",
            sphere(Vec3::new(0.0, 0.0, 1.5), 0.6)
                .with_shaping(Shaping::new(Vec3::NEG_Z, 0.5, 0.0, 0.0, Vec3::ZERO).unwrap()),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.5),
            0.6,
        ),
    ]
}

/// The light's name and whether it is a delta light, for messages.
pub fn describe(light: &SceneLight) -> String {
    format!("{light:?} delta {}", light.is_delta())
}

/// ∫ f dω over the cone of half-angle `cone` about `axis`, one jittered point per cell of an
/// n×n polar grid (θ = cone·t², dense near the axis): where f jumps along a light's outline a
/// midpoint rule errs by the cells the outline crosses, a jittered one only by their variance.
pub fn integrate_cone_jittered(axis: Vec3, cone: f64, n: usize, seed: u64, f: impl Fn(Vec3) -> f64) -> f64 {
    use std::f64::consts::PI;
    let mut rng = sampler_core::rng::Pcg32::new(seed, 4);
    let frame = sampler_core::frame::Frame::from_normal(axis);
    let mut total = 0.0;
    for j in 0..n {
        for i in 0..n {
            let t = (i as f64 + rng.next_f64()) / n as f64;
            let phi = 2.0 * PI * (j as f64 + rng.next_f64()) / n as f64;
            let theta = cone * t * t;
            let local = glam::DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let d = frame.to_world(local.as_vec3()).normalize();
            total += f(d) * theta.sin() * 2.0 * cone * t * 2.0 * PI;
        }
    }
    total / (n * n) as f64
}
