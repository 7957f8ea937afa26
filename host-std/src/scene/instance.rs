//! Instanced geometry: a loader's prototype placed by many transforms (USD's PointInstancer),
//! held as one small record per instance and made triangles only when a render gathers its
//! primitives. See docs/usd.md, "Import speed", and docs/bvh.md, "Instances: what a two-level
//! BVH needs".

use super::Shape;
use sampler_core::glam::Vec3;
use std::fmt::Debug;
use std::sync::Arc;

/// A set of instances, each drawn as one mesh per material of its prototype (a group).
pub trait Instances: Send + Sync + Debug {
    /// The triangles of `instance`'s `group`, placed in the world: a [`Shape::Mesh`].
    fn mesh(&self, instance: u32, group: u32) -> Shape;
    /// The number of triangles of that mesh, without placing it.
    fn triangle_count(&self, instance: u32, group: u32) -> usize;
    /// The number of that mesh's triangles whose corners (in either winding) `counted`
    /// accepts, without making the mesh.
    fn count_triangles(&self, instance: u32, group: u32, counted: &dyn Fn([Vec3; 3]) -> bool) -> usize;
}

/// A shared [`Instances`] (equal when it is the same set).
#[derive(Clone, Debug)]
pub struct InstancesHandle(pub Arc<dyn Instances>);

impl PartialEq for InstancesHandle {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}
