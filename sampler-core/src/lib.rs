//! # sampler-core
//!
//! Practical product importance sampling of direct illumination from an environment map
//! (Clarberg & Akenine-Möller, EG 2008), for any engine: `#![no_std]`, no allocation, all
//! scratch memory in caller-provided arenas whose capacities are in their types.
//!
//! Pipeline per shading point: K BRDF samples → points of the equal-area square ([`mapping`]) →
//! a quadtree with one sample per leaf ([`quadtree`]) whose product with the environment's mip
//! pyramid ([`mod@env`]) is computed in the same traversal → hierarchical warping of uniform points
//! ([`points`], [`warp`]) through the tree and on through the environment's levels, with the
//! density of every direction available for MIS ([`sampler`]). [`estimator`] turns samples into
//! radiance; [`brdf`] holds the BRDF interface and the built-in materials; [`light`] samples
//! the other light sources (point, sphere, rectangle, disk, triangle, distant) by solid angle.
//!
//! ```
//! use sampler_core::{brdf::RoughConductor, env::{build_pyramid, pyramid_len, EnvHierarchy},
//!     frame::Frame, sampler::{ProductArena, ProductParams}};
//! use glam::{DVec2, Vec3};
//!
//! // A 4×4 equal-area map (level 2): grey sky with one bright texel.
//! let mut rgb = [[0.5f32; 3]; 16];
//! rgb[6] = [1.0e4; 3];
//! let mut pyramid = vec![0.0f32; pyramid_len(2)];
//! build_pyramid(2, &rgb, &mut pyramid).unwrap();
//! let env = EnvHierarchy::new(2, &pyramid, &rgb).unwrap();
//!
//! // One arena per thread, reused for every shading point.
//! let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
//! let brdf = RoughConductor::new(0.1, Vec3::ONE);
//! let frame = Frame::from_normal(Vec3::Z);
//! let wo = Vec3::new(0.3, 0.0, 1.0).normalize();
//! let sampler = arena.build(&env, &brdf, &frame, wo, &ProductParams::default(), 7).unwrap();
//! let s = sampler.sample(DVec2::new(0.3, 0.6)).unwrap();
//! assert_eq!(s.pdf, sampler.pdf(s.dir));
//! ```

#![no_std]
#![warn(missing_docs)]
#![forbid(unsafe_op_in_unsafe_fn)]
// Loops over the four children of a node read clearer with an index.
#![allow(clippy::needless_range_loop)]

#[cfg(test)]
extern crate std;

// The source groups what belongs together (`sphere/`, `env/`, `product/`, `baselines/`,
// `estimator/`, `brdf/`); the public modules keep one flat path each.
mod baselines;
pub mod cpu;
mod prefetch;
mod product;
mod sphere;

pub mod brdf;
pub mod direction;
pub mod env;
pub mod estimator;
pub mod frame;
pub mod light;
pub mod points;
pub mod rng;
pub mod sampling;

pub use baselines::{lightcuts, sis, two_level, two_stage};
pub use product::{bilinear, quadtree, sampler, wavelet};
pub use sphere::{cell, cone, latlong, mapping, warp};

pub use glam;
