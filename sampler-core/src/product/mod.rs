//! The quadtree product of one shading point (Clarberg & Akenine-Möller 2008), all its parts
//! together: the tree over the BRDF samples with the product computed in the same traversal
//! ([`quadtree`], its probes of B (`probe.rs`), its Haar cross-check [`wavelet`] and the
//! [`bilinear`] leaves), the arena that builds it, the [`sampler`] that warps points through
//! it and evaluates its density, and the same descents side by side (`lanes.rs`; the tree's
//! four to an AVX2 register in `lanes_avx2.rs`). The public modules are re-exported at the
//! crate's root (`sampler_core::sampler`, …).

mod arena;
pub mod bilinear;
mod bilinear_walk;
mod keys;
mod lanes;
#[cfg(target_arch = "x86_64")]
mod lanes_avx2;
mod params;
mod probe;
pub mod quadtree;
pub mod sampler;
pub mod wavelet;
