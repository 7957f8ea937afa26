//! sampler-core's integration tests, one module per concept, in one binary: one link, and the
//! test harness runs them all on every core. `no_alloc` has a binary of its own, since its
//! counting allocator is the whole process's.

mod batched_estimators;
mod brdf_batch;
mod brdf_properties;
mod chi2;
mod common;
mod design_example;
mod determinism;
mod efficiency;
mod estimators;
mod full_resolution;
mod guard;
mod light_estimator;
mod light_irradiance;
mod light_profile;
mod light_shaping;
mod light_tree;
mod lights;
mod mapping;
mod pdf_integral;
mod plane_product;
mod stability_matrix;
mod two_level;
mod two_stage;
mod wavefront;
