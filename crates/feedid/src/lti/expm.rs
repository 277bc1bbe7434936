//! Matrix exponential by scaling and squaring with the degree-13 Padé
//! approximant (Higham 2005), applied to the balanced matrix.
//!
//! e^M = D·e^{D⁻¹MD}·D⁻¹ with D the power-of-2 balancing scaling, so the
//! similarity is exact; balancing lowers ‖M‖₁ and hence the number of
//! squarings and the rounding error. With θ₁₃ = 5.37 and s = ⌈log₂(‖M‖₁/θ₁₃)⌉
//! the Padé approximant r₁₃(M/2ˢ) is accurate to unit roundoff, then squared
//! s times.
//!
//! Reference: N.J. Higham, "The scaling and squaring method for the matrix
//! exponential revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005.

use nalgebra::DMatrix;

use super::balance::{apply_similarity, balance_scaling, undo_similarity};
use crate::error::{Error, Result};

/// Padé-13 coefficients b₀ … b₁₃.
const B13: [f64; 14] = [
    64_764_752_532_480_000.0,
    32_382_376_266_240_000.0,
    7_771_770_303_897_600.0,
    1_187_353_796_428_800.0,
    129_060_195_264_000.0,
    10_559_470_521_600.0,
    670_442_572_800.0,
    33_522_128_640.0,
    1_323_241_920.0,
    40_840_800.0,
    960_960.0,
    16_380.0,
    182.0,
    1.0,
];
/// Largest ‖M‖₁ for which r₁₃(M) is accurate to unit roundoff.
const THETA13: f64 = 5.371_920_351_148_152;

/// e^M of a real square matrix, computed on the balanced matrix.
pub(crate) fn expm(m: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = m.nrows();
    if m.ncols() != n {
        return Err(Error::LengthMismatch {
            what: "matrix exponential columns",
            expected: n,
            actual: m.ncols(),
        });
    }
    if m.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "non-finite matrix entry in matrix exponential",
        });
    }
    if n == 0 {
        return Ok(DMatrix::zeros(0, 0));
    }
    let d = balance_scaling(m, n);
    let mb = apply_similarity(m, &d);
    let eb = expm_pade13(&mb)?;
    Ok(undo_similarity(&eb, &d))
}

/// One-norm (maximum absolute column sum).
fn norm1(m: &DMatrix<f64>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Scaling and squaring with r₁₃, no balancing.
fn expm_pade13(m: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let n = m.nrows();
    let norm = norm1(m);
    // finite entries can still sum to an infinite norm: that would ask for
    // i32::MAX squarings (a hang), and the exponential overflows anyway
    if !norm.is_finite() {
        return Err(Error::InvalidModel {
            reason: "matrix exponential overflowed",
        });
    }
    let s = if norm > THETA13 {
        (norm / THETA13).log2().ceil().max(0.0) as i32
    } else {
        0
    };
    let a = m * 2f64.powi(-s);
    let id = DMatrix::<f64>::identity(n, n);
    let a2 = &a * &a;
    let a4 = &a2 * &a2;
    let a6 = &a4 * &a2;
    let b = &B13;
    let u_inner = &a6 * (&a6 * b[13] + &a4 * b[11] + &a2 * b[9])
        + &a6 * b[7]
        + &a4 * b[5]
        + &a2 * b[3]
        + &id * b[1];
    let u = &a * u_inner;
    let v = &a6 * (&a6 * b[12] + &a4 * b[10] + &a2 * b[8])
        + &a6 * b[6]
        + &a4 * b[4]
        + &a2 * b[2]
        + &id * b[0];
    let p = &v + &u;
    let q = &v - &u;
    let mut r = q.lu().solve(&p).ok_or(Error::Singular {
        context: "matrix exponential (Padé denominator)",
    })?;
    for _ in 0..s {
        r = &r * &r;
    }
    if r.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "matrix exponential overflowed",
        });
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm_of_a_matrix_whose_norm_overflows_is_an_error_not_a_hang() {
        let m = DMatrix::from_element(3, 3, -1e308);
        assert!(matches!(expm(&m), Err(Error::InvalidModel { .. })));
        // large but finite norm: at most ~1000 squarings, then a clean result or error
        let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![-1e300, -1.0]));
        if let Ok(e) = expm(&m) {
            assert!(e.iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn expm_of_diagonal_matrix_is_elementwise_exp() {
        let m =
            DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![-1e-3, -2.0, -350.0, 0.5]));
        let e = expm(&m).unwrap();
        for i in 0..4 {
            let want = m[(i, i)].exp();
            // s squarings amplify the relative error of r13 by at most 2^s (here 2^7).
            assert!((e[(i, i)] - want).abs() <= 1e-12 * want, "{i}");
            assert_eq!(e[(i, (i + 1) % 4)], 0.0);
        }
    }

    #[test]
    fn expm_of_rotation_generator_is_rotation() {
        let w = 37.0;
        let m = DMatrix::from_row_slice(2, 2, &[0.0, w, -w, 0.0]);
        let e = expm(&m).unwrap();
        let want = [w.cos(), w.sin(), -w.sin(), w.cos()];
        for (k, wv) in want.iter().enumerate() {
            assert!((e[(k / 2, k % 2)] - wv).abs() < 1e-13, "{k}");
        }
    }

    #[test]
    fn expm_of_nilpotent_jordan_block_is_truncated_series() {
        // [[0, a], [0, 0]] with a widely scaled entry: e^M = [[1, a], [0, 1]].
        let m = DMatrix::from_row_slice(2, 2, &[0.0, 1e12, 0.0, 0.0]);
        let e = expm(&m).unwrap();
        assert_eq!(e[(0, 0)], 1.0);
        assert!((e[(0, 1)] - 1e12).abs() < 1e-3);
        assert_eq!(e[(1, 0)], 0.0);
        assert_eq!(e[(1, 1)], 1.0);
    }
}
