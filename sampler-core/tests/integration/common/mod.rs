//! Shared helpers of the statistical tests: charts of the sphere, a χ² goodness-of-fit harness
//! (after Mitsuba 3's `ChiSquareTest`), quadrature, and test environments.
#![allow(dead_code)]

mod brdfs;
mod chi2;
mod lights;
mod quadrature;
mod test_env;

// Each test uses some of the helpers.
#[allow(unused_imports)]
pub use brdfs::*;
#[allow(unused_imports)]
pub use chi2::*;
#[allow(unused_imports)]
pub use lights::*;
#[allow(unused_imports)]
pub use quadrature::*;
#[allow(unused_imports)]
pub use test_env::*;
