//! host-usd's integration tests, one module per concept, in one binary: one link, and the test
//! harness runs them all on every core. `mutation` (a counting allocator, the whole process's)
//! and `hostile_scaling` (the process's CPU time) have binaries of their own.

mod corpus;
mod deep;
mod instancer_layout;
mod lights;
mod mesh;
mod paths;
mod pixar;
mod render_settings;
