//! The BRDFs the batched-path tests run over: a glossy and a needle conductor, Lambert,
//! Phong and car paint.

use glam::Vec3;
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};

/// One of each kind of lobe the batched paths treat differently.
pub fn batch_brdfs() -> Vec<Box<dyn Brdf>> {
    vec![
        Box::new(RoughConductor::new(0.05, Vec3::new(0.9, 0.7, 0.5))),
        Box::new(RoughConductor::new(1e-3, Vec3::ONE)),
        Box::new(Lambert::new(Vec3::splat(0.6))),
        Box::new(Phong::new(Vec3::splat(0.2), Vec3::splat(0.7), 200.0)),
        Box::new(CarPaint::default()),
    ]
}
