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
//!   The feed-through adds D·det(sI − A); if that sum cancels by more than a
//!   factor 1e3 the numerator is taken as D·det(sI − A + B·C/D) instead. For
//!   stable systems with coefficients of one sign this gives every coefficient
//!   to near machine relative accuracy (the 7-state feed-drive model: < 1e-12),
//!   unlike det(sI − A + BC) − det(sI − A), which cancels. Limits: a cluster of
//!   several zeros far below the pole magnitudes loses digits (seen: 1e-7), and
//!   a biproper model realised in companion form already carries the
//!   cancellation of N − D·den in its C row.
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Default rig of docs/METHODS.md §2.5.
    struct Rig {
        r: f64,
        k: f64,
        j: f64,
        m: f64,
        kt: f64,
        ke: f64,
        res: f64,
        l: f64,
        c1: f64,
        c2: f64,
        kv: f64,
        kp: f64,
        ki: f64,
        kpi: f64,
        kii: f64,
    }

    const RIG: Rig = Rig {
        r: 0.010 / (2.0 * std::f64::consts::PI),
        k: 3.0e7,
        j: 1.6e-5,
        m: 3.0,
        kt: 0.06,
        ke: 0.06,
        res: 1.2,
        l: 3.5e-4,
        c1: 5e-5,
        c2: 100.0,
        kv: 700.0,
        kp: 465.8,
        ki: 471.2,
        kpi: 4.398,
        kii: 3428.6,
    };

    /// The 7-state cascade [z_v, z_i, i, θ, ω, x_a, v_a] of docs/METHODS.md §2, input x_s, output x_a.
    fn feed_drive_ss(p: &Rig) -> StateSpace {
        let mut a = DMatrix::<f64>::zeros(7, 7);
        let mut b = DVector::<f64>::zeros(7);
        // ż_v = e_v = Kv·(x_s − x_a) − r·ω
        a[(0, 4)] = -p.r;
        a[(0, 5)] = -p.kv;
        b[0] = p.kv;
        // ż_i = i_ref − i, i_ref = Kp·(e_v + Ki·z_v)
        a[(1, 0)] = p.kp * p.ki;
        a[(1, 2)] = -1.0;
        a[(1, 4)] = -p.kp * p.r;
        a[(1, 5)] = -p.kp * p.kv;
        b[1] = p.kp * p.kv;
        // L·di/dt = Kpi·(i_ref − i + Kii·z_i) − R·i − Ke·ω
        a[(2, 0)] = p.kpi * p.kp * p.ki / p.l;
        a[(2, 1)] = p.kpi * p.kii / p.l;
        a[(2, 2)] = -(p.kpi + p.res) / p.l;
        a[(2, 4)] = -(p.kpi * p.kp * p.r + p.ke) / p.l;
        a[(2, 5)] = -p.kpi * p.kp * p.kv / p.l;
        b[2] = p.kpi * p.kp * p.kv / p.l;
        // θ̇ = ω; J·ω̇ = Kt·i − C1·ω − r·K·(r·θ − x_a)
        a[(3, 4)] = 1.0;
        a[(4, 2)] = p.kt / p.j;
        a[(4, 3)] = -p.r * p.r * p.k / p.j;
        a[(4, 4)] = -p.c1 / p.j;
        a[(4, 5)] = p.r * p.k / p.j;
        // ẋ_a = v_a; M·v̇_a = K·(r·θ − x_a) − C2·v_a
        a[(5, 6)] = 1.0;
        a[(6, 3)] = p.k * p.r / p.m;
        a[(6, 5)] = -p.k / p.m;
        a[(6, 6)] = -p.c2 / p.m;
        let mut c = RowDVector::<f64>::zeros(7);
        c[5] = 1.0;
        StateSpace::new(a, b, c, 0.0).unwrap()
    }

    /// N and D of docs/METHODS.md §2.5 (corrected appendix), normalised so that D7 = J·L·M.
    fn feed_drive_coefficients(p: &Rig) -> (Vec<f64>, Vec<f64>) {
        let Rig {
            r,
            k,
            j,
            m,
            kt,
            ke,
            res,
            l,
            c1,
            c2,
            kv,
            kp,
            ki,
            kpi,
            kii,
        } = *p;
        let n2 = k * kp * kpi * kt * kv * r;
        let n1 = n2 * (ki + kii);
        let n0 = n2 * ki * kii;
        let d7 = j * l * m;
        let d6 = c1 * l * m + c2 * j * l + j * m * (res + kpi);
        let d5 = c1 * c2 * l
            + c1 * m * res
            + c2 * j * res
            + j * k * l
            + k * l * m * r * r
            + ke * kt * m
            + kpi * (c1 * m + c2 * j + j * kii * m + kp * kt * m * r);
        let d4 = c1 * c2 * res
            + c1 * k * l
            + c2 * k * l * r * r
            + c2 * ke * kt
            + j * k * res
            + k * m * res * r * r
            + kpi
                * (c1 * c2
                    + c1 * kii * m
                    + c2 * j * kii
                    + c2 * kp * kt * r
                    + j * k
                    + k * m * r * r
                    + (ki + kii) * kp * kt * m * r);
        let d3 = k * (c1 * res + c2 * res * r * r + ke * kt)
            + kpi
                * (c1 * c2 * kii
                    + c1 * k
                    + c2 * k * r * r
                    + c2 * (ki + kii) * kp * kt * r
                    + j * k * kii
                    + k * kii * m * r * r
                    + k * kp * kt * r
                    + ki * kii * kp * kt * m * r);
        let d2 = kpi
            * (c1 * k * kii
                + c2 * k * kii * r * r
                + c2 * ki * kii * kp * kt * r
                + k * kp * kt * r * (ki + kii + kv));
        let d1 = k * kp * kpi * kt * r * (ki * kii + kv * (ki + kii));
        let d0 = n0;
        (vec![n2, n1, n0], vec![d7, d6, d5, d4, d3, d2, d1, d0])
    }

    fn assert_coeffs_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        assert_eq!(a.len(), b.len(), "{what}: {a:?} vs {b:?}");
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= tol * y.abs(),
                "{what}[{k}]: {x:e} vs {y:e}"
            );
        }
    }

    #[test]
    fn feed_drive_state_space_to_tf_matches_hand_derived_coefficients() {
        let sys = feed_drive_ss(&RIG);
        let (num, den) = feed_drive_coefficients(&RIG);
        let tf = sys.to_tf().unwrap();
        let scale = den[0];
        let got_num: Vec<f64> = tf.num().iter().map(|c| c * scale).collect();
        let got_den: Vec<f64> = tf.den().iter().map(|c| c * scale).collect();
        assert_coeffs_close(&got_den, &den, 1e-9, "den");
        assert_coeffs_close(&got_num, &num, 1e-9, "num");
        // And the rounded values of docs/METHODS.md §2.5, to half a unit of the 6th digit.
        let notes_num: [f64; 3] = [4.10814e9, 1.60209e13, 6.63693e15];
        let notes_den: [f64; 8] = [
            1.68000e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7, 2.71640e10, 2.55023e13,
            6.63693e15,
        ];
        for (x, p) in got_num
            .iter()
            .chain(&got_den)
            .zip(notes_num.iter().chain(&notes_den))
        {
            let half_unit = 0.5 * 10f64.powf(p.abs().log10().floor() - 5.0);
            assert!(
                (x - p).abs() <= half_unit * 1.0001,
                "{x:e} vs the documented {p:e}"
            );
        }
    }

    #[test]
    fn feed_drive_dc_gain_is_one_and_poles_are_stable() {
        let sys = feed_drive_ss(&RIG);
        assert!((sys.dc_gain().unwrap() - 1.0).abs() < 1e-12);
        assert!(sys.is_stable().unwrap());
        let tf_poles = sys.to_tf().unwrap().poles().unwrap();
        let ss_poles = sys.poles().unwrap();
        for (a, b) in tf_poles.iter().zip(&ss_poles) {
            assert!((a - b).norm() < 1e-9 * b.norm(), "{a} vs {b}");
        }
    }

    #[test]
    fn balance_preserves_transfer_function_and_reduces_spread() {
        let sys = feed_drive_ss(&RIG);
        let bal = sys.balance();
        for w in [0.0, 10.0, 3e3, 1e5] {
            let s = Complex::new(0.0, w);
            let a = sys.eval_direct(s).unwrap();
            let b = bal.eval_direct(s).unwrap();
            assert!((a - b).norm() <= 1e-12 * b.norm(), "w={w}: {a} vs {b}");
        }
        let spread = |m: &DMatrix<f64>| {
            let nz: Vec<f64> = m.iter().filter(|v| **v != 0.0).map(|v| v.abs()).collect();
            nz.iter().cloned().fold(0.0, f64::max)
                / nz.iter().cloned().fold(f64::INFINITY, f64::min)
        };
        assert!(
            spread(&bal.a) < 1e-3 * spread(&sys.a),
            "{} vs {}",
            spread(&bal.a),
            spread(&sys.a)
        );
        // Balancing twice changes nothing.
        assert_eq!(bal.balance(), bal);
    }

    #[test]
    fn zoh_of_first_order_matches_closed_form() {
        let (tau, k, dt) = (0.02, 3.0, 1e-3);
        let sys = StateSpace::new(
            DMatrix::from_element(1, 1, -1.0 / tau),
            DVector::from_element(1, 1.0 / tau),
            RowDVector::from_element(1, k),
            0.0,
        )
        .unwrap();
        let d = sys.discretize_zoh(dt).unwrap();
        let e = (-dt / tau).exp();
        assert!((d.a[(0, 0)] - e).abs() <= 1e-15 * e);
        assert!((d.b[0] - (1.0 - e)).abs() <= 1e-14 * (1.0 - e));
        assert_eq!(d.c[0], k);
        assert_eq!(d.dt, dt);
    }

    #[test]
    fn zoh_poles_are_exponentials_of_continuous_poles() {
        let sys = feed_drive_ss(&RIG);
        let dt = 2e-4;
        let d = sys.discretize_zoh(dt).unwrap();
        let mut want: Vec<Complex<f64>> = sys
            .poles()
            .unwrap()
            .iter()
            .map(|p| (p * dt).exp())
            .collect();
        crate::lti::poly::sort_roots(&mut want);
        for (a, b) in d.poles().unwrap().iter().zip(&want) {
            assert!((a - b).norm() < 1e-12, "{a} vs {b}");
        }
        assert!(d.is_stable().unwrap());
        assert!((d.dc_gain().unwrap() - 1.0).abs() < 1e-10);
    }

    #[test]
    fn simulate_of_constant_input_equals_scaled_step_response() {
        let sys = feed_drive_ss(&RIG);
        let dt = 2e-4;
        let step = sys.step_response(dt, 300).unwrap();
        let y = sys.simulate(&[1e-3; 300], dt, None).unwrap();
        for (a, b) in y.iter().zip(&step) {
            assert!((a - 1e-3 * b).abs() < 1e-15, "{a} vs {b}");
        }
        // Superposition: starting from the state reached after 150 samples continues the response.
        let d = sys.discretize_zoh(dt).unwrap();
        let mut x = vec![0.0; 7];
        let mut y1 = vec![0.0; 150];
        let mut scratch = vec![0.0; 7];
        d.simulate_into(&[1.0; 150], &mut x, &mut y1, &mut scratch)
            .unwrap();
        let y2 = sys.simulate(&[1.0; 150], dt, Some(&x)).unwrap();
        for (k, (a, b)) in y1.iter().chain(&y2).zip(&step).enumerate() {
            assert!((a - b).abs() < 1e-12, "{k}: {a} vs {b}");
        }
    }

    #[test]
    fn eval_matches_transfer_function_and_rejects_poles() {
        let sys = feed_drive_ss(&RIG);
        let tf = sys.to_tf().unwrap();
        for f in [1.0, 60.0, 561.0, 2e3, 5e4] {
            let s = Complex::new(0.0, 2.0 * std::f64::consts::PI * f);
            let a = sys.eval(s).unwrap();
            let b = tf.eval(s);
            assert!((a - b).norm() <= 1e-9 * b.norm(), "f={f}: {a} vs {b}");
        }
        let integ = StateSpace::new(
            DMatrix::zeros(1, 1),
            DVector::from_element(1, 1.0),
            RowDVector::from_element(1, 1.0),
            0.0,
        )
        .unwrap();
        assert!(matches!(
            integ.eval(Complex::new(0.0, 0.0)),
            Err(Error::Singular { .. })
        ));
        assert!(matches!(integ.dc_gain(), Err(Error::Singular { .. })));
        assert!(!integ.is_stable().unwrap());
    }

    #[test]
    fn to_tf_handles_zero_output_and_static_gain() {
        let sys = StateSpace::new(
            DMatrix::from_element(1, 1, -2.0),
            DVector::from_element(1, 1.0),
            RowDVector::from_element(1, 0.0),
            0.0,
        )
        .unwrap();
        let tf = sys.to_tf().unwrap();
        assert_eq!(tf.num(), &[0.0]);
        assert_eq!(tf.den(), &[1.0, 2.0]);
        let stat = StateSpace::new(
            DMatrix::zeros(0, 0),
            DVector::zeros(0),
            RowDVector::zeros(0),
            4.0,
        )
        .unwrap();
        assert_eq!(stat.to_tf().unwrap().num(), &[4.0]);
        assert_eq!(stat.step_response(0.1, 3).unwrap(), vec![4.0; 3]);
    }
}
