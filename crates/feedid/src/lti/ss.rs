//! Continuous-time SISO state-space model ẋ = A·x + B·u, y = C·x + D·u.
//!
//! * **Balancing** ([`StateSpace::balance`]): x = T·x̃ with T = diag(t), tᵢ
//!   powers of 2 chosen by the Parlett–Reinsch/`dgebal` iteration on the
//!   bordered matrix `[[A, B], [C, 0]]` (MATLAB `ssbal`), iterated to
//!   convergence. The similarity is exact in floating point and equalises the
//!   row and column norms, which removes the 1e-8 … 1e16 spread of feed-drive
//!   models before any eigenvalue, exponential or linear solve.
//! * **Poles**: eigenvalues of the balanced A (Hessenberg + double-shift QR).
//! * **Zero-order hold** ([`StateSpace::discretize_zoh`]): with
//!   `M = [[A, B], [0, 0]]·Δt`, `e^M = [[A_d, B_d], [0, 1]]`, A_d = e^{AΔt},
//!   B_d = ∫₀^Δt e^{Aτ}dτ·B — exact for piecewise-constant inputs. The
//!   exponential is the balanced scaling-and-squaring Padé-13 method; the
//!   result is returned in the coordinates of `self`.
//! * **Ramp**: u = slope·t is produced by an integrator state, augmented
//!   `[[A, B, 0], [0, 0, 1], [0, 0, 0]]·Δt`; its exponential contains
//!   Γ₁ = ∫₀^Δt e^{A(Δt−τ)}B·τ dτ, so sampled ramp responses are exact.
//! * **Transfer function** ([`StateSpace::to_tf`]): the denominator is the
//!   characteristic polynomial ∏(s − λᵢ) of the balanced A, built from real
//!   linear and quadratic factors. The strictly proper numerator is
//!   g·∏(s − zᵢ): the relative degree r is the first non-negligible Markov
//!   parameter g = C·A^(r−1)·B (|g| > 1e-10·|C|·|A|^(r−1)·|B|, i.e. far above
//!   rounding); the zeros zᵢ are the eigenvalues of
//!   A_z = A − B·C·A^r/g restricted to its invariant subspace
//!   ker[C; C·A; …; C·A^(r−1)] (orthonormal basis from a QR factorisation).
//!   The feed-through adds D·det(sI − A). For stable systems with real
//!   coefficients of one sign this gives every coefficient to near machine
//!   relative accuracy, unlike det(sI − A + BC) − det(sI − A), which cancels.
//!
//! References: MATLAB `ssbal`; LAPACK `dgebal`; A. Emami-Naeini, P. Van Dooren,
//! "Computation of zeros of linear multivariable systems", Automatica 18 (1982);
//! C.F. Van Loan, "Computing integrals involving the matrix exponential", IEEE
//! TAC 23 (1978).

use nalgebra::{Complex, DMatrix, DVector, RowDVector};

use super::balance::{apply_similarity, balance_scaling};
use super::discrete::DiscreteStateSpace;
use super::eig::eigenvalues;
use super::expm::expm;
use super::poly::poly_from_roots;
use super::tf::{frequency_points, FrequencyPoint, TransferFunction};
use crate::error::{Error, Result};

/// A Markov parameter below this fraction of its rounding bound |C|·|A|^k·|B| counts as zero.
const MARKOV_TOL: f64 = 1e-10;

/// Above this loss factor the feed-through numerator is recomputed from the zeros.
const CANCELLATION_LIMIT: f64 = 1e3;

/// Check a sample time: finite and > 0.
pub(crate) fn check_dt(dt: f64) -> Result<()> {
    if dt.is_finite() && dt > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name: "dt",
            value: dt,
            reason: "sample time must be finite and > 0",
        })
    }
}

/// A continuous-time SISO state-space model.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// State matrix A (n×n).
    pub a: DMatrix<f64>,
    /// Input vector B (n).
    pub b: DVector<f64>,
    /// Output row C (1×n).
    pub c: RowDVector<f64>,
    /// Feed-through D.
    pub d: f64,
}

impl StateSpace {
    /// Build and check dimensions and finiteness.
    pub fn new(a: DMatrix<f64>, b: DVector<f64>, c: RowDVector<f64>, d: f64) -> Result<Self> {
        let n = a.nrows();
        if a.ncols() != n {
            return Err(Error::LengthMismatch {
                what: "A columns",
                expected: n,
                actual: a.ncols(),
            });
        }
        if b.len() != n {
            return Err(Error::LengthMismatch {
                what: "B rows",
                expected: n,
                actual: b.len(),
            });
        }
        if c.len() != n {
            return Err(Error::LengthMismatch {
                what: "C columns",
                expected: n,
                actual: c.len(),
            });
        }
        if a.iter()
            .chain(b.iter())
            .chain(c.iter())
            .any(|v| !v.is_finite())
            || !d.is_finite()
        {
            return Err(Error::InvalidModel {
                reason: "non-finite state-space entry",
            });
        }
        Ok(Self { a, b, c, d })
    }

    /// Number of states.
    pub fn order(&self) -> usize {
        self.a.nrows()
    }

    /// Diagonally balanced copy with the same transfer function (see module doc).
    pub fn balance(&self) -> StateSpace {
        self.balance_with_scaling().0
    }

    /// Balanced copy and the scaling t (x = diag(t)·x̃).
    pub(crate) fn balance_with_scaling(&self) -> (StateSpace, Vec<f64>) {
        let n = self.order();
        let mut m = DMatrix::<f64>::zeros(n + 1, n + 1);
        m.view_mut((0, 0), (n, n)).copy_from(&self.a);
        m.view_mut((0, n), (n, 1)).copy_from(&self.b);
        m.view_mut((n, 0), (1, n)).copy_from(&self.c);
        let t = balance_scaling(&m, n);
        let a = apply_similarity(&self.a, &t[..n]);
        let b = DVector::from_fn(n, |i, _| self.b[i] / t[i]);
        let c = RowDVector::from_fn(n, |_, j| self.c[j] * t[j]);
        (StateSpace { a, b, c, d: self.d }, t[..n].to_vec())
    }

    /// Poles: eigenvalues of A \[rad/s\], sorted by modulus.
    pub fn poles(&self) -> Result<Vec<Complex<f64>>> {
        let mut p = eigenvalues(&self.a)?;
        super::poly::sort_roots(&mut p);
        Ok(p)
    }

    /// True if every pole has a strictly negative real part.
    pub fn is_stable(&self) -> Result<bool> {
        Ok(self.poles()?.iter().all(|p| p.re < 0.0))
    }

    /// DC gain D − C·A⁻¹·B (LU solve on the balanced model); singular A is an error.
    pub fn dc_gain(&self) -> Result<f64> {
        let sys = self.balance();
        let x = sys.a.clone().lu().solve(&sys.b).ok_or(Error::Singular {
            context: "state-space DC gain (A is singular: pole at s = 0)",
        })?;
        let g = sys.d - sys.c.dot(&x.transpose());
        finite(g, "state-space DC gain")
    }

    /// G(s) = C·(sI − A)⁻¹·B + D at complex s (complex LU solve on the balanced model).
    pub fn eval(&self, s: Complex<f64>) -> Result<Complex<f64>> {
        self.balance().eval_direct(s)
    }

    /// G(s) without balancing first.
    fn eval_direct(&self, s: Complex<f64>) -> Result<Complex<f64>> {
        let n = self.order();
        let m = DMatrix::<Complex<f64>>::from_fn(n, n, |i, j| {
            let diag = if i == j { s } else { Complex::new(0.0, 0.0) };
            diag - Complex::new(self.a[(i, j)], 0.0)
        });
        let rhs = DVector::<Complex<f64>>::from_fn(n, |i, _| Complex::new(self.b[i], 0.0));
        let x = m.lu().solve(&rhs).ok_or(Error::Singular {
            context: "state-space evaluation (s is a pole)",
        })?;
        let g = self
            .c
            .iter()
            .zip(x.iter())
            .fold(Complex::new(self.d, 0.0), |acc, (c, xi)| acc + xi * *c);
        if g.re.is_finite() && g.im.is_finite() {
            Ok(g)
        } else {
            Err(Error::Singular {
                context: "state-space evaluation (s is a pole)",
            })
        }
    }

    /// Magnitude and phase at the given frequencies \[Hz\]; phase unwrapped along the list.
    pub fn freq_response(&self, freqs_hz: &[f64]) -> Result<Vec<FrequencyPoint>> {
        let sys = self.balance();
        let values = freqs_hz
            .iter()
            .map(|&f| sys.eval_direct(Complex::new(0.0, 2.0 * std::f64::consts::PI * f)))
            .collect::<Result<Vec<_>>>()?;
        Ok(frequency_points(freqs_hz, &values))
    }

    /// Transfer function N(s)/D(s) with monic D = det(sI − A) (see module doc for the method).
    ///
    /// ```
    /// use feedid::lti::TransferFunction;
    /// let g = TransferFunction::new(vec![2.0, 3.0], vec![1.0, 4.0, 5.0]).unwrap();
    /// let back = g.to_state_space().unwrap().to_tf().unwrap();
    /// assert!((back.num()[0] - 2.0).abs() < 1e-12 && (back.den()[2] - 5.0).abs() < 1e-12);
    /// ```
    pub fn to_tf(&self) -> Result<TransferFunction> {
        let n = self.order();
        if n == 0 {
            return TransferFunction::new(vec![self.d], vec![1.0]);
        }
        let sys = self.balance();
        let den = poly_from_roots(&eigenvalues(&sys.a)?);
        let nsp = strictly_proper_numerator(&sys)?;
        let mut num: Vec<f64> = den.iter().map(|c| c * sys.d).collect();
        let off = num.len().saturating_sub(nsp.len());
        for (slot, v) in num.iter_mut().skip(off).zip(&nsp) {
            *slot += v;
        }
        if sys.d != 0.0 {
            // D·det(sI − A) + C·adj(sI − A)·B cancels when the zeros are much
            // smaller than the poles; then D·det(sI − A + B·C/D) is accurate.
            let cancellation = num
                .iter()
                .enumerate()
                .map(|(k, &v)| {
                    let parts =
                        (sys.d * den[k]).abs() + if k >= off { nsp[k - off].abs() } else { 0.0 };
                    if parts == 0.0 {
                        1.0
                    } else {
                        parts / v.abs()
                    }
                })
                .fold(1.0_f64, f64::max);
            if cancellation > CANCELLATION_LIMIT {
                let az = &sys.a - (&sys.b * &sys.c) / sys.d;
                num = poly_from_roots(&eigenvalues(&az)?)
                    .iter()
                    .map(|c| c * sys.d)
                    .collect();
            }
        }
        TransferFunction::new(num, den)
    }

    /// Exact zero-order-hold discretisation with sample time `dt` \[s\] (> 0).
    ///
    /// The result is in the state coordinates of `self`.
    pub fn discretize_zoh(&self, dt: f64) -> Result<DiscreteStateSpace> {
        check_dt(dt)?;
        let n = self.order();
        let mut m = DMatrix::<f64>::zeros(n + 1, n + 1);
        m.view_mut((0, 0), (n, n)).copy_from(&(&self.a * dt));
        m.view_mut((0, n), (n, 1)).copy_from(&(&self.b * dt));
        let e = expm(&m)?;
        let ad = e.view((0, 0), (n, n)).into_owned();
        let bd = DVector::from_fn(n, |i, _| e[(i, n)]);
        DiscreteStateSpace::from_parts(ad, bd, self.c.clone(), self.d, dt)
    }

    /// Exact sampled unit-step response y(k·dt), k = 0 … n−1 (`dt` in s, > 0).
    pub fn step_response(&self, dt: f64, n: usize) -> Result<Vec<f64>> {
        self.discretize_zoh(dt)?.step_response(n)
    }

    /// Exact sampled response to u(t) = slope·t at t = k·dt, k = 0 … n−1, from x(0) = 0.
    ///
    /// `slope` in input units per second, `dt` in s (> 0). Uses the augmented
    /// integrator system of the module doc, so no input approximation is made.
    pub fn ramp_response(&self, slope: f64, dt: f64, n: usize) -> Result<Vec<f64>> {
        check_dt(dt)?;
        if !slope.is_finite() {
            return Err(Error::InvalidParameter {
                name: "slope",
                value: slope,
                reason: "must be finite",
            });
        }
        let ns = self.order();
        let mut m = DMatrix::<f64>::zeros(ns + 2, ns + 2);
        m.view_mut((0, 0), (ns, ns)).copy_from(&(&self.a * dt));
        m.view_mut((0, ns), (ns, 1)).copy_from(&(&self.b * dt));
        m[(ns, ns + 1)] = dt;
        let e = expm(&m)?;
        let phi = e.view((0, 0), (ns, ns)).into_owned();
        let g0 = DVector::from_fn(ns, |i, _| e[(i, ns)]);
        let g1 = DVector::from_fn(ns, |i, _| e[(i, ns + 1)]);
        let mut x = DVector::<f64>::zeros(ns);
        let mut y = Vec::with_capacity(n);
        for k in 0..n {
            let u = slope * (k as f64) * dt;
            y.push(self.c.dot(&x.transpose()) + self.d * u);
            x = &phi * &x + &g0 * u + &g1 * slope;
        }
        if y.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "ramp response overflowed (unstable system?)",
            });
        }
        Ok(y)
    }

    /// Response to the sampled input `u` held constant over each `dt` \[s\] (zero-order hold).
    ///
    /// y\[k\] = C·x\[k\] + D·u\[k\], x\[0\] = `x0` (in the coordinates of `self`) or 0.
    pub fn simulate(&self, u: &[f64], dt: f64, x0: Option<&[f64]>) -> Result<Vec<f64>> {
        self.discretize_zoh(dt)?.simulate(u, x0)
    }
}

/// A finite value or a `Singular` error naming `context`.
fn finite(v: f64, context: &'static str) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::Singular { context })
    }
}

/// Numerator of C·adj(sI − A)·B (descending powers, leading coefficient first),
/// via the first non-zero Markov parameter and the invariant zeros.
fn strictly_proper_numerator(sys: &StateSpace) -> Result<Vec<f64>> {
    let n = sys.order();
    let abs_a = sys.a.abs();
    let abs_c = sys.c.abs();
    let mut v = sys.b.clone();
    let mut av = sys.b.abs();
    let mut found = None;
    for k in 0..n {
        let m = sys.c.dot(&v.transpose());
        let bound = abs_c.dot(&av.transpose());
        if bound > 0.0 && m.abs() > MARKOV_TOL * bound {
            found = Some((k + 1, m));
            break;
        }
        v = &sys.a * v;
        av = &abs_a * av;
    }
    let Some((r, g)) = found else {
        return Ok(Vec::new());
    };
    if r == n {
        return Ok(vec![g]);
    }
    // Rows C·A^j, j < r, normalised, as columns of an n×n matrix padded with zeros.
    let mut basis = DMatrix::<f64>::zeros(n, n);
    let mut row = sys.c.clone();
    for j in 0..r {
        let nrm = row.norm();
        if nrm == 0.0 || !nrm.is_finite() {
            return Err(Error::InvalidModel {
                reason: "degenerate output map in numerator computation",
            });
        }
        for i in 0..n {
            basis[(i, j)] = row[i] / nrm;
        }
        row = &row * &sys.a;
    }
    // `row` is now C·A^r.
    let q = basis.qr().q();
    let vz = q.columns(r, n - r).into_owned();
    let az = &sys.a - (&sys.b * &row) / g;
    let z = vz.transpose() * az * &vz;
    let zeros = eigenvalues(&z)?;
    Ok(poly_from_roots(&zeros).iter().map(|c| c * g).collect())
}
