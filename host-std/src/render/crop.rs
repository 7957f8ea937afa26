//! A crop: the pixel bounds of a part of the frame, half-open (`x0 ≤ x < x1`, `y0 ≤ y < y1`),
//! as pbrt's `--pixelbounds` and OpenEXR's data window say it. A farm renders a frame as
//! crops in separate processes and merges them; [`Crop::grid`] is how `ppis tiles` splits a
//! frame for it, along the renderer's 16-pixel tile edges where it can, so that no render tile
//! is rendered by two crops.

use std::fmt;

/// Half-open pixel bounds inside a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Crop {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

/// Why a crop does not fit a frame.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum CropError {
    /// Not four whole numbers.
    #[error("--crop {0}: expected x0,y0,x1,y1 (four pixel bounds, half-open)")]
    Syntax(String),
    /// `x1 ≤ x0` or `y1 ≤ y0`.
    #[error("--crop {0}: empty or reversed (needs x0 < x1 and y0 < y1)")]
    Empty(Crop),
    /// Past the frame's right or bottom edge.
    #[error("--crop {crop}: outside the {width}×{height} frame")]
    Outside {
        /// The crop.
        crop: Crop,
        /// The frame's width.
        width: usize,
        /// The frame's height.
        height: usize,
    },
}

impl Crop {
    /// The whole frame.
    #[must_use]
    pub fn full(width: usize, height: usize) -> Self {
        Self { x0: 0, y0: 0, x1: width, y1: height }
    }

    /// Columns.
    #[must_use]
    pub fn width(&self) -> usize {
        self.x1.saturating_sub(self.x0)
    }

    /// Rows.
    #[must_use]
    pub fn height(&self) -> usize {
        self.y1.saturating_sub(self.y0)
    }

    /// Pixels.
    #[must_use]
    pub fn area(&self) -> usize {
        self.width() * self.height()
    }

    /// Whether pixel (x, y) is inside.
    #[must_use]
    pub fn contains(&self, x: usize, y: usize) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The pixels both crops hold, if any.
    #[must_use]
    pub fn intersection(&self, other: &Crop) -> Option<Crop> {
        let c = Crop {
            x0: self.x0.max(other.x0),
            y0: self.y0.max(other.y0),
            x1: self.x1.min(other.x1),
            y1: self.y1.min(other.y1),
        };
        (c.x0 < c.x1 && c.y0 < c.y1).then_some(c)
    }

    /// Parses `x0,y0,x1,y1` (spaces allowed around the numbers); the bounds are checked
    /// against a frame by [`Crop::check`].
    pub fn parse(text: &str) -> Result<Self, CropError> {
        let numbers: Vec<usize> = text.split(',').filter_map(|s| s.trim().parse().ok()).collect();
        match numbers[..] {
            [x0, y0, x1, y1] if text.split(',').count() == 4 => Ok(Self { x0, y0, x1, y1 }),
            _ => Err(CropError::Syntax(text.to_string())),
        }
    }

    /// The crop, when it is non-empty and inside a `width`×`height` frame.
    pub fn check(self, width: usize, height: usize) -> Result<Self, CropError> {
        if self.x1 <= self.x0 || self.y1 <= self.y0 {
            return Err(CropError::Empty(self));
        }
        if self.x1 > width || self.y1 > height {
            return Err(CropError::Outside { crop: self, width, height });
        }
        Ok(self)
    }

    /// The frame split into `columns`×`rows` crops, row by row, their edges on multiples of
    /// `align` where the frame is large enough (else as even as whole pixels allow). Every
    /// pixel is in exactly one crop; `None` when there are more columns or rows than pixels.
    #[must_use]
    pub fn grid(width: usize, height: usize, columns: usize, rows: usize, align: usize) -> Option<Vec<Crop>> {
        let xs = edges(width, columns, align)?;
        let ys = edges(height, rows, align)?;
        Some(
            ys.windows(2)
                .flat_map(|y| xs.windows(2).map(move |x| Crop { x0: x[0], y0: y[0], x1: x[1], y1: y[1] }))
                .collect(),
        )
    }

    /// The frame in crops of `size`×`size` pixels, row by row (narrower at the right edge,
    /// shorter at the bottom).
    #[must_use]
    pub fn squares(width: usize, height: usize, size: usize) -> Vec<Crop> {
        let size = size.max(1);
        (0..height.div_ceil(size))
            .flat_map(|j| {
                (0..width.div_ceil(size)).map(move |i| Crop {
                    x0: i * size,
                    y0: j * size,
                    x1: ((i + 1) * size).min(width),
                    y1: ((j + 1) * size).min(height),
                })
            })
            .collect()
    }

    /// `count` crops of the frame: the `columns`×`rows` grid with `columns·rows = count`
    /// whose crops are the most nearly square. `None` when the frame has fewer pixels than that.
    #[must_use]
    pub fn split(width: usize, height: usize, count: usize, align: usize) -> Option<Vec<Crop>> {
        let squareness = |c: usize| {
            let r = count / c;
            let aspect = (width as f64 / c as f64) / (height as f64 / r as f64);
            aspect.ln().abs()
        };
        let columns = (1..=count)
            .filter(|c| count.is_multiple_of(*c))
            .min_by(|&a, &b| squareness(a).total_cmp(&squareness(b)))?;
        Self::grid(width, height, columns, count / columns, align)
    }
}

/// `parts + 1` increasing edges from 0 to `size`, on multiples of `align` when that leaves no
/// part empty.
fn edges(size: usize, parts: usize, align: usize) -> Option<Vec<usize>> {
    if parts == 0 || parts > size {
        return None;
    }
    let even: Vec<usize> = (0..=parts).map(|i| i * size / parts).collect();
    let aligned: Vec<usize> =
        even.iter().map(|&e| if e == size { size } else { (e + align / 2) / align.max(1) * align.max(1) }).collect();
    Some(if aligned.windows(2).all(|w| w[0] < w[1]) { aligned } else { even })
}

impl fmt::Display for Crop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crop_parses_and_is_checked_against_the_frame() {
        let c = Crop::parse("8, 4,40,30").unwrap();
        assert_eq!(c, Crop { x0: 8, y0: 4, x1: 40, y1: 30 });
        assert_eq!(c.to_string(), "8,4,40,30");
        assert_eq!(c.check(64, 48), Ok(c));
        assert!(matches!(Crop::parse("1,2,3"), Err(CropError::Syntax(_))));
        assert!(matches!(Crop::parse("1,2,3,4,5"), Err(CropError::Syntax(_))));
        assert!(matches!(Crop::parse("-1,2,3,4"), Err(CropError::Syntax(_))));
        assert!(matches!(Crop::parse("4,0,4,8").unwrap().check(64, 48), Err(CropError::Empty(_))));
        assert!(matches!(Crop::parse("9,0,4,8").unwrap().check(64, 48), Err(CropError::Empty(_))));
        assert!(matches!(Crop::parse("0,0,65,8").unwrap().check(64, 48), Err(CropError::Outside { .. })));
    }

    #[test]
    fn a_split_covers_every_pixel_once_on_tile_edges() {
        for (w, h, n) in [(64, 48, 4), (1920, 1080, 16), (640, 480, 64), (33, 7, 6), (5, 5, 25)] {
            let crops = Crop::split(w, h, n, 16).unwrap();
            assert_eq!(crops.len(), n);
            let mut seen = vec![0u8; w * h];
            for c in &crops {
                for y in c.y0..c.y1 {
                    for x in c.x0..c.x1 {
                        seen[y * w + x] += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{w}×{h} in {n}");
        }
        let squares = Crop::squares(64, 48, 20);
        assert_eq!(squares.len(), 12);
        assert_eq!(
            (squares[3], squares[11]),
            (Crop::parse("60,0,64,20").unwrap(), Crop::parse("60,40,64,48").unwrap())
        );
        let crops = Crop::split(1920, 1080, 16, 16).unwrap();
        assert!(crops.iter().all(|c| c.x0 % 16 == 0 && c.y0 % 16 == 0), "{crops:?}");
        assert!(Crop::split(4, 4, 32, 16).is_none());
    }
}
