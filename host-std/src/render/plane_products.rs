//! The environment times the cosine of each plane a diffuse material lies on: one pyramid per
//! plane normal (and side), built the first time a shading point needs it, so that every
//! shading point on the plane samples the map × its cosine exactly with nothing built per
//! point (`sampler_core::env::EnvHierarchy::plane_importance_rows`). On a diffuse plane that
//! leaves only visibility to vary the estimate; docs/perf.md, "Plane products", measures it.

use crate::light::map_buffer::{MapBuffer, PYRAMID_LINE_START};
use crate::scene::{Scene, Shape};
use rayon::prelude::*;
use sampler_core::env::{EnvHierarchy, build_pyramid_from_importance, pyramid_len};
use sampler_core::glam::Vec3;
use std::sync::OnceLock;

/// Angle (radians) within which a shading normal counts as a plane's: its pyramid reaches that
/// much further below the horizon, so that every direction above the shading point's own
/// horizon keeps a density > 0.
pub const NORMAL_TOLERANCE: f32 = 1e-3;

/// Finest map level (2^12 = 4096² texels) for which planes get pyramids of their own; above it
/// each would hold hundreds of megabytes, and their surfaces sample as their plan's fallback.
pub const MAX_PLANE_LEVEL: u32 = 12;

/// The planes' normals and their pyramids, each built on first use.
pub struct PlaneProducts {
    planes: Vec<Plane>,
}

/// One plane side: its unit normal and, once a shading point asked for it, its pyramid.
struct Plane {
    normal: Vec3,
    pyramid: OnceLock<MapBuffer<f32>>,
}

impl PlaneProducts {
    /// The distinct normals (both sides) of the planes among the objects of the materials
    /// `chosen` marks, for a map of finest level `level`; `None` where there are none or the map
    /// is finer than [`MAX_PLANE_LEVEL`].
    #[must_use]
    pub fn of_scene(scene: &Scene, level: u32, chosen: impl Fn(usize) -> bool) -> Option<Self> {
        if level > MAX_PLANE_LEVEL {
            return None;
        }
        let mut normals: Vec<Vec3> = Vec::new();
        for object in scene.objects.iter().filter(|o| chosen(o.material)) {
            let Some(n) = plane_normal(&object.shape) else { continue };
            for side in [n, -n] {
                if !normals.iter().any(|m| same_normal(*m, side)) {
                    normals.push(side);
                }
            }
        }
        let planes: Vec<Plane> = normals.into_iter().map(|normal| Plane { normal, pyramid: OnceLock::new() }).collect();
        (!planes.is_empty()).then_some(Self { planes })
    }

    /// The plane whose normal is `normal`'s (within [`NORMAL_TOLERANCE`]), if any.
    #[must_use]
    pub fn find(&self, normal: Vec3) -> Option<usize> {
        self.planes.iter().position(|p| same_normal(p.normal, normal))
    }

    /// `env` sampled ∝ radiance × plane `k`'s cosine, its pyramid built on the first call.
    #[must_use]
    pub fn view<'a>(&'a self, env: &EnvHierarchy<'a>, k: usize) -> EnvHierarchy<'a> {
        let plane = &self.planes[k];
        let pyramid = plane.pyramid.get_or_init(|| build(env, plane.normal));
        env.with_importance(pyramid).expect("built for this map's level")
    }

    /// How many plane sides there are.
    #[must_use]
    pub fn len(&self) -> usize {
        self.planes.len()
    }

    /// Whether there are none (never, as built).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty()
    }
}

/// Whether two unit normals are within [`NORMAL_TOLERANCE`] of each other.
fn same_normal(a: Vec3, b: Vec3) -> bool {
    a.dot(b) > 0.0 && a.cross(b).length() <= NORMAL_TOLERANCE
}

/// Rows of the map per task of a plane's build: a whole number of `COSINE_LEVEL`'s cells in
/// every map up to [`MAX_PLANE_LEVEL`], so that no task weighs a row of cells another does.
const BUILD_ROWS: usize = 64;

/// The pyramid of `env`'s radiance × the cosine to `normal`. The importance is written in bands
/// of rows on rayon's threads (each band depends on its rows alone): the render's threads that
/// wait for the plane meanwhile leave their cores to it.
fn build(env: &EnvHierarchy<'_>, normal: Vec3) -> MapBuffer<f32> {
    let level = env.finest_level();
    let n = 1usize << level;
    let mut importance = vec![0.0f32; n * n];
    importance.par_chunks_mut(n * BUILD_ROWS.min(n)).enumerate().for_each(|(k, band)| {
        let first_row = (k * BUILD_ROWS) as u32;
        env.plane_importance_rows(normal, NORMAL_TOLERANCE, first_row, band).expect("whole rows of the map");
    });
    let mut pyramid = MapBuffer::new(pyramid_len(level), PYRAMID_LINE_START);
    build_pyramid_from_importance(level, &importance, &mut pyramid).expect("sized for the map's level");
    pyramid
}

/// Whether every object of material `material` is flat (and there is one).
#[must_use]
pub fn on_planes_only(scene: &Scene, material: usize) -> bool {
    let mut objects = scene.objects.iter().filter(|o| o.material == material).peekable();
    objects.peek().is_some() && objects.all(|o| plane_normal(&o.shape).is_some())
}

/// The unit front normal of a flat shape: a rectangle's, or a mesh's whose every triangle with
/// an area faces the same way within [`NORMAL_TOLERANCE`] and whose shading normals, if any,
/// are that normal.
#[must_use]
pub fn plane_normal(shape: &Shape) -> Option<Vec3> {
    match shape {
        Shape::Rectangle { e1, e2, .. } => e1.cross(*e2).try_normalize(),
        Shape::Mesh { positions, triangles, normals, .. } => {
            let mut plane: Option<Vec3> = None;
            for t in triangles.iter() {
                let [a, b, c] = t.map(|i| positions.get(i as usize).copied());
                let Some(n) = (b? - a?).cross(c? - a?).try_normalize() else { continue };
                match plane {
                    Some(p) if !same_normal(p, n) => return None,
                    Some(_) => {}
                    None => plane = Some(n),
                }
            }
            let plane = plane?;
            normals.iter().flatten().all(|n| n.try_normalize().is_some_and(|n| same_normal(plane, n))).then_some(plane)
        }
        Shape::Sphere { .. } | Shape::Instance { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sampler_core::glam::Vec2;

    fn mesh(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>, normals: Vec<[Vec3; 3]>) -> Shape {
        Shape::Mesh {
            positions: positions.into(),
            triangles: triangles.into(),
            normals: normals.into(),
            uvs: Vec::<[Vec2; 3]>::new().into(),
        }
    }

    #[test]
    fn rectangles_and_flat_meshes_are_planes_and_nothing_else_is() {
        let rect = Shape::Rectangle { p0: Vec3::ZERO, e1: Vec3::X * 2.0, e2: -Vec3::Z * 3.0 };
        assert!(same_normal(plane_normal(&rect).unwrap(), Vec3::Y));
        let quad = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, -1.0), -Vec3::Z];
        let flat = mesh(quad.clone(), vec![[0, 1, 2], [0, 2, 3], [0, 0, 1]], Vec::new());
        assert!(same_normal(plane_normal(&flat).unwrap(), Vec3::Y), "degenerate triangles aside");
        let bent = mesh(vec![Vec3::ZERO, Vec3::X, -Vec3::Z, Vec3::Y], vec![[0, 1, 2], [0, 3, 1]], Vec::new());
        assert!(plane_normal(&bent).is_none());
        let smooth = mesh(quad.clone(), vec![[0, 1, 2]], vec![[Vec3::Y, Vec3::Y, Vec3::new(0.1, 1.0, 0.0)]]);
        assert!(plane_normal(&smooth).is_none(), "shading normals that bend");
        let shaded = mesh(quad, vec![[0, 1, 2]], vec![[Vec3::Y * 2.0; 3]]);
        assert!(plane_normal(&shaded).is_some(), "shading normals of the face's direction");
        assert!(plane_normal(&Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }).is_none());
    }

    #[test]
    fn normals_match_within_the_tolerance_on_the_same_side_only() {
        let tilted = Vec3::new(0.5 * NORMAL_TOLERANCE, 1.0, 0.0).normalize();
        assert!(same_normal(Vec3::Y, tilted));
        assert!(!same_normal(Vec3::Y, -tilted));
        assert!(!same_normal(Vec3::Y, Vec3::new(3.0 * NORMAL_TOLERANCE, 1.0, 0.0).normalize()));
    }
}
