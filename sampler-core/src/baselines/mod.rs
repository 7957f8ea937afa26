//! The samplers the quadtree product is measured against, each a
//! [`DirectionSampler`](crate::direction::DirectionSampler) like it: two-stage sampling (the
//! paper's comparison, [`two_stage`]) and the two-level product ([`two_level`]). Re-exported at
//! the crate's root (`sampler_core::two_stage`, `sampler_core::two_level`). Beside them, the
//! seed's other baselines, which are not direction samplers: structured importance sampling
//! ([`sis`]: the map as N pre-integrated directional lights) and Lightcuts ([`lightcuts`]: a cut
//! through a light tree per shading point), both deterministic and biased by design.

mod lightcut_bound;
mod lightcut_tree;
pub mod lightcuts;
pub mod sis;
pub mod two_level;
pub mod two_stage;
