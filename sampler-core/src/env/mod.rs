//! The environment hierarchy: a borrowed view over a caller-owned mip pyramid of the
//! equal-area map.
//!
//! Level `k` is a `2^k × 2^k` grid of scalar importance (luminance) with `x` along `u` and `y`
//! along `v`, stored in Morton (Z) order so that a node's four children are one contiguous
//! 16-byte block and a subtree stays together in memory — the warp touches one cache line per
//! level. Levels are packed from the 1×1 root down to the finest level `K`: level `k` starts at
//! [`level_offset`]`(k)`, node `(x, y)` of level `k` (a [`Cell`](crate::cell::Cell)) sits at [`pyramid_index`]; the whole pyramid holds
//! [`pyramid_len`]`(K)` values (4/3 of the finest level). Because every texel of the equal-area
//! map covers the same solid angle, each coarser texel is the plain mean of its four children.
//! RGB radiance for shading is kept at the finest level only, row-major. Lookups are
//! nearest-texel, the same piecewise-constant function the sampling densities are built from, so
//! radiance cancels exactly in the product estimator.
//!
//! The pyramid's layout and builders are in `pyramid.rs`, the view over it in `hierarchy.rs`,
//! env-only sampling in `sample.rs` (descending in f32, `descent_f32.rs`, eight to an AVX2
//! register in `descent_f32_avx2.rs` where the CPU has it), the f64 descents the product
//! samplers continue below their leaves side by side in `lanes.rs` (four to an AVX2 register in
//! `lanes_avx2.rs`); with a
//! texel table (`texel_cdf.rs`) attached, env-only sampling skips the descent. MIS with BRDF
//! samples draws from a compensated pyramid (`compensation.rs`) where one is attached, and weighs
//! its samples by the view's heuristic (`mis_heuristic.rs`). A Lambertian plane samples the map
//! times its cosine through a pyramid of its own (`plane.rs`).

mod compensation;
mod density;
mod descent_f32;
#[cfg(target_arch = "x86_64")]
mod descent_f32_avx2;
mod frame;
mod hierarchy;
mod lanes;
#[cfg(target_arch = "x86_64")]
mod lanes_avx2;
#[cfg(target_arch = "x86_64")]
mod lanes_avx2_ops;
mod mis_heuristic;
mod plane;
mod pyramid;
mod sample;
#[cfg(test)]
mod test_maps;
mod texel_cdf;

pub use compensation::compensate_pyramid;
pub use hierarchy::EnvHierarchy;
pub(crate) use lanes::{IN_FLIGHT, LANES, WarpLane};
#[cfg(target_arch = "x86_64")]
pub(crate) use lanes_avx2_ops::{clamp_unit, floats, lane_mask};
pub use mis_heuristic::MisHeuristic;
pub use plane::COSINE_LEVEL;
pub use pyramid::{
    EnvError, MAX_LEVEL, build_pyramid, build_pyramid_from_importance, level_offset, luminance, pyramid_index,
    pyramid_len, sanitize_rgb,
};
pub use texel_cdf::{CDF_MAX_LEVEL, TexelCdf, build_texel_cdf, texel_cdf_len, texel_guide_len};
