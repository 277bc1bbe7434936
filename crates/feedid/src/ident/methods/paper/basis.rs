//! The scaled basis of a window (see the module doc of the method):
//! Legendre polynomials in `s = (τ − τ_c)/h ∈ [−1, 1]`, unit-norm columns,
//! and the exact change of basis back to monomials in `τ`.

use super::polynomials::NQ;

/// Legendre recurrence factors `(2k+1)/(k+1)` and `k/(k+1)`, `k = 0 … 6`.
pub(super) const LEGENDRE_A: [f64; NQ - 1] =
    [1.0, 1.5, 5.0 / 3.0, 1.75, 1.8, 11.0 / 6.0, 13.0 / 7.0];
pub(super) const LEGENDRE_B: [f64; NQ - 1] = [0.0, 0.5, 2.0 / 3.0, 0.75, 0.8, 5.0 / 6.0, 6.0 / 7.0];

/// Coefficients (powers of `s`) of the Legendre polynomials `L_0 … L_7`:
/// `L_k(s) = Σ_j table[k][j]·s^j`.
pub(super) fn legendre_monomials() -> [[f64; NQ]; NQ] {
    let mut t = [[0.0; NQ]; NQ];
    t[0][0] = 1.0;
    t[1][1] = 1.0;
    for k in 1..NQ - 1 {
        for j in 0..NQ {
            let shifted = if j > 0 { t[k][j - 1] } else { 0.0 };
            t[k + 1][j] = ((2 * k + 1) as f64 * shifted - k as f64 * t[k - 1][j]) / (k + 1) as f64;
        }
    }
    t
}

/// Coefficients in powers of `τ` of `Σ_j m_j·((τ − c)/h)^j` (Horner in
/// polynomial arithmetic); `out.len() == m.len()`.
pub(super) fn affine_to_monomial(m: &[f64], c: f64, h: f64, out: &mut [f64]) {
    let n = m.len();
    for v in out.iter_mut() {
        *v = 0.0;
    }
    // multiplications by 1/h and c/h instead of two divisions per term
    let (ih, ch) = (1.0 / h, c / h);
    for j in (0..n).rev() {
        // out ← out·(τ/h − c/h) + m_j
        for i in (0..n).rev() {
            let lower = if i > 0 { out[i - 1] } else { 0.0 };
            out[i] = lower * ih - out[i] * ch;
        }
        out[0] += m[j];
    }
}

/// Scale `v` to unit 2-norm and return the norm (1 for a zero vector, which is kept).
#[cfg(test)]
pub(super) fn normalise(v: &mut [f64]) -> f64 {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n > 0.0 && n.is_finite() {
        let inv = 1.0 / n;
        for x in v.iter_mut() {
            *x *= inv;
        }
        n
    } else {
        1.0
    }
}
