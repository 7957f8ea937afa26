//! The interface every environment-side sampler shares — env-only sampling, the quadtree
//! product, the two-level product and two-stage sampling — and the direction they draw. The
//! estimators are generic over it ([`crate::estimator::sampled`], [`crate::estimator::sampled_mis`]
//! and their batched forms), so a host holds any of them behind one type.

use crate::env::EnvHierarchy;
use crate::mapping::SPHERE_AREA;
use crate::sampler::ProductSampler;
use crate::two_level::TwoLevelSampler;
use crate::two_stage::TwoStageSampler;
use glam::{DVec2, Vec2, Vec3};

/// A direction drawn by a sampler, with its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionSample {
    /// World-space unit direction.
    pub dir: Vec3,
    /// Point of the equal-area square (map frame): where the radiance is looked up.
    pub uv: Vec2,
    /// Density with respect to solid angle (the same value the sampler's `pdf` gives).
    pub pdf: f32,
}

/// Draws directions towards an environment and gives the density of any direction, for MIS.
pub trait DirectionSampler {
    /// The environment the directions point into.
    fn env(&self) -> &EnvHierarchy<'_>;

    /// Draws a direction from the uniform point `u` ∈ [0,1)²; `None` when nothing can be drawn.
    fn sample(&self, u: DVec2) -> Option<DirectionSample>;

    /// Density per unit area of the equal-area square at `uv` (mean 1 over the square).
    fn pdf_square(&self, uv: Vec2) -> f32;

    /// Density with respect to solid angle of world direction `dir`.
    fn pdf(&self, dir: Vec3) -> f32 {
        self.pdf_square(self.env().square_of(dir)) / SPHERE_AREA
    }

    /// [`DirectionSampler::sample`] for every point of `u` (as many as both hold), bit for bit;
    /// implementations may draw several at once.
    fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        for (o, p) in out.iter_mut().zip(u) {
            *o = self.sample(*p);
        }
    }

    /// [`DirectionSampler::pdf_square`] for every point of `uv` (as many as both hold).
    fn pdf_square_many(&self, uv: &[Vec2], out: &mut [f32]) {
        for (o, p) in out.iter_mut().zip(uv) {
            *o = self.pdf_square(*p);
        }
    }
}

impl DirectionSampler for EnvHierarchy<'_> {
    fn env(&self) -> &EnvHierarchy<'_> {
        self
    }
    fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        EnvHierarchy::sample(self, u)
    }
    fn pdf_square(&self, uv: Vec2) -> f32 {
        EnvHierarchy::pdf_square(self, uv)
    }
    fn pdf(&self, dir: Vec3) -> f32 {
        EnvHierarchy::pdf(self, dir)
    }
    fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        EnvHierarchy::sample_many(self, u, out)
    }
    fn pdf_square_many(&self, uv: &[Vec2], out: &mut [f32]) {
        EnvHierarchy::pdf_square_many(self, uv, out)
    }
}

impl DirectionSampler for ProductSampler<'_, '_> {
    fn env(&self) -> &EnvHierarchy<'_> {
        ProductSampler::env(self)
    }
    fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        ProductSampler::sample(self, u)
    }
    fn pdf_square(&self, uv: Vec2) -> f32 {
        ProductSampler::pdf_square(self, uv)
    }
    fn pdf(&self, dir: Vec3) -> f32 {
        ProductSampler::pdf(self, dir)
    }
    fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        ProductSampler::sample_many(self, u, out)
    }
    fn pdf_square_many(&self, uv: &[Vec2], out: &mut [f32]) {
        ProductSampler::pdf_square_many(self, uv, out)
    }
}

impl DirectionSampler for TwoLevelSampler<'_, '_> {
    fn env(&self) -> &EnvHierarchy<'_> {
        TwoLevelSampler::env(self)
    }
    fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        TwoLevelSampler::sample(self, u)
    }
    fn pdf_square(&self, uv: Vec2) -> f32 {
        TwoLevelSampler::pdf_square(self, uv)
    }
    fn pdf(&self, dir: Vec3) -> f32 {
        TwoLevelSampler::pdf(self, dir)
    }
    fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        TwoLevelSampler::sample_many(self, u, out)
    }
}

impl<const R: usize> DirectionSampler for TwoStageSampler<'_, '_, R> {
    fn env(&self) -> &EnvHierarchy<'_> {
        TwoStageSampler::env(self)
    }
    fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        TwoStageSampler::sample(self, u)
    }
    fn pdf_square(&self, uv: Vec2) -> f32 {
        TwoStageSampler::pdf_square(self, uv)
    }
    fn pdf(&self, dir: Vec3) -> f32 {
        TwoStageSampler::pdf(self, dir)
    }
}
