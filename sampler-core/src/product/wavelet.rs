//! The wavelet product (Clarberg, Jarosz, Akenine-Möller & Jensen 2005, "Wavelet importance
//! sampling"): the node averages of a product computed from the nonstandard 2D Haar expansions
//! of its two factors.
//!
//! On one node, with the children numbered `c = dx + 2·dy`, a function's four child means `f_c`
//! have the Haar coefficients `a = mean f_c` and `a_i = mean(f_c·ψ_i(c))` for the three sign
//! patterns ψ₁ = (+,−,+,−) (along u), ψ₂ = (+,+,−,−) (along v), ψ₃ = (+,−,−,+) (diagonal). The
//! patterns are orthonormal under the mean, so for two functions f, g that are constant on the
//! children  mean(f_c·g_c) = a·b + Σ a_i·b_i. Finer detail adds the children's own correlation
//! terms C_c = P_c − f_c·g_c, so the product's mean on the node is
//!
//!   P = a·b + Σᵢ aᵢ·bᵢ + mean_c C_c,
//!
//! evaluated bottom-up. Below a B̃ leaf B̃ has no detail, so C = 0 there and the recursion stops
//! at the leaves of the BRDF tree. The environment's coefficients come from its mip pyramid
//! (the pyramid *is* the scaling part of its Haar transform).

const PSI: [[f32; 4]; 3] = [[1.0, -1.0, 1.0, -1.0], [1.0, 1.0, -1.0, -1.0], [1.0, -1.0, -1.0, 1.0]];

/// Haar coefficients (scaling, three wavelets) of four child means.
#[inline]
#[must_use]
pub fn haar_coefficients(f: [f32; 4]) -> (f32, [f32; 3]) {
    let mean = 0.25 * ((f[0] + f[1]) + (f[2] + f[3]));
    let w = PSI.map(|psi| 0.25 * ((f[0] * psi[0] + f[1] * psi[1]) + (f[2] * psi[2] + f[3] * psi[3])));
    (mean, w)
}

/// Mean of the product on a node from the child means of both factors (`b`, `l`) and the
/// children's product means `p` (which carry the finer detail).
#[inline]
#[must_use]
pub fn haar_product_mean(b: [f32; 4], l: [f32; 4], p: [f32; 4]) -> f32 {
    let (ab, wb) = haar_coefficients(b);
    let (al, wl) = haar_coefficients(l);
    let detail = 0.25 * (((p[0] - b[0] * l[0]) + (p[1] - b[1] * l[1])) + ((p[2] - b[2] * l[2]) + (p[3] - b[3] * l[3])));
    let p = ab * al + (wb[0] * wl[0] + wb[1] * wl[1] + wb[2] * wl[2]) + detail;
    p.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equals_the_mean_of_child_products() {
        let b = [1.0, 0.0, 3.0, 2.0];
        let l = [0.5, 4.0, 0.25, 8.0];
        let p = [b[0] * l[0], b[1] * l[1], b[2] * l[2], b[3] * l[3]];
        let direct = 0.25 * p.iter().sum::<f32>();
        assert!((haar_product_mean(b, l, p) - direct).abs() < 1e-6);
        // With finer detail (children's products differ from b·l).
        let p2 = [p[0] + 1.0, p[1], p[2] + 0.5, p[3]];
        let direct2 = 0.25 * p2.iter().sum::<f32>();
        assert!((haar_product_mean(b, l, p2) - direct2).abs() < 1e-6);
    }
}
