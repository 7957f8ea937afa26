//! `host-std`: the renderer around `sampler-core` — environment maps, scenes, a BVH, the
//! threaded tracer and the `ppis` command line.

pub mod bvh;
pub mod camera;
pub mod default_scene;
pub mod env_io;
pub mod environment;
pub mod integrator;
pub mod mesh;
pub mod output;
pub mod pilot;
pub mod ply;
pub mod render;
pub mod report;
pub mod resample;
pub mod scene;
pub mod scene_json;
pub mod sky;
pub mod texture;
#[cfg(feature = "usd")]
pub mod usd_info;
#[cfg(feature = "usd")]
pub mod usd_scene;
