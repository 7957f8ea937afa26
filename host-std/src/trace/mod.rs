//! Rays against the scene: the pinhole camera that makes primary rays and the BVH that
//! intersects them and tests shadow rays. Depends on `scene`.

pub mod bvh;
pub mod camera;
