//! The equal-area sphere and its dyadic cells: the map between the unit sphere and the unit
//! square ([`mapping`]), the cells `(level, x, y)` of the grids over the square ([`cell`]), lat-long maps resampled onto it ([`latlong`]), the hierarchical warp
//! down a quadtree of cells of the square ([`warp`]) and the bounding cones of those cells
//! ([`cone`]). The modules are re-exported at the crate's root (`sampler_core::mapping`, …).

pub mod cell;
pub mod cone;
pub mod latlong;
pub mod mapping;
pub mod warp;
