//! Point sets in [0, 1)² that drive the warps: stratified (jittered grid), Poisson-disk-like
//! (Mitchell's best candidate) and a scrambled (0,2)-sequence (the first two Sobol' dimensions
//! with Owen scrambling, which keeps every elementary-interval stratification). All are written
//! into caller-provided slices; doubles carry 32 random bits, which the deep warps need.

mod sobol;
mod sobol_x4;

pub use sobol::{Sobol02, nested_uniform_scramble, sobol_dim0, sobol_dim1, sobol02, sobol02_shifted};

use crate::rng::Pcg32;
use glam::DVec2;

const INV_2_32: f64 = 1.0 / 4_294_967_296.0;

/// Jittered grid of `out.len()` points: rows × cols with rows·cols = n and the grid as square
/// as n's divisors allow.
pub fn stratified(rng: &mut Pcg32, out: &mut [DVec2]) {
    let n = out.len();
    if n == 0 {
        return;
    }
    let mut rows = libm::sqrt(n as f64) as usize;
    while rows > 1 && !n.is_multiple_of(rows) {
        rows -= 1;
    }
    let rows = rows.max(1);
    let cols = n / rows;
    for (k, p) in out.iter_mut().enumerate() {
        let (i, j) = (k % cols, k / cols);
        let jx = rng.next_u32() as f64 * INV_2_32;
        let jy = rng.next_u32() as f64 * INV_2_32;
        *p = DVec2::new((i as f64 + jx) / cols as f64, (j as f64 + jy) / rows as f64);
    }
}

/// Mitchell's best-candidate points (toroidal distance): each new point is the farthest of
/// `candidates × (points so far + 1)` uniform candidates. O(n²); meant for n ≲ 256.
pub fn best_candidate(rng: &mut Pcg32, candidates: usize, out: &mut [DVec2]) {
    let candidates = candidates.max(1);
    for k in 0..out.len() {
        let mut best = DVec2::ZERO;
        let mut best_d = -1.0;
        for _ in 0..candidates * (k + 1) {
            let c = DVec2::new(rng.next_u32() as f64 * INV_2_32, rng.next_u32() as f64 * INV_2_32);
            let mut d_min = f64::INFINITY;
            for q in &out[..k] {
                let mut d = (c - *q).abs();
                d = d.min(DVec2::ONE - d);
                d_min = d_min.min(d.length_squared());
            }
            if d_min > best_d {
                best_d = d_min;
                best = c;
            }
        }
        out[k] = best;
    }
}

/// Element `i` of a pseudo-random permutation of `0 .. n` chosen by `seed` (Kensler 2013,
/// "Correlated multi-jittered sampling": an invertible hash on the next power of two, walked
/// until it lands below `n`). Pairs the runs of one sequence with the points of another
/// without the digit correlation that equal indices into two (0,2)-sequences would have.
#[must_use]
pub fn permutation_element(mut i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(i < n);
    let mut w = n.wrapping_sub(1);
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    let p = seed;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            return (i.wrapping_add(p)) % n;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutation_element_is_a_permutation() {
        for n in [1u32, 2, 3, 7, 16, 64, 100, 1000] {
            for seed in [0u32, 1, 0xdead_beef] {
                let mut seen = [false; 1000];
                for i in 0..n {
                    let j = permutation_element(i, n, seed) as usize;
                    assert!(j < n as usize && !seen[j], "n {n} seed {seed} i {i} -> {j}");
                    seen[j] = true;
                }
            }
        }
        // Different seeds give different orders.
        let a: [u32; 8] = core::array::from_fn(|i| permutation_element(i as u32, 8, 1));
        let b: [u32; 8] = core::array::from_fn(|i| permutation_element(i as u32, 8, 2));
        assert_ne!(a, b);
    }

    #[test]
    fn stratified_covers_every_stratum() {
        let mut rng = Pcg32::new(1, 2);
        let mut pts = [DVec2::ZERO; 12];
        stratified(&mut rng, &mut pts);
        let mut seen = [false; 12]; // 3 rows × 4 cols
        for p in pts {
            seen[(p.x * 4.0) as usize + 4 * (p.y * 3.0) as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn best_candidate_spreads_points() {
        let mut rng = Pcg32::new(3, 4);
        let mut pts = [DVec2::ZERO; 32];
        best_candidate(&mut rng, 10, &mut pts);
        let mut d_min = f64::INFINITY;
        for i in 0..32 {
            for j in 0..i {
                d_min = d_min.min((pts[i] - pts[j]).length());
            }
        }
        // Uniform random 32 points have min distance ~0.03; best candidate ≳ 0.08.
        assert!(d_min > 0.06, "{d_min}");
    }
}
