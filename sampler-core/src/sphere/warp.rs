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
    child_by(mass, xi, pick::<2>)
}

/// Two levels in one step: picks one of the 16 grandchildren of a node (`mass` in Morton
/// order: index `x0 | y0 << 1 | x1 << 2 | y1 << 3` for the cell at column `2·x1 + x0`, row
/// `2·y1 + y0`) with probability ∝ its mass — the column by ξ.x over the four column sums,
/// then the row within it by ξ.y — and rescales `xi` into it. Returns the Morton index and
/// the cell's (column, row). The 16 masses are one cache line of the packed pyramid, and the
/// chain of dependent steps is half as long as two [`choose_child`] calls.
#[inline]
pub fn choose_grandchild(mass: &[f32; 16], xi: &mut DVec2) -> Option<(usize, u32, u32)> {
    grandchild_by(mass, xi, pick::<4>)
}

/// Index of grandchild (column x, row y) ∈ [0, 4)² in the Morton order of
/// [`choose_grandchild`]: `x0 | y0 << 1 | x1 << 2 | y1 << 3`.
#[inline(always)]
#[must_use]
pub fn grandchild_index(x: u32, y: u32) -> usize {
    ((x & 1) | (y & 1) << 1 | (x >> 1) << 2 | (y >> 1) << 3) as usize
}

/// Probability that `choose_grandchild` picks grandchild `k` of masses `mass`.
#[inline]
pub(crate) fn grandchild_probability(mass: &[f32; 16], k: usize) -> f64 {
    let total: f64 = mass.iter().map(|&m| f64::from(m)).sum();
    if total > 0.0 { f64::from(mass[k]) / total } else { 0.0 }
}

/// [`choose_grandchild`] without data-dependent branches (the same choice and rescaling for
/// every input with some mass), for interleaving several descents: alone, its chain of
/// dependent arithmetic is slower than a predicted branch; four chains side by side are not
/// (docs/tuning.md#batched-and-branch-free-sampling).
#[inline(always)]
pub fn choose_grandchild_branchless(mass: &[f32; 16], xi: &mut DVec2) -> Option<(usize, u32, u32)> {
    grandchild_by(mass, xi, pick_branchless::<4>)
}

/// [`choose_child`] without data-dependent branches (the same choice for every input with
/// some mass; ξ may differ in its last bits), for descents run side by side.
#[inline(always)]
pub fn choose_child_branchless(mass: [f32; 4], xi: &mut DVec2) -> Option<usize> {
    child_by(mass, xi, pick_branchless::<2>)
}

/// The column by ξ.x, then the row within it by ξ.y, each by `pick`; see [`choose_child`].
#[inline(always)]
fn child_by(mass: [f32; 4], xi: &mut DVec2, pick: Pick<2>) -> Option<usize> {
    let m = mass.map(f64::from);
    let (dx, ox, wx) = pick([m[0] + m[2], m[1] + m[3]], xi.x)?;
    let (dy, oy, wy) = pick([m[dx], m[dx + 2]], xi.y)?;
    rescale(xi, ox, wx, oy, wy);
    Some(dx + 2 * dy)
}

/// A side chooser: (weights, ξ) → (side, ξ's offset into it, its weight).
type Pick<const N: usize> = fn([f64; N], f64) -> Option<(usize, f64, f64)>;

/// The column, then the row within it, each by `pick`; see [`choose_grandchild`].
#[inline(always)]
fn grandchild_by(mass: &[f32; 16], xi: &mut DVec2, pick: Pick<4>) -> Option<(usize, u32, u32)> {
    let m = mass.map(f64::from);
    let at = |x: usize, y: usize| grandchild_index(x as u32, y as u32);
    let cols: [f64; 4] = core::array::from_fn(|x| (m[at(x, 0)] + m[at(x, 1)]) + (m[at(x, 2)] + m[at(x, 3)]));
    let (x, ox, wx) = pick(cols, xi.x)?;
    let rows: [f64; 4] = core::array::from_fn(|y| m[at(x, y)]);
    let (y, oy, wy) = pick(rows, xi.y)?;
    rescale(xi, ox, wx, oy, wy);
    Some((at(x, y), x as u32, y as u32))
}

/// Chooses side i with probability w[i]/Σw by t = x·Σw; returns it, t's offset into it and
/// its weight, or `None` if Σw is not positive. A side of zero weight is never chosen, even
/// when rounding pushes t past the end. (Branching, for one descent: with a branch-free count
/// of prefix sums the address of the next level's load waits for the arithmetic, where a
/// predicted branch lets the load start early; docs/tuning.md#batched-and-branch-free-sampling.)
#[inline(always)]
fn pick<const N: usize>(w: [f64; N], x: f64) -> Option<(usize, f64, f64)> {
    let total = w.iter().sum::<f64>();
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let t = x * total;
    let (mut acc, mut last, mut last_acc) = (0.0, 0, 0.0);
    for (i, &wi) in w.iter().enumerate() {
        if wi > 0.0 {
            if t < acc + wi {
                return Some((i, t - acc, wi));
            }
            (last, last_acc) = (i, acc);
        }
        acc += wi;
    }
    Some((last, t - last_acc, w[last]))
}

/// [`pick`] by a count of prefix sums below t (N ≤ 4).
#[inline(always)]
fn pick_branchless<const N: usize>(w: [f64; N], x: f64) -> Option<(usize, f64, f64)> {
    let mut prefix = [0.0; 4];
    for i in 1..N {
        prefix[i] = prefix[i - 1] + w[i - 1];
    }
    let total = prefix[N - 1] + w[N - 1];
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let t = x * total;
    let i = (1..N).map(|j| (t >= prefix[j]) as usize).sum::<usize>();
    if w[i] > 0.0 {
        Some((i, t - prefix[i], w[i]))
    } else {
        // Rounding put t at the total with trailing empty sides: the last side with mass.
        let i = (0..N).rev().find(|&j| w[j] > 0.0)?;
        Some((i, t - prefix[i], w[i]))
    }
}

/// `xi = (ox / wx, oy / wy)` clamped to [0, 1) — with one division instead of two.
#[inline(always)]
fn rescale(xi: &mut DVec2, ox: f64, wx: f64, oy: f64, wy: f64) {
    let r = 1.0 / (wx * wy);
    xi.x = (ox * wy * r).clamp(0.0, ONE_MINUS_EPSILON);
    xi.y = (oy * wx * r).clamp(0.0, ONE_MINUS_EPSILON);
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
    fn grandchild_follows_the_mass_and_rescales() {
        // Uniform masses: ξ = (0.6, 0.3) lands in column 2, row 1 at (0.4, 0.2) inside it.
        let mut xi = DVec2::new(0.6, 0.3);
        let (c, x, y) = choose_grandchild(&[1.0; 16], &mut xi).unwrap();
        assert_eq!((x, y), (2, 1));
        assert_eq!(c, 2 | 4);
        assert!((xi - DVec2::new(0.4, 0.2)).abs().max_element() < 1e-12);
        // A single massive cell is always chosen, whatever ξ.
        for &u in &[0.0, 0.3, ONE_MINUS_EPSILON] {
            let mut m = [0.0f32; 16];
            m[13] = 5.0; // x0 = 1, y0 = 0, x1 = 1, y1 = 1: column 3, row 2
            let mut xi = DVec2::new(u, 1.0 - u.max(1e-9));
            assert_eq!(choose_grandchild(&m, &mut xi).unwrap(), (13, 3, 2));
            assert!((0.0..1.0).contains(&xi.x) && (0.0..1.0).contains(&xi.y));
        }
        assert!(choose_grandchild(&[0.0; 16], &mut DVec2::ZERO.clone()).is_none());
        assert!(choose_grandchild(&[f32::NAN; 16], &mut DVec2::ZERO.clone()).is_none());
    }

    #[test]
    fn rescaled_point_is_uniform_in_the_child() {
        let mut xi = DVec2::new(0.75, 0.5);
        let c = choose_child([1.0, 1.0, 1.0, 1.0], &mut xi).unwrap();
        assert_eq!(c, 1 + 2);
        assert!((xi - DVec2::new(0.5, 0.0)).abs().max_element() < 1e-15);
    }
}
