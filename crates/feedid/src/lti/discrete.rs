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
