//! Light sources. The environment: image files read into RGB texels, lat-long maps resampled to
//! the equal-area square, the built-in sky, and the built map with its importance pyramid that
//! `sampler-core` samples; and the other lights of a scene, as a table the renderer samples
//! (`lights.rs`), and the lights of the seed's baselines, SIS and Lightcuts (`baselines.rs`). The bottom layer: it depends on nothing else in the crate.

pub mod baselines;
mod distant_in_env;
mod latlong_x4;
pub use distant_in_env::move_distant_lights;
pub mod environment;
pub mod image_file;
pub mod lights;
pub mod map_buffer;
pub mod resample;
pub mod sky;
