//! What is rendered: the scene model and the loaders that fill it — the built-in scene, the
//! JSON format, USD stages, triangle meshes (OBJ, PLY) and image textures. Depends on `light`
//! for the environment a scene names.

pub mod builtin;
pub mod ies;
mod instance;
pub mod json;
mod json_lights;
mod json_shaping;
pub mod mesh;
mod mesh_light;
mod model;
pub mod ply;
#[cfg(feature = "usd")]
mod rect_texture;
pub mod texture;
#[cfg(feature = "usd")]
pub mod usd;
#[cfg(feature = "usd")]
pub mod usd_info;
#[cfg(feature = "usd")]
pub mod usd_lights;

pub use instance::{Instances, InstancesHandle};
pub use model::*;
