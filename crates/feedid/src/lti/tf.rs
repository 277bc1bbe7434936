//! Continuous-time SISO transfer function G(s) = N(s)/D(s), coefficients in
//! descending powers of s.
//!
//! Everything dynamic goes through a balanced state-space realisation
//! ([`TransferFunction::to_state_space`]): the controllable companion form of
//! the monic denominator, then the diagonal power-of-2 similarity of
//! [`StateSpace::balance`]. Raw companion matrices of the feed-drive
//! polynomial have entries from 1 to ~4e23; balanced, their entries are of the
//! order of the pole magnitudes, so matrix exponentials and simulations lose no
//! accuracy to the coefficient scaling.
//!
//! Evaluation at a point s uses Horner's rule in s for |s| ≤ 1 and in 1/s for
//! |s| > 1 (G(s) = s^(m−n)·Ñ(1/s)/D̃(1/s) with reversed coefficients), followed
//! by Smith's complex division, so no power of s overflows and no intermediate
//! |·|² is formed.

use nalgebra::{Complex, DMatrix, DVector, RowDVector};

use super::poly::{poly_eval, poly_roots};
use super::ss::StateSpace;
use crate::error::{Error, Result};

/// A continuous-time SISO transfer function with coefficients in descending powers of s.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    num: Vec<f64>,
    den: Vec<f64>,
}

/// Magnitude and phase of a frequency response at one frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrequencyPoint {
    /// Frequency \[Hz\].
    pub freq_hz: f64,
    /// Magnitude (linear, not dB).
    pub magnitude: f64,
    /// Phase \[deg\], unwrapped along the requested frequencies.
    pub phase_deg: f64,
}

impl TransferFunction {
    /// Build from numerator and denominator in descending powers of s.
    ///
    /// Leading zeros are stripped; the denominator must be non-zero, all
    /// coefficients finite, and the system proper (deg N ≤ deg D).
    pub fn new(num: Vec<f64>, den: Vec<f64>) -> Result<Self> {
        let strip = |v: Vec<f64>| -> Vec<f64> {
            let first = v.iter().position(|&c| c != 0.0).unwrap_or(v.len());
            v[first..].to_vec()
        };
        if num.iter().chain(den.iter()).any(|c| !c.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "non-finite transfer-function coefficient",
            });
        }
        let num = strip(num);
        let den = strip(den);
        if den.is_empty() {
            return Err(Error::InvalidModel {
                reason: "zero denominator",
            });
        }
        if num.len() > den.len() {
            return Err(Error::InvalidModel {
                reason: "improper transfer function (deg N > deg D)",
            });
        }
        let num = if num.is_empty() { vec![0.0] } else { num };
        Ok(Self { num, den })
    }

    /// Numerator coefficients, descending powers of s.
    pub fn num(&self) -> &[f64] {
        &self.num
    }

    /// Denominator coefficients, descending powers of s.
    pub fn den(&self) -> &[f64] {
        &self.den
    }

    /// Order of the denominator.
    pub fn order(&self) -> usize {
        self.den.len() - 1
    }

    /// DC gain N(0)/D(0); common factors s are cancelled first, ±∞ if D(0) = 0.
    pub fn dc_gain(&self) -> f64 {
        // Cancel common roots at s = 0 (trailing zeros of both polynomials).
        let tz = |v: &[f64]| v.iter().rev().take_while(|&&c| c == 0.0).count();
        let num_zero = self.num.iter().all(|&c| c == 0.0);
        if num_zero {
            return 0.0;
        }
        let k = tz(&self.num).min(tz(&self.den));
        let n0 = self.num[self.num.len() - 1 - k];
        let d0 = self.den[self.den.len() - 1 - k];
        if d0 == 0.0 {
            if n0 >= 0.0 {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            }
        } else {
            n0 / d0
        }
    }

    /// Poles: roots of the denominator (balanced companion eigenvalues) \[rad/s\].
    pub fn poles(&self) -> Result<Vec<Complex<f64>>> {
        poly_roots(&self.den)
    }

    /// Zeros: roots of the numerator \[rad/s\].
    pub fn zeros(&self) -> Result<Vec<Complex<f64>>> {
        poly_roots(&self.num)
    }

    /// True if every pole has a strictly negative real part.
    pub fn is_stable(&self) -> Result<bool> {
        Ok(self.poles()?.iter().all(|p| p.re < 0.0))
    }

    /// Same transfer function scaled so that the leading denominator coefficient is 1.
    pub fn normalized(&self) -> TransferFunction {
        let lead = self.den[0];
        TransferFunction {
            num: self.num.iter().map(|c| c / lead).collect(),
            den: self.den.iter().map(|c| c / lead).collect(),
        }
    }

    /// G(s) at a complex point s (robust to widely scaled coefficients; ∞ at a pole).
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        if s.norm() <= 1.0 {
            return cdiv(poly_eval(&self.num, s), poly_eval(&self.den, s));
        }
        // Reversed polynomials in w = 1/s: p(s) = s^deg · p̃(w).
        let w = cdiv(Complex::new(1.0, 0.0), s);
        let rev = |c: &[f64]| {
            c.iter()
                .rev()
                .fold(Complex::new(0.0, 0.0), |acc, &a| acc * w + a)
        };
        let ratio = cdiv(rev(&self.num), rev(&self.den));
        let excess = self.den.len() - self.num.len();
        let mut g = ratio;
        for _ in 0..excess {
            g *= w;
        }
        g
    }

    /// Magnitude and phase at the given frequencies \[Hz\]; phase unwrapped along the list.
    pub fn freq_response(&self, freqs_hz: &[f64]) -> Vec<FrequencyPoint> {
        let values: Vec<Complex<f64>> = freqs_hz
            .iter()
            .map(|&f| self.eval(Complex::new(0.0, 2.0 * std::f64::consts::PI * f)))
            .collect();
        frequency_points(freqs_hz, &values)
    }

    /// Balanced state-space realisation (controllable companion form, then [`StateSpace::balance`]).
    ///
    /// For deg N = deg D the direct feed-through is D = n₀/d₀ and the strictly
    /// proper remainder is realised.
    pub fn to_state_space(&self) -> Result<StateSpace> {
        let tf = self.normalized();
        let n = tf.order();
        let den = &tf.den;
        let mut num = vec![0.0; n + 1 - tf.num.len()];
        num.extend_from_slice(&tf.num);
        if den.iter().chain(num.iter()).any(|c| !c.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "transfer-function coefficients overflow when normalised",
            });
        }
        let d = num[0];
        let mut a = DMatrix::<f64>::zeros(n, n);
        let mut b = DVector::<f64>::zeros(n);
        let mut c = RowDVector::<f64>::zeros(n);
        for j in 0..n {
            a[(0, j)] = -den[j + 1];
            c[j] = num[j + 1] - d * den[j + 1];
        }
        for i in 1..n {
            a[(i, i - 1)] = 1.0;
        }
        if n > 0 {
            b[0] = 1.0;
        }
        Ok(StateSpace::new(a, b, c, d)?.balance())
    }

    /// Exact sampled unit-step response y(k·dt), k = 0 … n−1 (`dt` in s, > 0).
    ///
    /// ```
    /// use feedid::lti::TransferFunction;
    /// let g = TransferFunction::new(vec![1.0], vec![0.1, 1.0]).unwrap(); // 1/(0.1 s + 1)
    /// let y = g.step_response(0.1, 3).unwrap();
    /// assert!((y[1] - (1.0 - (-1.0f64).exp())).abs() < 1e-12);
    /// ```
    pub fn step_response(&self, dt: f64, n: usize) -> Result<Vec<f64>> {
        self.to_state_space()?.step_response(dt, n)
    }

    /// Exact sampled response to the ramp u(t) = slope·t, at t = k·dt, k = 0 … n−1.
    ///
    /// `slope` in input units per second, `dt` in s (> 0). The ramp is
    /// generated by an integrator in an augmented system, so the samples are
    /// exact (no zero-order-hold approximation of the input).
    pub fn ramp_response(&self, slope: f64, dt: f64, n: usize) -> Result<Vec<f64>> {
        self.to_state_space()?.ramp_response(slope, dt, n)
    }
}

/// Smith's complex division a/b; b = 0 gives an infinite real part (never NaN for finite a).
pub(crate) fn cdiv(a: Complex<f64>, b: Complex<f64>) -> Complex<f64> {
    if b.re == 0.0 && b.im == 0.0 {
        let sign = if a.re < 0.0 { -1.0 } else { 1.0 };
        return Complex::new(sign * f64::INFINITY, 0.0);
    }
    if b.re.abs() >= b.im.abs() {
        let r = b.im / b.re;
        let den = b.re + b.im * r;
        Complex::new((a.re + a.im * r) / den, (a.im - a.re * r) / den)
    } else {
        let r = b.re / b.im;
        let den = b.re * r + b.im;
        Complex::new((a.re * r + a.im) / den, (a.im * r - a.re) / den)
    }
}

/// Frequency points with the phase unwrapped continuously along the list.
///
/// The first phase is in (−180°, 180°]; each following one is shifted by a
/// multiple of 360° to lie within 180° of its predecessor. A non-finite value
/// (at a pole) keeps the previous phase.
pub(crate) fn frequency_points(freqs_hz: &[f64], values: &[Complex<f64>]) -> Vec<FrequencyPoint> {
    let mut out = Vec::with_capacity(values.len());
    let mut prev: Option<f64> = None;
    for (&f, g) in freqs_hz.iter().zip(values) {
        let magnitude = g.re.hypot(g.im);
        let raw = if g.re.is_finite() && g.im.is_finite() {
            Some(g.im.atan2(g.re).to_degrees())
        } else {
            None
        };
        let phase_deg = match (raw, prev) {
            (Some(p), None) => p,
            (Some(p), Some(q)) => p + 360.0 * ((q - p) / 360.0).round(),
            (None, Some(q)) => q,
            (None, None) => 0.0,
        };
        prev = Some(phase_deg);
        out.push(FrequencyPoint {
            freq_hz: f,
            magnitude: if magnitude.is_nan() {
                f64::INFINITY
            } else {
                magnitude
            },
            phase_deg,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::poly_from_roots;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    pub(crate) const RIG_NUM: [f64; 3] = [4.10814e9, 1.60209e13, 6.63693e15];
    pub(crate) const RIG_DEN: [f64; 8] = [
        1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7, 2.71640e10, 2.55023e13, 6.63693e15,
    ];

    fn notes_tf() -> TransferFunction {
        TransferFunction::new(RIG_NUM.to_vec(), RIG_DEN.to_vec()).unwrap()
    }

    /// Max |a − b| ≤ tol·max(1, max |b|).
    fn assert_series_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        assert_eq!(a.len(), b.len(), "{what}: length");
        let scale = b.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= tol * scale,
                "{what}[{k}]: {x} vs {y} (diff {:e})",
                x - y
            );
        }
    }

    /// Coefficient-wise relative comparison (leading zeros of `a` beyond `b`'s length must be ~0).
    fn assert_coeffs_close(a: &[f64], b: &[f64], tol: f64, what: &str) {
        assert_eq!(a.len(), b.len(), "{what}: {a:?} vs {b:?}");
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= tol * y.abs().max(x.abs()),
                "{what}[{k}]: {x:e} vs {y:e} (rel {:e})",
                (x - y).abs() / y.abs()
            );
        }
    }

    /// Second-order ωn²/(s² + 2ζωn s + ωn²): (step, ramp/slope, impulse) at t by residues.
    fn second_order_closed_form(wn: f64, zeta: f64, t: f64) -> (f64, f64, f64) {
        let disc = Complex::new(zeta * zeta - 1.0, 0.0).sqrt();
        let p1 = wn * (-zeta + disc);
        let p2 = wn * (-zeta - disc);
        let w2 = wn * wn;
        let mut step = Complex::new(1.0, 0.0);
        let mut ramp = Complex::new(t - 2.0 * zeta / wn, 0.0);
        let mut imp = Complex::new(0.0, 0.0);
        for (pi, pj) in [(p1, p2), (p2, p1)] {
            let e = (pi * t).exp();
            step += e * w2 / (pi * (pi - pj));
            ramp += e * w2 / (pi * pi * (pi - pj));
            imp += e * w2 / (pi - pj);
        }
        (step.re, ramp.re, imp.re)
    }

    #[test]
    fn first_order_step_ramp_impulse_match_closed_form() {
        let (k, tau) = (2.5, 0.01);
        let g = TransferFunction::new(vec![k], vec![tau, 1.0]).unwrap();
        let (dt, n, slope) = (1e-3, 200, 3.0);
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let step_ref: Vec<f64> = t.iter().map(|t| k * (1.0 - (-t / tau).exp())).collect();
        let ramp_ref: Vec<f64> = t
            .iter()
            .map(|t| k * slope * (t - tau * (1.0 - (-t / tau).exp())))
            .collect();
        let imp_ref: Vec<f64> = t.iter().map(|t| k / tau * (-t / tau).exp()).collect();
        assert_series_close(&g.step_response(dt, n).unwrap(), &step_ref, 1e-10, "step");
        assert_series_close(
            &g.ramp_response(slope, dt, n).unwrap(),
            &ramp_ref,
            1e-10,
            "ramp",
        );
        // Impulse response = free response from x(0) = B (zero input).
        let ss = g.to_state_space().unwrap();
        let x0: Vec<f64> = ss.b.iter().copied().collect();
        let imp = ss.simulate(&vec![0.0; n], dt, Some(&x0)).unwrap();
        assert_series_close(&imp, &imp_ref, 1e-10, "impulse");
    }

    fn check_second_order(wn: f64, zeta: f64) {
        let g = TransferFunction::new(vec![wn * wn], vec![1.0, 2.0 * zeta * wn, wn * wn]).unwrap();
        let (dt, n, slope) = (2e-4, 400, 0.05);
        let refs: Vec<(f64, f64, f64)> = (0..n)
            .map(|i| second_order_closed_form(wn, zeta, i as f64 * dt))
            .collect();
        let step_ref: Vec<f64> = refs.iter().map(|r| r.0).collect();
        let ramp_ref: Vec<f64> = refs.iter().map(|r| slope * r.1).collect();
        let imp_ref: Vec<f64> = refs.iter().map(|r| r.2).collect();
        let what = format!("wn={wn}, zeta={zeta}");
        assert_series_close(&g.step_response(dt, n).unwrap(), &step_ref, 1e-10, &what);
        assert_series_close(
            &g.ramp_response(slope, dt, n).unwrap(),
            &ramp_ref,
            1e-10,
            &what,
        );
        let ss = g.to_state_space().unwrap();
        let x0: Vec<f64> = ss.b.iter().copied().collect();
        let imp = ss.simulate(&vec![0.0; n], dt, Some(&x0)).unwrap();
        assert_series_close(&imp, &imp_ref, 1e-10, &what);
    }

    #[test]
    fn second_order_underdamped_responses_match_closed_form() {
        check_second_order(2.0 * std::f64::consts::PI * 50.0, 0.3);
        check_second_order(2.0 * std::f64::consts::PI * 561.0, 0.16);
    }

    #[test]
    fn second_order_overdamped_responses_match_closed_form() {
        check_second_order(2.0 * std::f64::consts::PI * 40.0, 2.0);
    }

    #[test]
    fn first_order_frequency_response_matches_closed_form() {
        let tau = 0.002;
        let g = TransferFunction::new(vec![1.0], vec![tau, 1.0]).unwrap();
        let freqs: Vec<f64> = (0..60).map(|i| 10f64.powf(-1.0 + i as f64 * 0.1)).collect();
        let fr = g.freq_response(&freqs);
        let ss_fr = g.to_state_space().unwrap().freq_response(&freqs).unwrap();
        for (p, q) in fr.iter().zip(&ss_fr) {
            let wt = 2.0 * std::f64::consts::PI * p.freq_hz * tau;
            let mag = 1.0 / (1.0 + wt * wt).sqrt();
            let ph = -wt.atan().to_degrees();
            assert!((p.magnitude - mag).abs() < 1e-13 * mag.max(1e-3), "{p:?}");
            assert!((p.phase_deg - ph).abs() < 1e-10, "{p:?} vs {ph}");
            assert!((q.magnitude - mag).abs() < 1e-12 * mag.max(1e-3), "{q:?}");
            assert!((q.phase_deg - ph).abs() < 1e-9, "{q:?} vs {ph}");
        }
    }

    #[test]
    fn phase_is_unwrapped_continuously_past_minus_180() {
        // 1/(s + 1)^4: phase −4·atan(ω) reaches −360° without jumps.
        let g = TransferFunction::new(vec![1.0], vec![1.0, 4.0, 6.0, 4.0, 1.0]).unwrap();
        let freqs: Vec<f64> = (0..200)
            .map(|i| 10f64.powf(-3.0 + i as f64 * 0.03))
            .collect();
        for p in g.freq_response(&freqs) {
            let w = 2.0 * std::f64::consts::PI * p.freq_hz;
            let want = -4.0 * w.atan().to_degrees();
            assert!((p.phase_deg - want).abs() < 1e-9, "{p:?} vs {want}");
        }
    }

    #[test]
    fn eval_is_finite_and_accurate_far_outside_unit_circle() {
        let g = notes_tf();
        let ss = g.to_state_space().unwrap();
        for w in [1.0, 1e2, 1e4, 1e6, 1e8] {
            let s = Complex::new(0.0, w);
            let a = g.eval(s);
            let b = ss.eval(s).unwrap();
            assert!((a - b).norm() <= 1e-10 * b.norm(), "w={w}: {a} vs {b}");
        }
        let far = g.eval(Complex::new(0.0, 1e200));
        assert!(far.re.is_finite() && far.im.is_finite() && far.norm() < 1e-300);
    }

    #[test]
    fn notes_poles_match_listed_frequencies_and_dampings() {
        let poles = notes_tf().poles().unwrap();
        assert_eq!(poles.len(), 7);
        let hz = |p: &Complex<f64>| p.norm() / (2.0 * std::f64::consts::PI);
        let real: Vec<f64> = poles.iter().filter(|p| p.im == 0.0).map(hz).collect();
        let pairs: Vec<(f64, f64)> = poles
            .iter()
            .filter(|p| p.im > 0.0)
            .map(|p| (hz(p), -p.re / p.norm()))
            .collect();
        assert_eq!(real.len(), 3);
        assert_eq!(pairs.len(), 2);
        assert!((real[0] - 60.7).abs() < 0.05, "{real:?}");
        assert!((real[1] - 579.0).abs() < 0.5, "{real:?}");
        assert!((real[2] - 1430.0).abs() < 5.0, "{real:?}");
        assert!(
            (pairs[0].0 - 254.0).abs() < 0.5 && (pairs[0].1 - 0.59).abs() < 0.005,
            "{pairs:?}"
        );
        assert!(
            (pairs[1].0 - 561.0).abs() < 0.5 && (pairs[1].1 - 0.16).abs() < 0.005,
            "{pairs:?}"
        );
        assert!(notes_tf().is_stable().unwrap());
    }

    #[test]
    fn notes_dc_gain_is_one() {
        let g = notes_tf();
        assert!((g.dc_gain() - 1.0).abs() < 1e-6);
        let ss = g.to_state_space().unwrap();
        assert!((ss.dc_gain().unwrap() - 1.0).abs() < 1e-6);
        let y = g.step_response(2e-4, 250).unwrap();
        assert!((y[249] - 1.0).abs() < 1e-6, "{}", y[249]);
    }

    #[test]
    fn notes_ramp_following_error_is_v_over_kv() {
        // docs/METHODS.md: 50 mm/s ramp, steady following error 71.4 µm (= v/Kv, Kv = 700 1/s).
        let v = 0.05;
        let (dt, n) = (2e-4, 1001);
        let y = notes_tf().ramp_response(v, dt, n).unwrap();
        let t = (n - 1) as f64 * dt;
        let err = v * t - y[n - 1];
        assert!(
            (err * 1e6 - 71.4).abs() < 0.05,
            "following error {} µm",
            err * 1e6
        );
        // Exact steady value from the coefficients: v·(D1 − N1)/D0.
        let want = v * (RIG_DEN[6] - RIG_NUM[1]) / RIG_DEN[7];
        assert!((err - want).abs() < 1e-9 * want, "{err} vs {want}");
    }

    #[test]
    fn notes_state_space_round_trip_preserves_coefficients() {
        let g = notes_tf();
        let back = g.to_state_space().unwrap().to_tf().unwrap();
        let want = g.normalized();
        assert_coeffs_close(back.den(), want.den(), 1e-9, "den");
        assert_coeffs_close(back.num(), want.num(), 1e-9, "num");
    }

    #[test]
    fn random_strictly_proper_round_trip_preserves_coefficients() {
        // Poles and zeros spread over four decades. Accuracy limit (3000-case
        // sweep of this generator): median 1e-15, 99th percentile 1e-13; a
        // cluster of ≥ 5 zeros 3 decades below the poles reaches 1e-7.
        let mut rng = ChaCha8Rng::seed_from_u64(2024);
        for case in 0..200 {
            let n = rng.random_range(1..=8);
            let m = rng.random_range(0..n);
            let roots = |count: usize, rng: &mut ChaCha8Rng| {
                let mut r = Vec::new();
                while r.len() < count {
                    let wn = 10f64.powf(rng.random_range(0.0..4.0));
                    if count - r.len() >= 2 && rng.random_bool(0.5) {
                        let z: f64 = rng.random_range(0.05..0.95);
                        let (re, im) = (-z * wn, wn * (1.0 - z * z).sqrt());
                        r.push(Complex::new(re, im));
                        r.push(Complex::new(re, -im));
                    } else {
                        r.push(Complex::new(-wn, 0.0));
                    }
                }
                r
            };
            let den_scale = 10f64.powf(rng.random_range(-8.0..2.0));
            let num_scale = 10f64.powf(rng.random_range(-3.0..10.0));
            let den: Vec<f64> = poly_from_roots(&roots(n, &mut rng))
                .iter()
                .map(|c| c * den_scale)
                .collect();
            let num: Vec<f64> = poly_from_roots(&roots(m, &mut rng))
                .iter()
                .map(|c| c * num_scale)
                .collect();
            let g = TransferFunction::new(num, den).unwrap();
            let back = g.to_state_space().unwrap().to_tf().unwrap();
            let want = g.normalized();
            let what = format!("case {case} (n={n}, m={m})");
            assert_coeffs_close(back.den(), want.den(), 1e-9, &format!("{what} den"));
            assert_coeffs_close(back.num(), want.num(), 1e-9, &format!("{what} num"));
        }
    }

    #[test]
    fn random_biproper_round_trip_preserves_coefficients() {
        // deg N = deg D: D·det(sI − A) plus the strictly proper part, or the
        // zeros of A − B·C/D when those two cancel.
        let mut rng = ChaCha8Rng::seed_from_u64(99);
        for case in 0..100 {
            let n = rng.random_range(1..=7);
            let real_roots = |rng: &mut ChaCha8Rng| -> Vec<Complex<f64>> {
                (0..n)
                    .map(|_| Complex::new(-10f64.powf(rng.random_range(2.0..3.0)), 0.0))
                    .collect()
            };
            let d0: f64 = rng.random_range(0.1..10.0);
            let den = poly_from_roots(&real_roots(&mut rng));
            let num: Vec<f64> = poly_from_roots(&real_roots(&mut rng))
                .iter()
                .map(|c| c * d0)
                .collect();
            let g = TransferFunction::new(num, den).unwrap();
            let ss = g.to_state_space().unwrap();
            assert!((ss.d - d0).abs() <= 1e-15 * d0);
            let back = ss.to_tf().unwrap();
            assert_coeffs_close(back.den(), g.den(), 1e-9, &format!("case {case} den"));
            assert_coeffs_close(back.num(), g.num(), 1e-9, &format!("case {case} num"));
        }
    }

    #[test]
    fn biproper_tf_is_realised_with_feedthrough() {
        // (2s + 3)/(s + 1) = 2 + 1/(s + 1)
        let g = TransferFunction::new(vec![2.0, 3.0], vec![1.0, 1.0]).unwrap();
        let ss = g.to_state_space().unwrap();
        assert_eq!(ss.d, 2.0);
        let y = g.step_response(0.1, 20).unwrap();
        for (k, yk) in y.iter().enumerate() {
            let want = 3.0 - (-(k as f64) * 0.1).exp();
            assert!((yk - want).abs() < 1e-12, "{k}: {yk} vs {want}");
        }
        let back = ss.to_tf().unwrap();
        assert_coeffs_close(back.num(), &[2.0, 3.0], 1e-13, "num");
        assert_coeffs_close(back.den(), &[1.0, 1.0], 1e-13, "den");
    }

    #[test]
    fn dc_gain_handles_integrators_and_common_factors() {
        let integ = TransferFunction::new(vec![-2.0], vec![1.0, 0.0]).unwrap();
        assert_eq!(integ.dc_gain(), f64::NEG_INFINITY);
        let cancel = TransferFunction::new(vec![3.0, 0.0], vec![1.0, 2.0, 0.0]).unwrap();
        assert_eq!(cancel.dc_gain(), 1.5);
        let zero = TransferFunction::new(vec![0.0], vec![1.0, 2.0]).unwrap();
        assert_eq!(zero.dc_gain(), 0.0);
        assert!(zero.zeros().unwrap().is_empty());
    }

    #[test]
    fn normalized_scales_to_monic_denominator() {
        let g = TransferFunction::new(vec![4.0, 2.0], vec![2.0, 6.0, 8.0])
            .unwrap()
            .normalized();
        assert_eq!(g.den(), &[1.0, 3.0, 4.0]);
        assert_eq!(g.num(), &[2.0, 1.0]);
    }

    #[test]
    fn invalid_sample_time_is_rejected() {
        let g = TransferFunction::new(vec![1.0], vec![1.0, 1.0]).unwrap();
        assert!(matches!(
            g.step_response(0.0, 3),
            Err(Error::InvalidParameter { name: "dt", .. })
        ));
        assert!(matches!(
            g.ramp_response(1.0, f64::NAN, 3),
            Err(Error::InvalidParameter { .. })
        ));
    }
}
