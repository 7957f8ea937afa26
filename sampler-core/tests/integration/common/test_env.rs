//! Environments owned by a test: RGB texels and their importance pyramid.

use glam::{Vec2, Vec3};
use sampler_core::env::{
    CDF_MAX_LEVEL, EnvHierarchy, TexelCdf, build_pyramid, build_texel_cdf, compensate_pyramid, pyramid_len,
    texel_cdf_len, texel_guide_len,
};
use sampler_core::mapping::square_to_sphere;
use sampler_core::rng::Pcg32;

/// An environment owned by a test: RGB texels and the importance pyramid.
pub struct TestEnv {
    pub level: u32,
    pub rgb: Vec<[f32; 3]>,
    pub pyramid: Vec<f32>,
    /// The texel table and its guide (env-only sampling without the descent).
    pub ends: Vec<u32>,
    pub guide: Vec<u32>,
    /// The pyramid compensated for MIS, where anything of the map stands above its mean.
    pub compensated: Option<Vec<f32>>,
}

impl TestEnv {
    pub fn new(level: u32, rgb: Vec<[f32; 3]>) -> Self {
        let mut pyramid = vec![0.0; pyramid_len(level)];
        build_pyramid(level, &rgb, &mut pyramid).unwrap();
        let (mut ends, mut guide) = (Vec::new(), Vec::new());
        if level <= CDF_MAX_LEVEL {
            ends = vec![0; texel_cdf_len(level)];
            guide = vec![0; texel_guide_len(level)];
            build_texel_cdf(level, &pyramid, &mut ends, &mut guide).unwrap();
        }
        let mut compensated = vec![0.0; pyramid.len()];
        let compensated = compensate_pyramid(level, &pyramid, &mut compensated).unwrap().then_some(compensated);
        Self { level, rgb, pyramid, ends, guide, compensated }
    }

    pub fn view(&self) -> EnvHierarchy<'_> {
        EnvHierarchy::new(self.level, &self.pyramid, &self.rgb).unwrap()
    }

    /// [`view`](Self::view) sampling env-only through the texel table.
    #[allow(dead_code)]
    pub fn table_view(&self) -> EnvHierarchy<'_> {
        let cdf = TexelCdf::new(self.level, &self.ends, &self.guide).unwrap();
        self.view().with_texel_cdf(cdf).unwrap()
    }

    /// [`view`](Self::view)'s MIS view: sampled by the compensated pyramid, as the renderer's
    /// MIS samples it (the plain pyramid where nothing stands above the mean).
    #[allow(dead_code)]
    pub fn compensated_view(&self) -> EnvHierarchy<'_> {
        match &self.compensated {
            Some(c) => self.view().with_compensated(c).unwrap().compensated(),
            None => self.view(),
        }
    }

    /// Smooth random sky: a few random lobes over a dim floor, coloured.
    pub fn random_smooth(level: u32, seed: u64) -> Self {
        let n = 1usize << level;
        let mut rng = Pcg32::new(seed, 11);
        let lobes: Vec<(Vec3, f32, f32)> = (0..4)
            .map(|_| {
                let d = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
                (d, 2.0 + 30.0 * rng.next_f32(), 0.5 + 5.0 * rng.next_f32())
            })
            .collect();
        let mut rgb = vec![[0.0; 3]; n * n];
        for y in 0..n {
            for x in 0..n {
                let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32));
                let mut v = 0.05;
                for (axis, sharp, w) in &lobes {
                    v += w * (sharp * (d.dot(*axis) - 1.0)).exp();
                }
                rgb[y * n + x] = [v * 0.9, v, v * 1.2];
            }
        }
        Self::new(level, rgb)
    }

    /// Blue-ish sky with one texel `ratio` times brighter (a sun) at texel `sun`.
    pub fn sun(level: u32, sun: (usize, usize), ratio: f32) -> Self {
        let n = 1usize << level;
        let mut rgb = vec![[0.3, 0.5, 1.0]; n * n];
        rgb[sun.1 * n + sun.0] = [ratio, ratio, ratio];
        Self::new(level, rgb)
    }

    /// Constant radiance everywhere.
    pub fn constant(level: u32, value: f32) -> Self {
        let n = 1usize << level;
        Self::new(level, vec![[value; 3]; n * n])
    }
}
