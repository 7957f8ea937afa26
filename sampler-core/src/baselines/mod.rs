//! The samplers the quadtree product is measured against, each a
//! [`DirectionSampler`](crate::direction::DirectionSampler) like it: two-stage sampling (the
//! paper's comparison, [`two_stage`]) and the two-level product ([`two_level`]). Re-exported at
//! the crate's root (`sampler_core::two_stage`, `sampler_core::two_level`).

pub mod two_level;
pub mod two_stage;
