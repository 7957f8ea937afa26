//! `host-std`: the renderer around `sampler-core` — environment maps, scenes, a BVH, the
//! threaded tracer and the `ppis` command line.
//!
//! The modules are layers, each using only the ones listed before it:
//!
//! * [`light`]: environment maps — image files, lat-long resampling, the built-in sky;
//! * [`scene`]: the scene model and its loaders (built-in, JSON, USD, meshes, textures);
//! * [`trace`]: camera rays and the BVH;
//! * [`render`]: the tiles, the pixel pipeline, the sampler cache and shading, for materials
//!   whose strategies are decided;
//! * [`plan`]: the methods, `auto`'s rules and its pilot, and [`plan::render`], which plans a
//!   render and runs it;
//! * [`report`]: error against time over many renders;
//! * [`output`]: writing images and text, used by the command line and the report;
//! * [`merge`]: a frame assembled from crops rendered apart (`ppis merge`).

#![warn(missing_docs)]

pub mod cpu_time;
pub mod light;
pub mod merge;
pub mod output;
pub mod plan;
pub mod render;
pub mod report;
pub mod scene;
pub mod trace;
