//! Charts of the sphere and quadrature over it, with polar grids for sharp lobes.

use glam::{DVec2, Vec3};
use sampler_core::frame::Frame;
use sampler_core::mapping::{sphere_to_square, square_to_sphere};
use std::f64::consts::PI;

/// A parametrisation of the sphere by [0,1]² used for binning and quadrature.
#[derive(Clone, Copy, Debug)]
pub enum Chart {
    /// The equal-area square (constant Jacobian 4π).
    EqualArea,
    /// Polar coordinates about `axis`, concentrated within ~`scale` radians of it:
    /// tan(θ/2) = scale·tan(π t/2), φ = 2π s.
    Polar { axis: Vec3, scale: f64 },
}

impl Chart {
    /// Direction of chart point `c` and the solid angle per unit chart area there.
    pub fn dir_jacobian(&self, c: DVec2) -> (Vec3, f64) {
        match *self {
            Chart::EqualArea => (square_to_sphere(c.as_vec2()), 4.0 * PI),
            Chart::Polar { axis, scale } => {
                let a = 0.5 * PI * c.x;
                let ta = a.tan();
                let theta = 2.0 * (scale * ta).atan();
                let dtheta = 2.0 * scale * 0.5 * PI / (a.cos().powi(2) * (1.0 + scale * scale * ta * ta));
                let phi = 2.0 * PI * c.y;
                let f = Frame::from_normal(axis);
                let local =
                    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                (f.to_world(local), theta.sin() * dtheta * 2.0 * PI)
            }
        }
    }

    /// Chart point of a direction.
    pub fn point_of(&self, d: Vec3) -> DVec2 {
        match *self {
            Chart::EqualArea => sphere_to_square(d).as_dvec2(),
            Chart::Polar { axis, scale } => {
                let f = Frame::from_normal(axis);
                let l = f.to_local(d).as_dvec3();
                let theta = l.x.hypot(l.y).atan2(l.z);
                let t = 2.0 / PI * ((theta * 0.5).tan() / scale).atan();
                let mut phi = l.y.atan2(l.x) / (2.0 * PI);
                if phi < 0.0 {
                    phi += 1.0;
                }
                DVec2::new(t, phi)
            }
        }
    }
}

/// ∫ f dω over the sphere by the midpoint rule on an n×n grid of `chart`, each cell split into
/// `sub`×`sub` points.
pub fn integrate(chart: Chart, n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let c = DVec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let (d, jac) = chart.dir_jacobian(c);
            sum += f(d) * jac;
        }
    }
    sum / (n * n) as f64
}

/// ∫ f dω for an f with a sharp lobe of angular width `width` about `axis` plus wide parts:
/// a polar chart inside the cone of half-angle 30·width (capped at π) and an equal-area grid
/// outside it, each `n`×`n`.
pub fn integrate_lobe(axis: Vec3, width: f64, n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
    integrate_cone(axis, (30.0 * width).min(PI), n, f)
}

/// [`integrate_lobe`] with an explicit cone half-angle.
pub fn integrate_cone(axis: Vec3, cone: f64, n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
    let cone = cone.min(PI);
    let cos_cone = cone.cos();
    let axis_d = axis.as_dvec3().normalize();
    // Polar chart with θ = cone·g(t), g concentrating points near the axis.
    let frame = Frame::from_normal(axis);
    let mut inner = 0.0;
    for j in 0..n {
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64;
            let s = (j as f64 + 0.5) / n as f64;
            // θ = cone·t²: dense near the axis, dθ = 2·cone·t dt.
            let theta = cone * t * t;
            let dtheta = 2.0 * cone * t;
            let phi = 2.0 * PI * s;
            let local = glam::DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let d = frame.to_world(local.as_vec3());
            inner += f(d) * theta.sin() * dtheta * 2.0 * PI;
        }
    }
    inner /= (n * n) as f64;
    let outer = if cone >= PI {
        0.0
    } else {
        integrate(Chart::EqualArea, n, |d| if d.as_dvec3().normalize().dot(axis_d) < cos_cone { f(d) } else { 0.0 })
    };
    inner + outer
}

/// ∫ f(ωi) dωi over the sphere, integrated over half vectors: ωi = reflect(ωo, h) maps the
/// half vectors with ωo·h > 0 one-to-one onto the sphere with dωi = 4 |ωo·h| dωh. In h a GGX
/// lobe is an isotropic needle of width ~α around the normal whatever the view, so this stays
/// accurate at grazing views, where the lobe in ωi is stretched by ~1/cos θo. `normal`, `wo`:
/// world space; `alpha`: the sharpest lobe's width.
pub fn integrate_half_vector(normal: Vec3, wo: Vec3, alpha: f64, n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
    let wo = wo.normalize();
    // GGX's tail falls as α²/θ⁴: beyond a cone of 1000 α it holds ~1e-6 of the mass.
    integrate_cone(normal, 1000.0 * alpha, n, |h| {
        let c = wo.dot(h);
        if c <= 0.0 {
            return 0.0;
        }
        let wi = (2.0 * c * h - wo).normalize();
        f(wi) * 4.0 * c as f64
    })
}
