//! Image textures for materials: bilinear lookups with USD's texture-coordinate convention
//! (st = (0, 0) is the image's lower-left corner) and wrap modes.

use crate::light::image_file::RgbImage;
use sampler_core::glam::Vec2;

/// How coordinates outside [0, 1] read the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// Repeats the image.
    Repeat,
    /// Reads the nearest edge texel.
    Clamp,
    /// Repeats the image mirrored every other time.
    Mirror,
    /// Reads black.
    Black,
}

impl Wrap {
    /// A UsdUVTexture `wrapS`/`wrapT` token; `useMetadata` (the default, for files without
    /// wrap metadata, which none of our decoders read) repeats.
    pub fn from_usd(token: &str) -> Self {
        match token {
            "clamp" => Wrap::Clamp,
            "mirror" => Wrap::Mirror,
            "black" => Wrap::Black,
            _ => Wrap::Repeat,
        }
    }

    /// Texel index for integer coordinate `i` of an axis of `n` texels, or `None` (black).
    fn index(self, i: i64, n: usize) -> Option<usize> {
        let n = n as i64;
        Some(match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
            Wrap::Black => {
                if !(0..n).contains(&i) {
                    return None;
                }
                i
            }
        } as usize)
    }
}

/// A decoded texture (linear RGB).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageTexture {
    /// The texels.
    pub image: RgbImage,
    /// How s and t outside [0, 1] read the image.
    pub wrap: [Wrap; 2],
}

impl ImageTexture {
    /// Bilinear lookup at texture coordinate `st`.
    pub fn eval(&self, st: Vec2) -> [f32; 3] {
        let (w, h) = (self.image.width, self.image.height);
        if w == 0 || h == 0 || !st.is_finite() {
            return [0.0; 3];
        }
        let x = st.x as f64 * w as f64 - 0.5;
        let y = (1.0 - st.y as f64) * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let texel = |i: f64, j: f64| -> [f32; 3] {
            match (self.wrap[0].index(i as i64, w), self.wrap[1].index(j as i64, h)) {
                (Some(i), Some(j)) => self.image.texels[j * w + i],
                _ => [0.0; 3],
            }
        };
        let (a, b, c, d) = (texel(x0, y0), texel(x0 + 1.0, y0), texel(x0, y0 + 1.0), texel(x0 + 1.0, y0 + 1.0));
        std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (d[k] - c[k]) * fx;
            top + (bottom - top) * fy
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex(wrap: Wrap) -> ImageTexture {
        // 2×2: top row red, green; bottom row blue, white.
        let texels = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        ImageTexture { image: RgbImage { width: 2, height: 2, texels, sanitized: 0 }, wrap: [wrap; 2] }
    }

    #[test]
    fn st_origin_is_the_lower_left_corner() {
        let t = tex(Wrap::Clamp);
        assert_eq!(t.eval(Vec2::new(0.25, 0.25)), [0.0, 0.0, 1.0]);
        assert_eq!(t.eval(Vec2::new(0.25, 0.75)), [1.0, 0.0, 0.0]);
        assert_eq!(t.eval(Vec2::new(0.75, 0.75)), [0.0, 1.0, 0.0]);
        let mid = t.eval(Vec2::new(0.5, 0.5));
        assert!((mid[0] - 0.5).abs() < 1e-6 && (mid[2] - 0.5).abs() < 1e-6);
    }

    #[test]
    fn wrap_modes() {
        assert_eq!(tex(Wrap::Repeat).eval(Vec2::new(1.25, 0.25)), [0.0, 0.0, 1.0]);
        assert_eq!(tex(Wrap::Black).eval(Vec2::new(3.0, 3.0)), [0.0; 3]);
        assert_eq!(tex(Wrap::Clamp).eval(Vec2::new(9.0, -9.0)), [1.0, 1.0, 1.0]);
        assert_eq!(tex(Wrap::Mirror).eval(Vec2::new(1.25, 0.25)), [1.0, 1.0, 1.0]);
    }
}
