//! Discrete-time SISO state-space model x\[k+1\] = A_d·x\[k\] + B_d·u\[k\],
//! y\[k\] = C·x\[k\] + D·u\[k\], usually the exact zero-order-hold image of a
//! continuous model ([`super::StateSpace::discretize_zoh`]).
//!
//! Simulation ([`DiscreteStateSpace::simulate_into`]) is allocation-free and
//! works column by column on the column-major A_d; it is the per-sample hot
//! path of the prediction engine. Poles are the eigenvalues of A_d (balanced
//! Hessenberg QR); stability means spectral radius < 1.

use nalgebra::{Complex, DMatrix, DVector, RowDVector};

use super::eig::eigenvalues;
use super::poly::sort_roots;
use super::ss::{check_dt, StateSpace};
use crate::error::{Error, Result};

/// A discrete-time SISO state-space model with its sample time.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteStateSpace {
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input vector.
    pub b: DVector<f64>,
    /// Output row.
    pub c: RowDVector<f64>,
    /// Feed-through.
    pub d: f64,
    /// Sample time \[s\].
    pub dt: f64,
}

impl DiscreteStateSpace {
    /// Build from parts, checking dimensions, finiteness and `dt` > 0 \[s\].
    pub fn from_parts(
        a: DMatrix<f64>,
        b: DVector<f64>,
        c: RowDVector<f64>,
        d: f64,
        dt: f64,
    ) -> Result<Self> {
        check_dt(dt)?;
        let ss = StateSpace::new(a, b, c, d)?;
        Ok(Self {
            a: ss.a,
            b: ss.b,
            c: ss.c,
            d: ss.d,
            dt,
        })
    }

    /// Number of states.
    pub fn order(&self) -> usize {
        self.a.nrows()
    }

    /// Output C·x + D·u for state `x` (length = order) and input `u`.
    pub fn output(&self, x: &[f64], u: f64) -> f64 {
        self.c
            .iter()
            .zip(x)
            .fold(self.d * u, |acc, (c, xi)| acc + c * xi)
    }

    /// One step x ← A·x + B·u (allocation-free; `scratch` has at least `order()` entries).
    pub fn advance(&self, x: &mut [f64], u: f64, scratch: &mut [f64]) -> Result<()> {
        let n = self.order();
        if x.len() != n {
            return Err(Error::LengthMismatch {
                what: "discrete state",
                expected: n,
                actual: x.len(),
            });
        }
        if scratch.len() < n {
            return Err(Error::LengthMismatch {
                what: "discrete simulation scratch",
                expected: n,
                actual: scratch.len(),
            });
        }
        self.advance_unchecked(x, u, &mut scratch[..n]);
        Ok(())
    }

    /// x ← A·x + B·u; lengths already checked (x and scratch have `order()` entries).
    fn advance_unchecked(&self, x: &mut [f64], u: f64, scratch: &mut [f64]) {
        for (s, b) in scratch.iter_mut().zip(self.b.iter()) {
            *s = b * u;
        }
        // A is column-major: accumulate column by column.
        for (col, &xj) in self.a.column_iter().zip(x.iter()) {
            if xj != 0.0 {
                for (s, aij) in scratch.iter_mut().zip(col.iter()) {
                    *s += aij * xj;
                }
            }
        }
        x.copy_from_slice(scratch);
    }

    /// Simulate in place: y\[k\] = C·x\[k\] + D·u\[k\], then x ← A·x + B·u\[k\].
    ///
    /// `x` holds the initial state on entry and the final state on exit;
    /// `y` must have the length of `u`, `scratch` at least `order()` entries.
    /// Allocates nothing.
    pub fn simulate_into(
        &self,
        u: &[f64],
        x: &mut [f64],
        y: &mut [f64],
        scratch: &mut [f64],
    ) -> Result<()> {
        let n = self.order();
        if x.len() != n {
            return Err(Error::LengthMismatch {
                what: "discrete state",
                expected: n,
                actual: x.len(),
            });
        }
        if y.len() != u.len() {
            return Err(Error::LengthMismatch {
                what: "simulation output",
                expected: u.len(),
                actual: y.len(),
            });
        }
        if scratch.len() < n {
            return Err(Error::LengthMismatch {
                what: "discrete simulation scratch",
                expected: n,
                actual: scratch.len(),
            });
        }
        let scratch = &mut scratch[..n];
        for (yk, &uk) in y.iter_mut().zip(u) {
            *yk = self.output(x, uk);
            self.advance_unchecked(x, uk, scratch);
        }
        Ok(())
    }

    /// Simulate from `x0` (or 0); returns y\[k\] for every input sample.
    ///
    /// ```
    /// use feedid::lti::TransferFunction;
    /// let g = TransferFunction::new(vec![1.0], vec![0.01, 1.0]).unwrap();
    /// let sys = g.to_state_space().unwrap().discretize_zoh(1e-3).unwrap();
    /// let y = sys.simulate(&[1.0; 5], None).unwrap();
    /// assert!((y[4] - (1.0 - (-0.4f64).exp())).abs() < 1e-12);
    /// ```
    pub fn simulate(&self, u: &[f64], x0: Option<&[f64]>) -> Result<Vec<f64>> {
        let n = self.order();
        let mut x = match x0 {
            Some(x0) => x0.to_vec(),
            None => vec![0.0; n],
        };
        let mut y = vec![0.0; u.len()];
        let mut scratch = vec![0.0; n];
        self.simulate_into(u, &mut x, &mut y, &mut scratch)?;
        Ok(y)
    }

    /// Poles: eigenvalues of A (dimensionless z-plane), sorted by modulus.
    pub fn poles(&self) -> Result<Vec<Complex<f64>>> {
        let mut p = eigenvalues(&self.a)?;
        sort_roots(&mut p);
        Ok(p)
    }

    /// Zeros, relative degree and gain: `(g, r, zeros)` with `g` the first
    /// non-zero Markov parameter (`D`, or `C·A^{r−1}·B`), `r` the delay in
    /// samples, and the `n − r` transmission zeros as the eigenvalues of the
    /// zero dynamics
    ///
    /// ```text
    /// N = A − B·(C·A^r)/(C·A^{r−1}·B)     (D = 0),     N = A − B·C/D   (D ≠ 0)
    /// ```
    ///
    /// without the `r` eigenvalues of `N` at 0 (the input that holds the
    /// output at zero leaves exactly the zero dynamics). Unlike the roots
    /// of the numerator polynomial, this keeps the zeros of a fast-sampled
    /// model, clustered near `z = 1`, accurate. A Markov parameter below
    /// 1e-10 of the largest of the first `n + 1` counts as zero; no non-zero
    /// one is an error.
    ///
    /// ```
    /// use feedid::lti::TransferFunction;
    /// // 1/(s + 1) sampled at 0.1 s: no zero, one sample of delay
    /// let sys = TransferFunction::new(vec![1.0], vec![1.0, 1.0]).unwrap()
    ///     .to_state_space().unwrap().discretize_zoh(0.1).unwrap();
    /// let (g, r, z) = sys.zeros().unwrap();
    /// assert_eq!((r, z.len()), (1, 0));
    /// assert!((g - (1.0 - (-0.1f64).exp())).abs() < 1e-12);
    /// ```
    pub fn zeros(&self) -> Result<(f64, usize, Vec<Complex<f64>>)> {
        let n = self.order();
        let sys =
            StateSpace::new(self.a.clone(), self.b.clone(), self.c.clone(), self.d)?.balance();
        let (a, b, c) = (&sys.a, &sys.b, &sys.c);
        // Markov parameters C·A^{k−1}·B, k = 1 … n + 1
        let mut v = b.clone();
        let mut markov = Vec::with_capacity(n + 1);
        for _ in 0..=n {
            markov.push((c * &v)[(0, 0)]);
            v = a * &v;
        }
        let largest = markov.iter().fold(self.d.abs(), |m, h| m.max(h.abs()));
        if !(largest.is_finite() && largest > 0.0) {
            return Err(Error::InvalidModel {
                reason: "the model's output does not depend on its input",
            });
        }
        if self.d.abs() > 1e-10 * largest {
            let nz = a - (b * c) / self.d;
            let mut z = eigenvalues(&nz)?;
            sort_roots(&mut z);
            return Ok((self.d, 0, z));
        }
        let Some(r) = markov
            .iter()
            .position(|h| h.abs() > 1e-10 * largest)
            .map(|k| k + 1)
        else {
            return Err(Error::InvalidModel {
                reason: "the model's output does not depend on its input",
            });
        };
        if r > n {
            return Ok((markov[r - 1], r, Vec::new()));
        }
        let g = markov[r - 1];
        // C·A^r
        let mut car = c.clone();
        for _ in 0..r {
            car = &car * a;
        }
        let nz = a - (b * car) / g;
        let mut z = eigenvalues(&nz)?;
        sort_roots(&mut z);
        // the r smallest are the zero dynamics' eigenvalues at 0; rounding
        // may have paired one of them with a small real zero: a root whose
        // conjugate went with them is real
        let mut z = z.split_off(r.min(z.len()));
        let unpaired: Vec<usize> = (0..z.len())
            .filter(|&i| z[i].im != 0.0 && !z.iter().any(|w| *w == z[i].conj()))
            .collect();
        for i in unpaired {
            z[i].im = 0.0;
        }
        Ok((g, r, z))
    }

    /// True if the spectral radius of A is < 1.
    pub fn is_stable(&self) -> Result<bool> {
        Ok(self.poles()?.iter().all(|p| p.norm() < 1.0))
    }

    /// DC gain D + C·(I − A)⁻¹·B; a pole at z = 1 is an error.
    pub fn dc_gain(&self) -> Result<f64> {
        let n = self.order();
        if n == 0 {
            // a static gain: no state to solve for
            return Ok(self.d);
        }
        let m = DMatrix::<f64>::identity(n, n) - &self.a;
        let x = m.lu().solve(&self.b).ok_or(Error::Singular {
            context: "discrete DC gain (pole at z = 1)",
        })?;
        let g = self.d + self.c.dot(&x.transpose());
        if g.is_finite() {
            Ok(g)
        } else {
            Err(Error::Singular {
                context: "discrete DC gain (pole at z = 1)",
            })
        }
    }

    /// Unit-step response, n samples from x = 0.
    pub fn step_response(&self, n: usize) -> Result<Vec<f64>> {
        self.simulate(&vec![1.0; n], None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::TransferFunction;

    /// `g·∏(1 − zᵢ)/∏(1 − pⱼ)`: the DC gain the factors say.
    fn factored_dc_gain(sys: &DiscreteStateSpace) -> f64 {
        let (g, _, z) = sys.zeros().unwrap();
        let num: Complex<f64> = z.iter().map(|z| Complex::new(1.0, 0.0) - z).product();
        let den: Complex<f64> = sys
            .poles()
            .unwrap()
            .iter()
            .map(|p| Complex::new(1.0, 0.0) - p)
            .product();
        g * (num / den).re
    }

    #[test]
    fn zeros_agree_with_the_numerator_roots_where_those_are_well_conditioned() {
        // (s + 2)·(s + 30) / ((s + 1)(s + 3)(s + 10)(s + 40)) at 10 ms
        let tf = TransferFunction::new(
            crate::lti::poly_from_roots(&[Complex::new(-2.0, 0.0), Complex::new(-30.0, 0.0)])
                .iter()
                .map(|c| 1200.0 * c)
                .collect(),
            crate::lti::poly_from_roots(&[-1.0, -3.0, -10.0, -40.0].map(|p| Complex::new(p, 0.0))),
        )
        .unwrap();
        let sys = tf.to_state_space().unwrap().discretize_zoh(0.01).unwrap();
        let (g, r, z) = sys.zeros().unwrap();
        let back = StateSpace::new(sys.a.clone(), sys.b.clone(), sys.c.clone(), sys.d)
            .unwrap()
            .to_tf()
            .unwrap();
        let reference = back.zeros().unwrap();
        assert_eq!((r, z.len()), (1, reference.len()));
        for (a, b) in z.iter().zip(&reference) {
            assert!((a - b).norm() < 1e-9, "{z:?} vs {reference:?}");
        }
        assert!((g - back.num()[0] / back.den()[0]).abs() < 1e-12 * g.abs());
        assert!((factored_dc_gain(&sys) - sys.dc_gain().unwrap()).abs() < 1e-9);
    }

    #[test]
    fn the_factors_of_a_fast_sampled_high_order_model_keep_its_dc_gain() {
        // an output-error fit of a slow axis (7 poles from 1.9 to 1243 rad/s,
        // two zeros) sampled at 13.2 kHz: the poles and zeros crowd z = 1,
        // where the numerator's roots gave a DC gain of −0.05
        let tf = TransferFunction::new(
            vec![3594667572854.316, 56815387265393.02, 94095757796106.55],
            vec![
                1.0,
                894.5450795478295,
                1630848.715726167,
                1386501114.0666509,
                131310823668.99641,
                5554847665363.559,
                59974223135411.414,
                94128731501930.4,
            ],
        )
        .unwrap();
        let sys = tf
            .to_state_space()
            .unwrap()
            .discretize_zoh(7.578106011685905e-05)
            .unwrap();
        let want = tf.dc_gain();
        assert!((sys.dc_gain().unwrap() - want).abs() < 1e-9);
        let got = factored_dc_gain(&sys);
        assert!((got - want).abs() < 1e-5, "{got} vs {want}");
        let (_, r, z) = sys.zeros().unwrap();
        assert_eq!((r, z.len()), (1, 6));
    }

    #[test]
    fn a_model_whose_output_ignores_its_input_has_no_zeros() {
        let sys = DiscreteStateSpace::from_parts(
            DMatrix::from_row_slice(1, 1, &[0.5]),
            DVector::from_row_slice(&[0.0]),
            RowDVector::from_row_slice(&[1.0]),
            0.0,
            1e-3,
        )
        .unwrap();
        assert!(sys.zeros().is_err());
    }

    fn first_order(dt: f64) -> DiscreteStateSpace {
        // 2/(0.01 s + 1)
        TransferFunction::new(vec![2.0], vec![0.01, 1.0])
            .unwrap()
            .to_state_space()
            .unwrap()
            .discretize_zoh(dt)
            .unwrap()
    }

    #[test]
    fn step_response_of_discretised_first_order_is_exact() {
        let d = first_order(1e-3);
        assert_eq!(d.order(), 1);
        let y = d.step_response(50).unwrap();
        for (k, yk) in y.iter().enumerate() {
            let want = 2.0 * (1.0 - (-(k as f64) * 0.1).exp());
            assert!((yk - want).abs() < 1e-13, "{k}: {yk} vs {want}");
        }
        assert!((d.dc_gain().unwrap() - 2.0).abs() < 1e-13);
        let p = d.poles().unwrap();
        assert!((p[0].re - (-0.1f64).exp()).abs() < 1e-15 && p[0].im == 0.0);
        assert!(d.is_stable().unwrap());
    }

    #[test]
    fn simulate_into_returns_final_state_and_matches_wrapper() {
        let g = TransferFunction::new(vec![1.0, 5.0], vec![1e-4, 0.02, 1.0, 3.0]).unwrap();
        let d = g.to_state_space().unwrap().discretize_zoh(1e-3).unwrap();
        let u: Vec<f64> = (0..80).map(|k| ((k as f64) * 0.3).sin()).collect();
        let whole = d.simulate(&u, None).unwrap();
        let mut x = vec![0.0; 3];
        let mut y = vec![0.0; 40];
        let mut scratch = vec![0.0; 5];
        d.simulate_into(&u[..40], &mut x, &mut y, &mut scratch)
            .unwrap();
        let rest = d.simulate(&u[40..], Some(&x)).unwrap();
        for (k, (a, b)) in y.iter().chain(&rest).zip(&whole).enumerate() {
            assert_eq!(a, b, "sample {k}");
        }
        // Per-sample API gives the same outputs.
        let mut x = vec![0.0; 3];
        for (k, &uk) in u.iter().enumerate() {
            assert_eq!(d.output(&x, uk), whole[k]);
            d.advance(&mut x, uk, &mut scratch).unwrap();
        }
    }

    #[test]
    fn length_mismatches_are_reported() {
        let d = first_order(1e-3);
        let u = [1.0; 4];
        let mut y = [0.0; 3];
        let mut x = [0.0; 1];
        let mut s = [0.0; 1];
        assert!(matches!(
            d.simulate_into(&u, &mut x, &mut y, &mut s),
            Err(Error::LengthMismatch {
                what: "simulation output",
                expected: 4,
                actual: 3
            })
        ));
        let mut y = [0.0; 4];
        let mut x2 = [0.0; 2];
        assert!(matches!(
            d.simulate_into(&u, &mut x2, &mut y, &mut s),
            Err(Error::LengthMismatch { .. })
        ));
        let mut s0: [f64; 0] = [];
        assert!(matches!(
            d.simulate_into(&u, &mut x, &mut y, &mut s0),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            d.simulate(&u, Some(&[0.0, 0.0])),
            Err(Error::LengthMismatch { .. })
        ));
    }

    #[test]
    fn from_parts_checks_dimensions_and_sample_time() {
        let a = DMatrix::from_element(2, 2, 0.5);
        let b = DVector::from_element(2, 1.0);
        let c = RowDVector::from_element(2, 1.0);
        assert!(DiscreteStateSpace::from_parts(a.clone(), b.clone(), c.clone(), 0.0, 1e-3).is_ok());
        let c3 = RowDVector::from_element(3, 1.0);
        assert!(matches!(
            DiscreteStateSpace::from_parts(a.clone(), b.clone(), c3, 0.0, 1e-3),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            DiscreteStateSpace::from_parts(a.clone(), b.clone(), c.clone(), 0.0, -1.0),
            Err(Error::InvalidParameter { name: "dt", .. })
        ));
        assert!(matches!(
            DiscreteStateSpace::from_parts(a, b, c, f64::NAN, 1e-3),
            Err(Error::InvalidModel { .. })
        ));
    }

    #[test]
    fn unstable_and_integrating_systems_are_classified() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 0.1, 0.0, 0.5]);
        let d = DiscreteStateSpace::from_parts(
            a,
            DVector::from_element(2, 1.0),
            RowDVector::from_element(2, 1.0),
            0.0,
            1e-3,
        )
        .unwrap();
        assert!(!d.is_stable().unwrap());
        assert!(matches!(d.dc_gain(), Err(Error::Singular { .. })));
    }
}
