//! The scene's environment light, owned by the host: the equal-area RGB map and its importance
//! pyramid, built once; `sampler-core` borrows both through an `EnvHierarchy`.

use super::map_buffer::{MapBuffer, PYRAMID_LINE_START};
use crate::light::image_file::{self, LoadError, RgbImage};
use crate::light::resample;
use crate::light::sky::Sky;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::glam::Mat3;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where an environment comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvSource {
    /// The built-in procedural sky at `2^level`.
    Sky {
        /// Equal-area resolution: 2^level texels square.
        level: u32,
    },
    /// An image file: lat-long (2:1) or an equal-area square.
    File(PathBuf),
    /// An image already in memory (e.g. read from inside a usdz package), named for messages;
    /// `latlong` reads it as lat-long whatever its shape (a USD dome texture is lat-long even
    /// when square).
    Bytes {
        /// The name messages give it.
        name: PathBuf,
        /// The encoded image.
        bytes: std::sync::Arc<Vec<u8>>,
        /// Read as lat-long whatever its shape.
        latlong: bool,
    },
    /// The same radiance from every direction (a DomeLight without a texture).
    Constant {
        /// Equal-area resolution: 2^level texels square.
        level: u32,
    },
}

/// How an environment is placed: radiance scale and tint, and rotation: d_world =
/// R_y(rotate_y_deg) · rotation · d_local (the scene format's rotation about +Y is the first
/// factor; a USD DomeLight's frame is `rotation`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Radiance scale.
    pub scale: f32,
    /// Radiance tint per channel.
    pub tint: [f32; 3],
    /// Rotation about +Y in degrees, applied after `rotation`.
    pub rotate_y_deg: f32,
    /// The map's frame in the world.
    pub rotation: Mat3,
}

impl Default for Placement {
    fn default() -> Self {
        Self { scale: 1.0, tint: [1.0; 3], rotate_y_deg: 0.0, rotation: Mat3::IDENTITY }
    }
}

/// Facts about a built environment, for the summary and the stats file.
#[derive(Clone, Debug, Default)]
pub struct EnvStats {
    /// Where the map came from, for messages.
    pub source: String,
    /// The source image's width and height.
    pub source_size: (usize, usize),
    /// Equal-area resolution: 2^level texels square.
    pub level: u32,
    /// Source texels that were NaN, infinite or negative and were set to 0.
    pub sanitized: usize,
    /// Mean radiance over the sphere of the source.
    pub source_mean: [f64; 3],
    /// Mean radiance over the sphere of the equal-area map.
    pub map_mean: [f64; 3],
    /// Seconds reading the source.
    pub load_seconds: f64,
    /// Seconds resampling and building the pyramid.
    pub build_seconds: f64,
    /// Bytes of the map and its pyramid.
    pub bytes: usize,
}

/// Equal-area texels, their level, and the source's mean radiance over the sphere.
type EqualArea = (Vec<[f32; 3]>, u32, [f64; 3]);

/// An environment map ready for sampling.
pub struct Environment {
    /// Equal-area resolution: 2^level texels square.
    pub level: u32,
    /// The equal-area map's linear RGB texels, row by row.
    pub rgb: MapBuffer<[f32; 3]>,
    /// The importance pyramid over the map's luminance (sampler-core's layout).
    pub pyramid: MapBuffer<f32>,
    /// Directions of the map's frame into the world's.
    pub map_to_world: Mat3,
    /// What building it found and took.
    pub stats: EnvStats,
}

/// Why an environment cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// The image cannot be loaded.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The image's shape is neither lat-long nor equal-area.
    #[error("{path}: a {width}×{height} image is neither a 2:1 lat-long map nor a square power-of-two equal-area map")]
    Layout {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// sampler-core rejects the map.
    #[error("{0}")]
    Core(#[from] sampler_core::env::EnvError),
}

impl Environment {
    /// Loads or generates the map, resamples it into the equal-area square and builds the
    /// pyramid.
    pub fn build(source: &EnvSource, placement: Placement) -> Result<Self, EnvError> {
        let t0 = Instant::now();
        let (mut rgb, level, mut stats) = match source {
            EnvSource::Sky { level } => {
                let rgb = Sky::default().equal_area(*level);
                let stats = EnvStats {
                    source: "built-in sky".into(),
                    source_size: (1 << level, 1 << level),
                    ..EnvStats::default()
                };
                (rgb, *level, stats)
            }
            EnvSource::Constant { level } => {
                let rgb = vec![[1.0f32; 3]; 1usize << (2 * level)];
                let stats = EnvStats {
                    source: "constant dome".into(),
                    source_size: (1 << level, 1 << level),
                    ..EnvStats::default()
                };
                (rgb, *level, stats)
            }
            EnvSource::File(_) | EnvSource::Bytes { .. } => {
                let (path, image, latlong) = match source {
                    EnvSource::File(path) => (path, image_file::load(path)?, false),
                    EnvSource::Bytes { name, bytes, latlong } => (name, image_file::load_bytes(name, bytes)?, *latlong),
                    _ => unreachable!("matched above"),
                };
                let load_seconds = t0.elapsed().as_secs_f64();
                let (rgb, level, source_mean) = Self::to_equal_area(path, &image, latlong)?;
                let stats = EnvStats {
                    source: path.display().to_string(),
                    source_size: (image.width, image.height),
                    sanitized: image.sanitized,
                    source_mean,
                    load_seconds,
                    ..EnvStats::default()
                };
                (rgb, level, stats)
            }
        };
        let gain = placement.tint.map(|t| if t.is_finite() { (t * placement.scale).max(0.0) } else { 0.0 });
        if gain != [1.0; 3] {
            rgb.iter_mut().for_each(|t| *t = [t[0] * gain[0], t[1] * gain[1], t[2] * gain[2]]);
        }
        sampler_core::env::sanitize_rgb(&mut rgb);
        let rgb = MapBuffer::from_slice(&rgb, 0);
        let mut pyramid = MapBuffer::new(pyramid_len(level), PYRAMID_LINE_START);
        build_pyramid(level, &rgb, &mut pyramid)?;
        stats.level = level;
        stats.map_mean = resample::equal_area_mean(&rgb);
        if matches!(source, EnvSource::Sky { .. } | EnvSource::Constant { .. }) {
            stats.source_mean = stats.map_mean;
        } else {
            stats.source_mean = std::array::from_fn(|c| stats.source_mean[c] * gain[c] as f64);
        }
        // Everything after reading the file: resampling, scaling, the pyramid.
        stats.build_seconds = t0.elapsed().as_secs_f64() - stats.load_seconds;
        stats.bytes = rgb.len() * 12 + pyramid.len() * 4;
        let map_to_world = Mat3::from_rotation_y(placement.rotate_y_deg.to_radians()) * placement.rotation;
        Ok(Self { level, rgb, pyramid, map_to_world, stats })
    }

    /// The equal-area texels, their level, and the source's mean radiance.
    fn to_equal_area(path: &Path, image: &RgbImage, latlong: bool) -> Result<EqualArea, EnvError> {
        let (w, h) = (image.width, image.height);
        if w == 2 * h || latlong {
            let level = resample::equal_area_level(w, h);
            let rgb = resample::latlong_to_equal_area(image, level, 2);
            Ok((rgb, level, resample::latlong_mean(image)))
        } else if w == h && w.is_power_of_two() && w.trailing_zeros() <= sampler_core::env::MAX_LEVEL {
            let mean = resample::equal_area_mean(&image.texels);
            Ok((image.texels.clone(), w.trailing_zeros(), mean))
        } else {
            Err(EnvError::Layout { path: path.to_owned(), width: w, height: h })
        }
    }

    /// The core's view of this map (a render attaches the MIS-compensated pyramid where a plan
    /// needs it: `render::compensated_pyramid`).
    pub fn hierarchy(&self) -> EnvHierarchy<'_> {
        EnvHierarchy::new(self.level, &self.pyramid, &self.rgb)
            .expect("buffers built by Environment::build have matching lengths")
            .with_rotation(self.map_to_world)
    }
}
