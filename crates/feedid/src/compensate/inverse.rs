//! Stable inversion of a sampled SISO model, for a command computed offline
//! over a whole desired trajectory.
//!
//! The model in factored form (powers of the shift `q⁻¹`, `a₀ = 1`):
//!
//! ```text
//! G(q) = g·q^{−d}·∏ᵢ(1 − zᵢ·q⁻¹) / ∏ⱼ(1 − pⱼ·q⁻¹)
//! ```
//!
//! with gain `g` (first non-zero Markov parameter), delay `d ≥ 0`, zeros `zᵢ`
//! and poles `pⱼ` (from a state-space model: the eigenvalues of its zero
//! dynamics and of `A`, [`DiscreteStateSpace::zeros`] — never the roots of
//! its numerator polynomial, which fast sampling makes ill-conditioned). The inverse `u = G⁻¹·y` is applied as a cascade of first-
//! and second-order sections (real roots, conjugate pairs), never as one
//! high-order polynomial, so the poles of a fast-sampled model clustered near
//! `z = 1` cost no accuracy:
//!
//! 1. advance by `d` samples: `s[k] = y[k + d]`;
//! 2. every pole factor `(1 − p·q⁻¹)` as a two-tap FIR filter;
//! 3. zeros inside the unit circle (`|z| < 1 − δ`): causal recursion
//!    `v[k] = t[k] + z·v[k−1]` (stable);
//! 4. zeros on or near the unit circle cannot be inverted by a bounded (or
//!    a short) filter: replaced by the zero-phase-error approximation of
//!    Tomizuka's ZPETC, `1/(1 − z·q⁻¹) ≈ (1 − z·q)/(1 − z)²` (exact gain at
//!    DC, zero phase, gain error growing with frequency). "Near" is
//!    `||z| − 1| ≤ δ` for a zero in the left half plane (`Re z < 0`, where
//!    the exact inverse would ring at up to the Nyquist frequency with gain
//!    `1/||z| − 1|`: the spurious zeros of an identified model lie there),
//!    and `1 ≤ |z| ≤ 1 + 2e-4` in the right half plane (an anti-causal
//!    inverse that would take more than 200 000 samples to settle). A slow
//!    zero just inside the circle near `z = 1` (a fast-sampled model's
//!    slow mode, nearly cancelled by a pole) is always inverted exactly by
//!    step 3: the approximation's gain at the Nyquist frequency,
//!    `(1 + z)/(1 − z)²`, would be 10⁸ for `1 − z = 1.5·10⁻⁴`;
//! 5. zeros outside (`|z| > 1 + δ`, e.g. the sampling zeros of a model of
//!    relative degree ≥ 3): anti-causal recursion run backwards from the end,
//!    `u[k−1] = (u[k] − w[k])/z`, started at the steady state — the exact
//!    bounded (non-causal) inverse of stable inversion;
//! 6. divide by `g`.
//!
//! For a trajectory that starts at rest and ends at rest the result is the
//! exact inverse (up to rounding) wherever no zero needed step 4: the model
//! driven by `u` reproduces `y` at every sample. The signal is extended with
//! its final value by enough samples for every causal section to settle (to
//! 1e-17, at most 200 000 samples; what is left of a slower one only shifts
//! the start of the backward pass, which forgets it within its own settling,
//! added to the extension) before the backward pass starts; the anti-causal
//! part makes the
//! command move before the trajectory does ("pre-actuation"), and whatever of
//! it would fall before the first sample is lost.
//!
//! References: M. Tomizuka, "Zero phase error tracking algorithm for digital
//! control", J. Dyn. Sys. Meas. Control 109 (1987); S. Devasia, D. Chen,
//! B. Paden, "Nonlinear inversion-based output tracking", IEEE TAC 41 (1996);
//! K.J. Åström, P. Hagander, J. Sternby, "Zeros of sampled systems",
//! Automatica 20 (1984).

use nalgebra::Complex;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::lti::{poly_roots, DiscreteStateSpace};

/// Causal sections are run until their transient is below this fraction.
const SETTLE: f64 = 1e-17;

/// Longest extension of the trajectory \[samples\].
const MAX_TAIL: usize = 200_000;

/// Half-width of the band outside the unit circle where a zero in the right
/// half plane gets the zero-phase approximation: closer, its exact
/// (anti-causal) inverse would take more than [`MAX_TAIL`] samples to settle.
const SLOW_BAND: f64 = 2e-4;

/// Most samples of a slow causal zero's settling counted in
/// [`StableInverse::settle`] (the margins a caller extends a trajectory by;
/// the tail itself covers it up to [`MAX_TAIL`]).
const SETTLE_CAP: usize = 20_000;

/// How one zero of the model is inverted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ZeroHandling {
    /// Inside the unit circle: inverted by a stable causal recursion (exact).
    Causal,
    /// Outside the unit circle: inverted by a stable anti-causal recursion (exact, pre-actuation).
    AntiCausal,
    /// On the unit circle: zero-phase-error approximation (not exact).
    ZeroPhase,
}

/// A zero of the sampled model and how it is inverted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ZeroInfo {
    /// Real part (z-plane).
    pub re: f64,
    /// Imaginary part (z-plane).
    pub im: f64,
    /// Modulus `|z|`.
    pub modulus: f64,
    /// How it is inverted.
    pub handling: ZeroHandling,
}

/// A real first-order factor `1 − z·q⁻¹` or a real quadratic `1 − c1·q⁻¹ + c2·q⁻²`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Factor {
    Real(f64),
    Pair(f64, f64),
}

impl Factor {
    /// Value at q = 1.
    fn at_one(self) -> f64 {
        match self {
            Factor::Real(z) => 1.0 - z,
            Factor::Pair(c1, c2) => 1.0 - c1 + c2,
        }
    }

    /// Real part of the root(s).
    fn real_part(self) -> f64 {
        match self {
            Factor::Real(z) => z,
            Factor::Pair(c1, _) => 0.5 * c1,
        }
    }

    /// Modulus of the root(s).
    fn modulus(self) -> f64 {
        match self {
            Factor::Real(z) => z.abs(),
            Factor::Pair(_, c2) => c2.abs().sqrt(),
        }
    }
}

/// How a zero of modulus `m` and real part `re` is inverted (module doc):
/// causally inside the unit circle, anti-causally outside it, with the
/// zero-phase approximation within `margin` of it in the left half plane
/// and within [`SLOW_BAND`] outside it in the right half plane. A slow zero
/// just inside the circle near `z = 1` is inverted exactly: there the
/// approximation's gain `(1 + z)/(1 − z)²` would reach 10⁸ at the Nyquist
/// frequency for `1 − z = 1.5·10⁻⁴`.
fn handling_of(m: f64, re: f64, margin: f64) -> ZeroHandling {
    let band = if re < 0.0 {
        margin.max(SLOW_BAND)
    } else {
        SLOW_BAND
    };
    if m < 1.0 - band || (re >= 0.0 && m < 1.0) {
        ZeroHandling::Causal
    } else if m > 1.0 + band {
        ZeroHandling::AntiCausal
    } else {
        ZeroHandling::ZeroPhase
    }
}

/// Group roots into real factors and conjugate pairs.
fn factors(roots: &[Complex<f64>]) -> Result<Vec<Factor>> {
    let mut out = Vec::new();
    let mut upper = 0usize;
    let mut lower = 0usize;
    for r in roots {
        let tol = 1e-12 * r.norm().max(1.0);
        if r.im.abs() <= tol {
            out.push(Factor::Real(r.re));
        } else if r.im > 0.0 {
            upper += 1;
            out.push(Factor::Pair(2.0 * r.re, r.norm_sqr()));
        } else {
            lower += 1;
        }
    }
    if upper != lower {
        return Err(Error::InvalidModel {
            reason: "complex roots of a real model without their conjugates",
        });
    }
    Ok(out)
}

/// The stable inverse of a sampled model (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct StableInverse {
    gain: f64,
    delay: usize,
    poles: Vec<Factor>,
    causal: Vec<Factor>,
    zero_phase: Vec<Factor>,
    anticausal: Vec<Factor>,
    zeros: Vec<ZeroInfo>,
    tail: usize,
    settle: usize,
}

impl StableInverse {
    /// From gain `g`, delay `d` \[samples\], zeros and poles (z-plane); zeros
    /// within `margin` of the unit circle get the zero-phase approximation.
    pub fn from_roots(
        gain: f64,
        delay: usize,
        zeros: &[Complex<f64>],
        poles: &[Complex<f64>],
        margin: f64,
    ) -> Result<Self> {
        if !gain.is_finite() || gain == 0.0 {
            return Err(Error::InvalidModel {
                reason: "the model's gain (first Markov parameter) is zero or not finite",
            });
        }
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "unit-circle margin",
                value: margin,
                reason: "must be finite and >= 0",
            });
        }
        if zeros
            .iter()
            .chain(poles)
            .any(|z| !(z.re.is_finite() && z.im.is_finite()))
        {
            return Err(Error::InvalidModel {
                reason: "non-finite pole or zero",
            });
        }
        let mut causal = Vec::new();
        let mut zero_phase = Vec::new();
        let mut anticausal = Vec::new();
        for f in factors(zeros)? {
            let handling = handling_of(f.modulus(), f.real_part(), margin);
            if handling == ZeroHandling::Causal {
                causal.push(f);
            } else if handling == ZeroHandling::AntiCausal {
                anticausal.push(f);
            } else {
                if f.at_one().abs() < 1e-12 {
                    return Err(Error::InvalidModel {
                        reason:
                            "the model has a zero at z = 1 (zero DC gain) and cannot be inverted",
                    });
                }
                zero_phase.push(f);
            }
        }
        let zeros_info = zeros
            .iter()
            .map(|z| ZeroInfo {
                re: z.re,
                im: z.im,
                modulus: z.norm(),
                handling: handling_of(z.norm(), z.re, margin),
            })
            .collect();
        // the causal sections settle within the tail, so that the backward
        // passes start from the steady state; a slow zero's settling is cut
        // at MAX_TAIL, and what is left of it then only shifts the
        // anti-causal sections' start, which they forget within their own
        // settling (added to the tail)
        let mut causal_settle = delay + 4;
        for f in &causal {
            let m = f.modulus();
            if m > 0.0 {
                let n = (SETTLE.ln() / m.ln()).ceil();
                causal_settle = causal_settle.max(if n.is_finite() {
                    n as usize + 4
                } else {
                    usize::MAX
                });
            }
        }
        let mut settle = delay + 4;
        for f in &anticausal {
            let m = f.modulus();
            let n = (SETTLE.ln() / (1.0 / m).ln()).ceil();
            settle = settle.max(if n.is_finite() {
                n as usize + 4
            } else {
                usize::MAX
            });
        }
        if settle > MAX_TAIL {
            return Err(Error::InvalidModel {
                reason: "a zero is so close to the unit circle that its inverse does not settle; increase the unit-circle margin",
            });
        }
        let tail = if causal_settle > MAX_TAIL {
            MAX_TAIL + settle
        } else {
            causal_settle.max(settle)
        };
        let settle = settle.max(causal_settle.min(SETTLE_CAP));
        Ok(Self {
            gain,
            delay,
            poles: factors(poles)?,
            causal,
            zero_phase,
            anticausal,
            zeros: zeros_info,
            tail,
            settle,
        })
    }

    /// From discrete `B(q⁻¹)/A(q⁻¹)` coefficients (`a[0] ≠ 0`).
    pub fn from_polynomials(b: &[f64], a: &[f64], margin: f64) -> Result<Self> {
        let a0 = a.first().copied().unwrap_or(0.0);
        if a0 == 0.0 || !a0.is_finite() {
            return Err(Error::InvalidModel {
                reason: "discrete model needs a[0] != 0",
            });
        }
        let delay = b
            .iter()
            .position(|&v| v != 0.0)
            .ok_or(Error::InvalidModel {
                reason: "the model's numerator is zero",
            })?;
        let beta = &b[delay..];
        Self::from_roots(
            beta[0] / a0,
            delay,
            &poly_roots(beta)?,
            &poly_roots(a)?,
            margin,
        )
    }

    /// From a discrete state-space model (its transfer function in `z`).
    pub fn from_state_space(sys: &DiscreteStateSpace, margin: f64) -> Result<Self> {
        // zeros from the zero dynamics, poles from A: never the roots of a
        // polynomial, whose roots near z = 1 a fast-sampled model loses
        let (gain, delay, zeros) = sys.zeros()?;
        Self::from_roots(gain, delay, &zeros, &sys.poles()?, margin)
    }

    /// The model's zeros and how each is inverted.
    pub fn zeros(&self) -> &[ZeroInfo] {
        &self.zeros
    }

    /// Delay `d` of the model \[samples\].
    pub fn delay(&self) -> usize {
        self.delay
    }

    /// The model's DC gain `g·∏(1 − zᵢ)/∏(1 − pⱼ)`.
    pub fn dc_gain(&self) -> f64 {
        let num: f64 = self
            .causal
            .iter()
            .chain(&self.zero_phase)
            .chain(&self.anticausal)
            .map(|f| f.at_one())
            .product();
        let den: f64 = self.poles.iter().map(|f| f.at_one()).product();
        self.gain * num / den
    }

    /// Scale the model's gain by `factor` (e.g. to make its DC gain 1).
    pub fn scale_gain(&mut self, factor: f64) {
        self.gain *= factor;
    }

    /// True when every zero is inverted exactly (no zero-phase approximation).
    pub fn is_exact(&self) -> bool {
        self.zero_phase.is_empty()
    }

    /// Samples appended after the trajectory for the causal sections to settle.
    pub fn tail(&self) -> usize {
        self.tail
    }

    /// Samples over which any section's response to a change has decayed
    /// below 1e-17 of it, forward (causal zeros) or backward (anti-causal
    /// zeros, i.e. the pre-actuation); at least [`StableInverse::tail`].
    pub fn settle(&self) -> usize {
        self.settle
    }

    /// The input `u` whose response is `y` (both deviations from the rest
    /// state, `y` at rest before its first sample and held at its last value
    /// after it); `out` gets `y.len()` samples. `work` is resized as needed
    /// (no allocation when it already has `y.len() + tail()` entries).
    pub fn apply_into(&self, y: &[f64], out: &mut [f64], work: &mut Vec<f64>) -> Result<()> {
        let n = y.len();
        if out.len() != n {
            return Err(Error::LengthMismatch {
                what: "inverse output",
                expected: n,
                actual: out.len(),
            });
        }
        if n == 0 {
            return Ok(());
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "desired trajectory".to_string(),
                index: i,
                value: y[i],
            });
        }
        let len = n + self.tail;
        work.clear();
        work.extend((0..len).map(|k| y[(k + self.delay).min(n - 1)]));
        let s = &mut work[..];
        // pole factors: FIR, newest first so that older samples are still unfiltered
        for f in &self.poles {
            match *f {
                Factor::Real(p) => {
                    for k in (0..len).rev() {
                        let prev = if k >= 1 { s[k - 1] } else { 0.0 };
                        s[k] -= p * prev;
                    }
                }
                Factor::Pair(c1, c2) => {
                    for k in (0..len).rev() {
                        let p1 = if k >= 1 { s[k - 1] } else { 0.0 };
                        let p2 = if k >= 2 { s[k - 2] } else { 0.0 };
                        s[k] += -c1 * p1 + c2 * p2;
                    }
                }
            }
        }
        // causal zero sections: forward recursions
        for f in &self.causal {
            match *f {
                Factor::Real(z) => {
                    for k in 1..len {
                        s[k] += z * s[k - 1];
                    }
                }
                Factor::Pair(c1, c2) => {
                    for k in 1..len {
                        let p2 = if k >= 2 { s[k - 2] } else { 0.0 };
                        s[k] += c1 * s[k - 1] - c2 * p2;
                    }
                }
            }
        }
        // zero-phase approximations: one or two samples of preview, oldest first
        for f in &self.zero_phase {
            let g = 1.0 / (f.at_one() * f.at_one());
            match *f {
                Factor::Real(z) => {
                    for k in 0..len {
                        let next = s[(k + 1).min(len - 1)];
                        s[k] = (s[k] - z * next) * g;
                    }
                }
                Factor::Pair(c1, c2) => {
                    for k in 0..len {
                        let n1 = s[(k + 1).min(len - 1)];
                        let n2 = s[(k + 2).min(len - 1)];
                        s[k] = (s[k] - c1 * n1 + c2 * n2) * g;
                    }
                }
            }
        }
        // anti-causal zero sections: backward recursions from the steady state
        for f in &self.anticausal {
            let steady = s[len - 1] / f.at_one();
            match *f {
                Factor::Real(z) => {
                    // u[k−1] = (u[k] − w[k])/z, u[len−1] = steady
                    let mut u_next = steady;
                    let mut w_next = s[len - 1];
                    s[len - 1] = steady;
                    for k in (0..len - 1).rev() {
                        let u = (u_next - w_next) / z;
                        w_next = s[k];
                        s[k] = u;
                        u_next = u;
                    }
                }
                Factor::Pair(c1, c2) => {
                    // u[k−2] = (w[k] − u[k] + c1·u[k−1])/c2
                    if len < 2 {
                        s[0] = steady;
                        continue;
                    }
                    let (mut u1, mut u0) = (steady, steady); // u[k], u[k−1] with k = len−1
                    let mut w = s[len - 1];
                    let mut w_prev = s[len - 2];
                    s[len - 1] = steady;
                    s[len - 2] = steady;
                    for k in (2..len).rev() {
                        // k: current top index; compute u[k−2]
                        let u = (w - u1 + c1 * u0) / c2;
                        let w_k2 = s[k - 2];
                        s[k - 2] = u;
                        u1 = u0;
                        u0 = u;
                        w = w_prev;
                        w_prev = w_k2;
                    }
                }
            }
        }
        let inv_g = 1.0 / self.gain;
        for (o, v) in out.iter_mut().zip(s.iter()) {
            *o = v * inv_g;
        }
        if let Some(i) = out.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "compensated command".to_string(),
                index: i,
                value: out[i],
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::LinearModel;

    fn simulate(b: &[f64], a: &[f64], u: &[f64]) -> Vec<f64> {
        let m = LinearModel::discrete(b.to_vec(), a.to_vec(), 1.0).unwrap();
        m.discrete_state_space(None)
            .unwrap()
            .simulate(u, None)
            .unwrap()
    }

    /// Largest |a − b| over the samples both have.
    fn largest_gap(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    }

    fn trajectory(n: usize) -> Vec<f64> {
        // smooth rest-to-rest move after 100 samples of rest
        (0..n)
            .map(|k| {
                let t = ((k as f64 - 100.0) / 60.0).clamp(0.0, 1.0);
                t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
            })
            .collect()
    }

    #[test]
    fn minimum_and_non_minimum_phase_models_are_inverted_exactly() {
        // zeros 0.5 (causal), −2.5 (anti-causal), pair 1.5·e^{±0.4i} (anti-causal);
        // poles 0.9, 0.3 ± 0.4i; delay 1
        let zeros = [
            Complex::new(0.5, 0.0),
            Complex::new(-2.5, 0.0),
            Complex::from_polar(1.5, 0.4),
            Complex::from_polar(1.5, -0.4),
        ];
        let poles = [
            Complex::new(0.9, 0.0),
            Complex::new(0.3, 0.4),
            Complex::new(0.3, -0.4),
            Complex::new(-0.2, 0.0),
            Complex::new(0.6, 0.0),
        ];
        let beta: Vec<f64> = crate::lti::poly_from_roots(&zeros)
            .iter()
            .map(|c| 0.3 * c)
            .collect();
        let mut b = vec![0.0];
        b.extend_from_slice(&beta);
        let a = crate::lti::poly_from_roots(&poles);
        let inv = StableInverse::from_polynomials(&b, &a, 1e-6).unwrap();
        assert!(inv.is_exact());
        assert_eq!(inv.delay(), 1);
        let handling: Vec<_> = inv.zeros().iter().map(|z| z.handling).collect();
        assert_eq!(
            handling
                .iter()
                .filter(|h| **h == ZeroHandling::AntiCausal)
                .count(),
            3
        );
        let y = trajectory(300);
        let mut u = vec![0.0; 300];
        inv.apply_into(&y, &mut u, &mut Vec::new()).unwrap();
        let back = simulate(&b, &a, &u);
        let err = largest_gap(&back, &y);
        assert!(err < 1e-13, "{err}");
        // the anti-causal part moves the input before the output
        assert!(u[95].abs() > 1e-6);
        assert!((inv.dc_gain() - b.iter().sum::<f64>() / a.iter().sum::<f64>()).abs() < 1e-12);
    }

    #[test]
    fn zero_on_the_unit_circle_gets_the_zero_phase_approximation() {
        // zero at −1 (Nyquist): no bounded inverse
        let b = [0.0, 0.5, 0.5];
        let a = [1.0, -0.5];
        let inv = StableInverse::from_polynomials(&b, &a, 1e-6).unwrap();
        assert!(!inv.is_exact());
        assert_eq!(inv.zeros()[0].handling, ZeroHandling::ZeroPhase);
        // exact at DC: a constant output needs the constant input 1/G(1)
        let y = vec![1.0; 50];
        let mut u = vec![0.0; 50];
        inv.apply_into(&y, &mut u, &mut Vec::new()).unwrap();
        let g = 1.0 / 0.5;
        assert!((u[49] - 1.0 / g).abs() < 1e-14);
        // and close on a slow trajectory
        let y = trajectory(300);
        let mut u = vec![0.0; 300];
        inv.apply_into(&y, &mut u, &mut Vec::new()).unwrap();
        let back = simulate(&b, &a, &u);
        let err = largest_gap(&back, &y);
        assert!(err < 1e-3, "{err}");
    }

    #[test]
    fn a_slow_zero_just_inside_the_circle_is_inverted_exactly() {
        // a fast-sampled model's slow mode: zero 0.99985 beside pole 0.9997
        // (the causal section settles to 1e-17 only after 260 000 samples,
        // more than the tail allows); unit DC gain
        let beta = crate::lti::poly_from_roots(&[Complex::new(0.99985, 0.0)]);
        let a = crate::lti::poly_from_roots(&[Complex::new(0.9, 0.0), Complex::new(0.9997, 0.0)]);
        let g = 0.1 * 3e-4 / 1.5e-4;
        let mut b = vec![0.0];
        b.extend(beta.iter().map(|c| g * c));
        let inv = StableInverse::from_polynomials(&b, &a, 1e-6).unwrap();
        assert_eq!(inv.zeros()[0].handling, ZeroHandling::Causal);
        assert!(inv.is_exact());
        assert!((inv.dc_gain() - 1.0).abs() < 1e-9);
        assert!(inv.tail() >= MAX_TAIL);
        let y = trajectory(3000);
        let mut u = vec![0.0; 3000];
        inv.apply_into(&y, &mut u, &mut Vec::new()).unwrap();
        // the model driven by u follows y; the command stays of its size
        // (the zero-phase approximation's gain here is (1 + z)/(1 − z)² ≈ 10⁸)
        let back = simulate(&b, &a, &u);
        let err = largest_gap(&back, &y);
        assert!(err < 1e-9, "{err}");
        let peak = u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(peak < 20.0, "{peak}");
    }

    #[test]
    fn zero_at_one_is_refused() {
        let e = StableInverse::from_polynomials(&[0.0, 1.0, -1.0], &[1.0, -0.5], 1e-6).unwrap_err();
        assert!(e.to_string().contains("z = 1"), "{e}");
    }

    #[test]
    fn zpetc_makes_the_loop_zero_phase_with_gain_cos_squared() {
        // G = q⁻¹·(1 + q⁻¹)/2: zero at −1; G·Ĝ⁻¹ = (q + 2 + q⁻¹)/4 = cos²(ω/2)
        let b = [0.0, 0.5, 0.5];
        let a = [1.0];
        let inv = StableInverse::from_polynomials(&b, &a, 0.05).unwrap();
        assert_eq!(inv.zeros()[0].handling, ZeroHandling::ZeroPhase);
        let w = 0.7;
        let y: Vec<f64> = (0..400).map(|k| (w * k as f64).cos()).collect();
        let mut u = vec![0.0; 400];
        inv.apply_into(&y, &mut u, &mut Vec::new()).unwrap();
        let back = simulate(&b, &a, &u);
        let gain = (w / 2.0).cos().powi(2);
        for k in 10..390 {
            assert!((back[k] - gain * y[k]).abs() < 1e-12, "{k}");
        }
    }

    #[test]
    fn only_left_half_plane_zeros_near_the_circle_are_approximated() {
        // zeros −0.97 (ZPETC with margin 0.05) and 0.97 (exact, causal)
        let beta =
            crate::lti::poly_from_roots(&[Complex::new(-0.97, 0.0), Complex::new(0.97, 0.0)]);
        let mut b = vec![0.0];
        b.extend_from_slice(&beta);
        let inv = StableInverse::from_polynomials(&b, &[1.0, -0.5], 0.05).unwrap();
        let h: Vec<_> = inv
            .zeros()
            .iter()
            .map(|z| (z.re > 0.0, z.handling))
            .collect();
        assert!(h.contains(&(false, ZeroHandling::ZeroPhase)));
        assert!(h.contains(&(true, ZeroHandling::Causal)));
        // an anti-causal zero's settle length covers its decay, 1e-17 = 1.5^−n
        let beta = crate::lti::poly_from_roots(&[Complex::new(1.5, 0.0)]);
        let inv = StableInverse::from_polynomials(&beta, &[1.0], 0.05).unwrap();
        let n = (1e-17_f64.ln() / (1.0 / 1.5_f64).ln()).ceil() as usize;
        assert!(inv.settle() >= n);
    }
}
