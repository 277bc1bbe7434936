//! The paper's polynomial models (eq. 4–6): the closed loop `N(s)/D(s)`
//! divided by `s⁸` read as Laplace transforms, whose inverses are the output
//! polynomial `P5·τ⁵ + P6·τ⁶ + P7·τ⁷` and the input polynomial
//! `Σ Q_i·τⁱ`, and the map between their coefficients and `N2 … D0`.

/// Number of output-model coefficients (`P5, P6, P7`).
pub(super) const NP: usize = 3;
/// Number of input-model coefficients (`Q0 … Q7`).
pub(super) const NQ: usize = 8;
/// Number of identified coefficients (`N2, N1, N0, D7 … D0`).
pub(super) const NC: usize = NP + NQ;
/// `i!` for `i = 0 … 7`.
pub(super) const FACT: [f64; 8] = [1.0, 1.0, 2.0, 6.0, 24.0, 120.0, 720.0, 5040.0];
pub(super) const NAMES: [&str; NC] = [
    "N2", "N1", "N0", "D7", "D6", "D5", "D4", "D3", "D2", "D1", "D0",
];

/// Map the polynomial coefficients `P = [P5, P6, P7]` and `Q = [Q0, …, Q7]`
/// of eq. (6) to `[N2, N1, N0, D7, D6, …, D0]`:
/// `N2 = 120·P5`, `N1 = 720·P6`, `N0 = 5040·P7`, `D_{7−i} = i!·Q_i`.
pub fn coefficients_from_polynomials(p: [f64; 3], q: [f64; 8]) -> [f64; 11] {
    let mut c = [0.0; NC];
    c[0] = FACT[5] * p[0];
    c[1] = FACT[6] * p[1];
    c[2] = FACT[7] * p[2];
    for i in 0..NQ {
        c[NP + i] = FACT[i] * q[i];
    }
    c
}

/// Inverse of [`coefficients_from_polynomials`]: `[N2, N1, N0, D7, …, D0]` →
/// (`[P5, P6, P7]`, `[Q0, …, Q7]`) with `P5 = N2/120`, `P6 = N1/720`,
/// `P7 = N0/5040`, `Q_i = D_{7−i}/i!`.
pub fn polynomials_from_coefficients(c: &[f64; 11]) -> ([f64; 3], [f64; 8]) {
    let p = [c[0] / FACT[5], c[1] / FACT[6], c[2] / FACT[7]];
    let mut q = [0.0; NQ];
    for i in 0..NQ {
        q[i] = c[NP + i] / FACT[i];
    }
    (p, q)
}
