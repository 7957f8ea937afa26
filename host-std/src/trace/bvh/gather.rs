//! The primitives of a scene: its shapes (rectangles as two triangles, meshes' triangles with
//! an area, with their shading normals and texture coordinates) and the surfaces of its area
//! lights, each tagged with what it is the surface of.

use super::disk::Disk;
use super::{CornerAttrs, NO_ATTRS, Primitive, Surface};
use crate::scene::{Scene, Shape};
use sampler_core::glam::{Vec2, Vec3};
use sampler_core::light::LightSurface;

/// What a scene's hierarchy is built over.
pub(super) struct Gathered {
    pub(super) prims: Vec<Primitive>,
    pub(super) corner_attrs: Vec<CornerAttrs>,
    pub(super) disks: Vec<Disk>,
}

/// Every primitive of `scene`, in the order of its objects and then of its lights.
pub(super) fn gather(scene: &Scene) -> Gathered {
    let mut g = Gathered { prims: Vec::new(), corner_attrs: Vec::new(), disks: Vec::new() };
    for o in &scene.objects {
        let surface = Surface::Material(o.material).id();
        match &o.shape {
            Shape::Sphere { center, radius } => {
                g.prims.push(Primitive::Sphere { center: *center, radius: *radius, surface })
            }
            Shape::Rectangle { p0, e1, e2 } => rectangle(&mut g.prims, *p0, *e1, *e2, surface),
            Shape::Mesh { positions, triangles, normals, uvs } => {
                mesh(&mut g, positions, triangles, normals, uvs, surface)
            }
            Shape::Instance { set, instance, group } => {
                if let Shape::Mesh { positions, triangles, normals, uvs } = set.0.mesh(*instance, *group) {
                    mesh(&mut g, &positions, &triangles, &normals, &uvs, surface)
                }
            }
        }
    }
    for (index, light) in scene.lights.iter().enumerate() {
        let surface = Surface::Emitter(index).id();
        match light.surface() {
            None => {}
            Some(LightSurface::Sphere { center, radius }) => {
                g.prims.push(Primitive::Sphere { center, radius, surface })
            }
            Some(LightSurface::Rect { p0, e1, e2 }) => rectangle(&mut g.prims, p0, e1, e2, surface),
            Some(LightSurface::Triangle([a, b, c])) => {
                g.prims.push(Primitive::Triangle { v0: a, e1: b - a, e2: c - a, surface, attrs: NO_ATTRS })
            }
            Some(LightSurface::Disk { center, normal, radius }) => {
                g.disks.push(Disk { center, normal, radius_squared: radius * radius, surface })
            }
        }
    }
    g
}

/// A mesh's triangles that have an area, with their shading normals and texture
/// coordinates where given and finite.
fn mesh(
    g: &mut Gathered,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    normals: &[[Vec3; 3]],
    uvs: &[[Vec2; 3]],
    surface: u32,
) {
    for (k, t) in triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        if has_area(a, b, c) {
            let n = normals.get(k).filter(|n| n.iter().all(|n| n.is_finite() && n.length_squared() > 0.0)).copied();
            let uv = uvs.get(k).filter(|uv| uv.iter().all(|t| t.is_finite())).copied();
            let attrs = if n.is_some() || uv.is_some() {
                g.corner_attrs.push(CornerAttrs { normals: n, uvs: uv });
                (g.corner_attrs.len() - 1) as u32
            } else {
                NO_ATTRS
            };
            g.prims.push(Primitive::Triangle { v0: a, e1: b - a, e2: c - a, surface, attrs });
        }
    }
}

/// The number of primitives [`gather`] makes of `shape`.
fn shape_count(shape: &Shape) -> usize {
    match shape {
        Shape::Sphere { .. } => 1,
        Shape::Rectangle { .. } => 2,
        Shape::Mesh { positions, triangles, .. } => triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                has_area(a, b, c)
            })
            .count(),
        // A triangle's area is the same in either winding.
        Shape::Instance { set, instance, group } => {
            set.0.count_triangles(*instance, *group, &|[a, b, c]| has_area(a, b, c))
        }
    }
}

/// The number of primitives [`gather`] makes of `scene` (disks aside), without making them.
pub(super) fn count(scene: &Scene) -> usize {
    let light = |surface: Option<LightSurface>| match surface {
        Some(LightSurface::Sphere { .. } | LightSurface::Triangle(_)) => 1,
        Some(LightSurface::Rect { .. }) => 2,
        Some(LightSurface::Disk { .. }) | None => 0,
    };
    scene.objects.iter().map(|o| shape_count(&o.shape)).sum::<usize>()
        + scene.lights.iter().map(|l| light(l.surface())).sum::<usize>()
}

/// The rectangle p0 + s·e1 + t·e2 as two triangles with its front face.
fn rectangle(prims: &mut Vec<Primitive>, p0: Vec3, e1: Vec3, e2: Vec3, surface: u32) {
    let attrs = NO_ATTRS;
    prims.push(Primitive::Triangle { v0: p0, e1, e2: e1 + e2, surface, attrs });
    prims.push(Primitive::Triangle { v0: p0, e1: e1 + e2, e2, surface, attrs });
}

/// Whether the triangle `a b c` has an area (a degenerate one is never hit, and is left out).
fn has_area(a: Vec3, b: Vec3, c: Vec3) -> bool {
    (b - a).cross(c - a).length_squared() > 0.0
}
