//! Hierarchical sample warping: one step down a quadtree of non-negative masses.
//!
//! A point ξ ∈ [0, 1)² picks the column (left/right) with ξ.x by the ratio of the column sums,
//! is rescaled into the chosen side, then picks the row with ξ.y the same way. Repeated from the
//! root, the leaf is reached with probability ∝ its mass, and the rescaled ξ is again uniform
//! inside it, so it can keep going down the next hierarchy (the env mip levels below a B̃ leaf).
//! The state is f64: each level costs about one bit per axis (more where the mass is skewed),
//! and 13 levels of an 8192² map would leave an f32 almost nothing for the in-texel position.

use glam::DVec2;

/// Largest f64 below 1.
pub const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// Children are numbered `dx + 2·dy`: 0 = (0,0), 1 = (1,0), 2 = (0,1), 3 = (1,1), where
/// dx steps along u and dy along v.
#[inline(always)]
#[must_use]
pub fn child_offset(child: usize) -> (u32, u32) {
    ((child & 1) as u32, (child >> 1) as u32)
}

/// Picks a child with probability ∝ its mass and rescales `xi` to be uniform inside it.
/// Returns `None` when all four masses are zero. A child of zero mass is never chosen.
#[inline]
pub fn choose_child(mass: [f32; 4], xi: &mut DVec2) -> Option<usize> {
    let m = mass.map(f64::from);
    let left = m[0] + m[2];
    let right = m[1] + m[3];
    let total = left + right;
    if total <= 0.0 || total.is_nan() {
        return None;
    }
    let dx = pick(left, right, total, &mut xi.x);
    let (top, bottom) = (m[dx], m[dx + 2]);
    let dy = pick(top, bottom, top + bottom, &mut xi.y);
    Some(dx + 2 * dy)
}

/// Chooses side 0 with probability a/total (side 1 otherwise) and rescales `x` into it.
/// One division: t = x·total is compared against a, then divided by the chosen side's mass.
#[inline(always)]
fn pick(a: f64, b: f64, total: f64, x: &mut f64) -> usize {
    let t = *x * total;
    if (t < a && a > 0.0) || b <= 0.0 {
        *x = (t / a).clamp(0.0, ONE_MINUS_EPSILON);
        0
    } else {
        *x = ((t - a) / b).clamp(0.0, ONE_MINUS_EPSILON);
        1
    }
}

/// Places a uniform point `xi` ∈ [0,1)² inside cell `(x, y)` of a `2^level` grid, returning
/// square coordinates that are guaranteed to lie in that cell (f32 rounding could otherwise
/// push a point onto the next cell's edge).
#[inline]
#[must_use]
pub fn point_in_cell(x: u32, y: u32, level: u32, xi: DVec2) -> glam::Vec2 {
    // 2^−level exactly, without a division.
    let inv = f64::from_bits((1023 - level as u64) << 52);
    let coord = |i: u32, f: f64| -> f32 {
        let lo = (i as f64 * inv) as f32; // exact: dyadic
        let hi = ((i + 1) as f64 * inv) as f32;
        let c = ((i as f64 + f) * inv) as f32;
        if c >= hi { next_down(hi).max(lo) } else { c.max(lo) }
    };
    glam::Vec2::new(coord(x, xi.x), coord(y, xi.y))
}

/// The largest f32 below a positive finite `x`.
#[inline]
fn next_down(x: f32) -> f32 {
    if x <= 0.0 { x } else { f32::from_bits(x.to_bits() - 1) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_mass_child_is_never_picked() {
        for &x in &[0.0, 0.25, 0.5, ONE_MINUS_EPSILON] {
            for &y in &[0.0, 0.5, ONE_MINUS_EPSILON] {
                let mut xi = DVec2::new(x, y);
                let c = choose_child([0.0, 0.0, 0.0, 2.0], &mut xi).unwrap();
                assert_eq!(c, 3);
                let mut xi = DVec2::new(x, y);
                let c = choose_child([1.0, 0.0, 0.0, 0.0], &mut xi).unwrap();
                assert_eq!(c, 0);
                assert!((0.0..1.0).contains(&xi.x) && (0.0..1.0).contains(&xi.y));
            }
        }
        assert!(choose_child([0.0; 4], &mut DVec2::ZERO.clone()).is_none());
    }

    #[test]
    fn rescaled_point_is_uniform_in_the_child() {
        let mut xi = DVec2::new(0.75, 0.5);
        let c = choose_child([1.0, 1.0, 1.0, 1.0], &mut xi).unwrap();
        assert_eq!(c, 1 + 2);
        assert!((xi - DVec2::new(0.5, 0.0)).abs().max_element() < 1e-15);
    }

    #[test]
    fn points_stay_inside_their_cell() {
        let p = point_in_cell(8191, 8191, 13, DVec2::splat(ONE_MINUS_EPSILON));
        assert!(p.x < 1.0 && p.y < 1.0);
        assert_eq!(crate::mapping::texel_of(p, 8192), (8191, 8191));
        let p = point_in_cell(5, 0, 3, DVec2::new(ONE_MINUS_EPSILON, 0.0));
        assert_eq!(crate::mapping::texel_of(p, 8), (5, 0));
    }
}
