//! Errors of an image against the reference: over all pixels and per region (the pixels whose
//! centre ray hits a material of one kind and lobe width).

use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use crate::trace::camera::Camera;

/// Pixels grouped by the material their centre ray hits, named by kind and lobe width
/// ("diffuse", "roughconductor α=0.05", "phong n=200", "carpaint"); misses belong to no region.
pub struct Regions {
    /// The regions' names.
    pub names: Vec<String>,
    /// Per pixel, the index into `names`, or `None`.
    pub of_pixel: Vec<Option<usize>>,
}

impl Regions {
    /// The regions of the scene's image, from one centre ray per pixel.
    pub fn of(scene: &Scene, bvh: &Bvh) -> Self {
        let camera = Camera::new(&scene.camera);
        let (w, h) = (camera.width as usize, camera.height as usize);
        let mut names: Vec<String> = Vec::new();
        let mut of_pixel = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let d = camera.direction(x as f32 + 0.5, y as f32 + 0.5);
                let hit = bvh.intersect(camera.origin, d, camera.near_clip, f32::INFINITY);
                of_pixel.push(hit.and_then(|hit| hit.surface.material()).map(|material| {
                    let label = scene.materials[material].bsdf.label();
                    names.iter().position(|n| *n == label).unwrap_or_else(|| {
                        names.push(label);
                        names.len() - 1
                    })
                }));
            }
        }
        Self { names, of_pixel }
    }

    /// RMSE and relMSE of each region.
    pub fn errors(&self, image: &[[f32; 3]], reference: &[[f32; 3]]) -> Vec<(String, f64, f64)> {
        self.names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                let (mut se, mut rel, mut n) = (0.0f64, 0.0f64, 0usize);
                for ((p, r), region) in image.iter().zip(reference).zip(&self.of_pixel) {
                    if *region == Some(k) {
                        for c in 0..3 {
                            let d = p[c] as f64 - r[c] as f64;
                            se += d * d;
                            rel += d * d / (r[c] as f64 * r[c] as f64 + 0.01);
                        }
                        n += 3;
                    }
                }
                let n = n.max(1) as f64;
                (name.clone(), (se / n).sqrt(), rel / n)
            })
            .collect()
    }
}

/// The relative bias of `image`'s mean against `reference`'s (same size): Σ image / Σ
/// reference − 1 over pixels and channels; 0 against a black reference.
#[must_use]
pub fn relative_bias(image: &[[f32; 3]], reference: &[[f32; 3]]) -> f64 {
    let sum = |px: &[[f32; 3]]| px.iter().flatten().map(|&c| c as f64).sum::<f64>();
    let r = sum(reference);
    if r > 0.0 { sum(image) / r - 1.0 } else { 0.0 }
}

/// RMSE and relMSE of `image` against `reference` (same size).
pub fn errors(image: &[[f32; 3]], reference: &[[f32; 3]]) -> (f64, f64) {
    let (mut se, mut rel) = (0.0f64, 0.0f64);
    for (p, r) in image.iter().zip(reference) {
        for c in 0..3 {
            let d = p[c] as f64 - r[c] as f64;
            se += d * d;
            rel += d * d / (r[c] as f64 * r[c] as f64 + 0.01);
        }
    }
    let n = (3 * image.len()) as f64;
    ((se / n).sqrt(), rel / n)
}
