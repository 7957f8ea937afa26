//! Implicit gprims (Sphere, Cube, Cylinder, Cone, Capsule, Plane) with their schema fallback
//! sizes, tessellated in local space with smooth normals. A Sphere under a similarity
//! transform is intersected exactly instead (see `import.rs`).

use crate::mesh::LocalMesh;
use crate::stage::{PrimPath, Stage, Value};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Segments around an axis; rings from pole to pole.
const SEGMENTS: usize = 64;
const RINGS: usize = 32;

/// A number attribute with the schema's fallback.
pub fn number(stage: &Stage, prim: &PrimPath, attr: &str, fallback: f64) -> Result<f64, String> {
    Ok(stage.value(prim, attr)?.and_then(|v| v.scalar()).unwrap_or(fallback))
}

fn axis_frame(stage: &Stage, prim: &PrimPath) -> Result<[DVec3; 3], String> {
    let axis = stage.value(prim, "axis")?;
    // (e1, e2, axis), right-handed.
    Ok(match axis.as_ref().and_then(Value::token).unwrap_or("Z") {
        "X" => [DVec3::Y, DVec3::Z, DVec3::X],
        "Y" => [DVec3::Z, DVec3::X, DVec3::Y],
        _ => [DVec3::X, DVec3::Y, DVec3::Z],
    })
}

/// The local mesh of an implicit gprim, or `None` for a type this file does not know.
pub fn tessellate(stage: &Stage, prim: &PrimPath, type_name: &str) -> Result<Option<LocalMesh>, String> {
    let mut b = Builder::default();
    match type_name {
        "Sphere" => {
            let r = number(stage, prim, "radius", 1.0)?;
            b.revolve([DVec3::X, DVec3::Y, DVec3::Z], RINGS, |t| {
                let phi = PI * t;
                (r * phi.sin(), -r * phi.cos(), DVec3::new(phi.sin(), 0.0, -phi.cos()))
            });
        }
        "Cube" => {
            let h = 0.5 * number(stage, prim, "size", 2.0)?;
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                for s in [-1.0, 1.0] {
                    let n = axis * s;
                    let (u, v) = (n.any_orthonormal_vector(), n.cross(n.any_orthonormal_vector()));
                    b.quad([n - u - v, n + u - v, n + u + v, n - u + v].map(|p| p * h), n);
                }
            }
        }
        "Cylinder" | "Cone" | "Capsule" => {
            let f = axis_frame(stage, prim)?;
            let (r_default, h_default) = if type_name == "Capsule" { (0.5, 1.0) } else { (1.0, 2.0) };
            let r = number(stage, prim, "radius", r_default)?;
            let h = number(stage, prim, "height", h_default)?;
            match type_name {
                "Cylinder" => {
                    b.revolve(f, 1, |t| (r, h * (t - 0.5), DVec3::X));
                    b.disk(f, r, 0.5 * h, 1.0);
                    b.disk(f, r, -0.5 * h, -1.0);
                }
                "Cone" => {
                    let slope = DVec3::new(h, 0.0, r).normalize();
                    b.revolve(f, 1, |t| (r * (1.0 - t), h * (t - 0.5), slope));
                    b.disk(f, r, -0.5 * h, -1.0);
                }
                _ => {
                    // Hemispheres of radius r on both ends of a cylinder of height h.
                    let half = RINGS / 2;
                    b.revolve(f, half, |t| {
                        let phi = 0.5 * PI * t;
                        (r * phi.sin(), -0.5 * h - r * phi.cos(), DVec3::new(phi.sin(), 0.0, -phi.cos()))
                    });
                    b.revolve(f, 1, |t| (r, h * (t - 0.5), DVec3::X));
                    b.revolve(f, half, |t| {
                        let phi = 0.5 * PI * (1.0 + t);
                        (r * phi.sin(), 0.5 * h - r * phi.cos(), DVec3::new(phi.sin(), 0.0, -phi.cos()))
                    });
                }
            }
        }
        "Plane" => {
            let [e1, e2, axis] = axis_frame(stage, prim)?;
            let w = 0.5 * number(stage, prim, "width", 2.0)?;
            let l = 0.5 * number(stage, prim, "length", 2.0)?;
            b.quad([-w * e1 - l * e2, w * e1 - l * e2, w * e1 + l * e2, -w * e1 + l * e2], axis);
        }
        _ => return Ok(None),
    }
    Ok(Some(b.mesh))
}

#[derive(Default)]
struct Builder {
    mesh: LocalMesh,
}

impl Builder {
    fn vertex(&mut self, p: DVec3) -> u32 {
        self.mesh.positions.push(p);
        (self.mesh.positions.len() - 1) as u32
    }

    fn tri(&mut self, t: [u32; 3], n: [DVec3; 3]) {
        self.mesh.faces.push(self.mesh.triangles.len() as u32);
        self.mesh.triangles.push(t);
        self.mesh.normals.push(n);
    }

    /// A flat quad, counter-clockwise around `n`.
    fn quad(&mut self, p: [DVec3; 4], n: DVec3) {
        let v = p.map(|p| self.vertex(p));
        self.tri([v[0], v[1], v[2]], [n; 3]);
        self.tri([v[0], v[2], v[3]], [n; 3]);
    }

    /// A surface of revolution about frame axis f[2]: `profile(t)`, t ∈ [0, 1] bottom to top,
    /// gives (radius, height, normal in the (radial, ·, axial) plane as (x, _, z)).
    fn revolve(&mut self, f: [DVec3; 3], rings: usize, profile: impl Fn(f64) -> (f64, f64, DVec3)) {
        let ring: Vec<(f64, f64, DVec3)> = (0..=rings).map(|i| profile(i as f64 / rings as f64)).collect();
        // sin(π) is 1e-16, not 0: radii this small relative to the largest are poles.
        let pole = 1e-9 * ring.iter().map(|r| r.0.abs()).fold(0.0, f64::max);
        let at = |j: usize, (r, h, n): (f64, f64, DVec3)| {
            let a = TAU * (j % SEGMENTS) as f64 / SEGMENTS as f64;
            let radial = f[0] * a.cos() + f[1] * a.sin();
            (radial * r + f[2] * h, (radial * n.x + f[2] * n.z).normalize_or_zero())
        };
        for i in 0..rings {
            for j in 0..SEGMENTS {
                let corners = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)].map(|(i, j)| at(j, ring[i]));
                // Skip the degenerate triangle at a pole (radius 0).
                let v = corners.map(|(p, _)| self.vertex(p));
                let n = corners.map(|(_, n)| n);
                if ring[i].0 > pole {
                    self.tri([v[0], v[1], v[2]], [n[0], n[1], n[2]]);
                }
                if ring[i + 1].0 > pole {
                    self.tri([v[0], v[2], v[3]], [n[0], n[2], n[3]]);
                }
            }
        }
    }

    /// A flat cap of radius r at height h, facing `side` · axis.
    fn disk(&mut self, f: [DVec3; 3], r: f64, h: f64, side: f64) {
        let n = f[2] * side;
        let c = self.vertex(f[2] * h);
        for j in 0..SEGMENTS {
            let p = |j: usize| {
                let a = TAU * (j % SEGMENTS) as f64 / SEGMENTS as f64;
                (f[0] * a.cos() + f[1] * a.sin()) * r + f[2] * h
            };
            let (a, b) = (self.vertex(p(j)), self.vertex(p(j + 1)));
            let t = if side > 0.0 { [c, a, b] } else { [c, b, a] };
            self.tri(t, [n; 3]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume of a closed triangle mesh (positive when faces wind outwards).
    fn volume(m: &LocalMesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn revolve_winds_outwards_with_outward_normals() {
        let mut b = Builder::default();
        b.revolve([DVec3::X, DVec3::Y, DVec3::Z], RINGS, |t| {
            let phi = PI * t;
            (phi.sin(), -phi.cos(), DVec3::new(phi.sin(), 0.0, -phi.cos()))
        });
        let v = volume(&b.mesh);
        assert!((v - 4.0 / 3.0 * PI).abs() < 0.02 * v, "{v}");
        for (t, n) in b.mesh.triangles.iter().zip(&b.mesh.normals) {
            let [a, bb, c] = t.map(|i| b.mesh.positions[i as usize]);
            let face = (bb - a).cross(c - a);
            assert!(face.dot(n[0]) > 0.0);
        }
        let mut c = Builder::default();
        let f = [DVec3::X, DVec3::Y, DVec3::Z];
        c.revolve(f, 1, |t| (1.0, 2.0 * (t - 0.5), DVec3::X));
        c.disk(f, 1.0, 1.0, 1.0);
        c.disk(f, 1.0, -1.0, -1.0);
        let v = volume(&c.mesh);
        assert!((v - 2.0 * PI).abs() < 0.01 * v, "{v}");
    }
}
