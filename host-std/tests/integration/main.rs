//! host-std's integration tests, one module per concept, in one binary: one link, and the test
//! harness runs them all on every core. `loaders` has a binary of its own, since its counting
//! allocator is the whole process's.

mod cli;
mod common;
mod crop;
mod env_cache;
mod farm;
mod ies;
mod image_hashes;
mod lights;
mod pilot;
mod render;
mod scene_lights;
mod usd;
mod usd_ies;
mod usd_instances;
mod usd_lights;
mod usd_time;
mod usd_twins;
