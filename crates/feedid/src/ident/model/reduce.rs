//! Cancelling pole–zero pairs that change nothing over the time a model is
//! used (MATLAB's `minreal` with a tolerance tied to the recording).
//!
//! A pole `p` and a zero `z` of `G = G₀·(s − z)/(s − p)` differ from `G₀`
//! by the mode
//!
//! ```text
//! G − G₀ = G₀·(p − z)/(s − p),
//! ```
//!
//! whose impulse response `(p − z)·e^{pt}` adds at most
//! `|p − z|·min(T, 1/|Re p|)` to the response to a unit step over a span
//! `T` (discrete: `|p − z|·min(N, 1/(1 − |p|))` over `N` samples). A pair
//! whose figure is below [`NEGLIGIBLE_PAIR`] is cancelled: within the
//! recording the model is the same to that share of a step.
//!
//! Such pairs are what an output-error fit returns when the data cannot
//! tell a pole at the origin from a zero there: a model with a
//! differentiator and a pole at 1e-11 rad/s fits an S-curve perfectly, has
//! a steady-state gain of 0 and cannot be inverted for compensation. With
//! the pair cancelled it is the unit-gain servo it behaves as.
//!
//! A pole that grows within the span (`Re p > 0` with `p·T ≥ 1`, or
//! `|p| > 1` discrete with growth over `N` samples) is never cancelled: the
//! pair is not negligible there.

use nalgebra::Complex;

use super::LinearModel;
use crate::error::{Error, Result};
use crate::lti::{poly_from_roots, poly_roots};

/// Largest change of a unit-step response over the span for which a
/// pole–zero pair is cancelled.
pub const NEGLIGIBLE_PAIR: f64 = 1e-6;

impl LinearModel {
    /// The model with its negligible pole–zero pairs over `span_s` seconds
    /// cancelled (module `ident::model::reduce`), and how many pairs went.
    ///
    /// The gain at high frequency (leading coefficients) is kept; a model
    /// without such pairs comes back unchanged (bit for bit).
    ///
    /// ```
    /// use feedid::ident::LinearModel;
    /// use feedid::lti::TransferFunction;
    /// // 100·s / ((s + 1e-12)(s + 100)): a differentiator behind an
    /// // (almost) integrator, over 10 s the unit-gain lag 100/(s + 100)
    /// let tf = TransferFunction::new(vec![100.0, 0.0], vec![1.0, 100.0 + 1e-12, 1e-10]).unwrap();
    /// let (m, n) = LinearModel::continuous(&tf).without_negligible_pairs(10.0).unwrap();
    /// assert_eq!(n, 1);
    /// assert!((m.dc_gain().unwrap() - 1.0).abs() < 1e-9);
    /// ```
    pub fn without_negligible_pairs(&self, span_s: f64) -> Result<(LinearModel, usize)> {
        self.without_pairs_below(span_s, NEGLIGIBLE_PAIR)
    }

    /// [`LinearModel::without_negligible_pairs`] with the largest change of
    /// a unit-step response over `span_s` seconds for which a pair is
    /// cancelled given (`tolerance`, a share of the step, ≥ 0).
    pub fn without_pairs_below(&self, span_s: f64, tolerance: f64) -> Result<(LinearModel, usize)> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "pair tolerance",
                value: tolerance,
                reason: "must be finite and >= 0 (share of a step)",
            });
        }
        if !(span_s.is_finite() && span_s > 0.0) {
            return Err(Error::InvalidParameter {
                name: "span",
                value: span_s,
                reason: "must be finite and > 0 (s)",
            });
        }
        match self {
            LinearModel::Continuous { num, den } => {
                let (num, den) = (trimmed(num), trimmed(den));
                let (Some(&nl), Some(&dl)) = (num.first(), den.first()) else {
                    return Ok((self.clone(), 0));
                };
                let zeros = poly_roots(num)?;
                let poles = poly_roots(den)?;
                let reach = |p: Complex<f64>| {
                    if p.re > 0.0 && p.re * span_s >= 1.0 {
                        None
                    } else {
                        Some(span_s.min(1.0 / p.re.abs().max(f64::MIN_POSITIVE)))
                    }
                };
                let (zl, pl, n) = cancel(&zeros, &poles, reach, tolerance);
                if n == 0 {
                    return Ok((self.clone(), 0));
                }
                let k = nl / dl;
                Ok((
                    LinearModel::Continuous {
                        num: poly_from_roots(&zl).iter().map(|c| k * c).collect(),
                        den: poly_from_roots(&pl),
                    },
                    n,
                ))
            }
            LinearModel::Discrete { b, a, dt } => {
                let samples = span_s / dt;
                let delay = b.iter().take_while(|&&v| v == 0.0).count();
                if delay == b.len() {
                    return Ok((self.clone(), 0));
                }
                let bz = &b[delay..];
                let zeros = poly_roots(bz)?;
                let poles = poly_roots(trimmed(a))?;
                let reach = |p: Complex<f64>| {
                    let m = p.norm();
                    if m > 1.0 && (m - 1.0) * samples >= 1.0 {
                        None
                    } else {
                        Some(samples.min(1.0 / (1.0 - m).abs().max(f64::MIN_POSITIVE)))
                    }
                };
                let (zl, pl, n) = cancel(&zeros, &poles, reach, tolerance);
                if n == 0 {
                    return Ok((self.clone(), 0));
                }
                let k = bz[0] / a[0];
                let mut nb = vec![0.0; delay];
                nb.extend(poly_from_roots(&zl).iter().map(|c| k * c));
                Ok((LinearModel::discrete(nb, poly_from_roots(&pl), *dt)?, n))
            }
        }
    }
}

/// The polynomial without its leading zero coefficients.
fn trimmed(p: &[f64]) -> &[f64] {
    let first = p.iter().position(|&c| c != 0.0).unwrap_or(p.len());
    &p[first..]
}

/// The zeros and poles left once every negligible pair is cancelled
/// (smallest figure first), and the number of pairs cancelled. `reach(p)`:
/// the time (or samples) over which the pole's mode acts, `None` when it
/// must stay.
fn cancel(
    zeros: &[Complex<f64>],
    poles: &[Complex<f64>],
    reach: impl Fn(Complex<f64>) -> Option<f64>,
    tolerance: f64,
) -> (Vec<Complex<f64>>, Vec<Complex<f64>>, usize) {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, z) in zeros.iter().enumerate() {
        for (j, p) in poles.iter().enumerate() {
            if let Some(r) = reach(*p) {
                let figure = (p - z).norm() * r;
                if figure <= tolerance {
                    pairs.push((figure, i, j));
                }
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut zero_gone = vec![false; zeros.len()];
    let mut pole_gone = vec![false; poles.len()];
    let mut n = 0;
    for (_, i, j) in pairs {
        if !zero_gone[i] && !pole_gone[j] {
            zero_gone[i] = true;
            pole_gone[j] = true;
            n += 1;
        }
    }
    let keep = |v: &[Complex<f64>], gone: &[bool]| {
        v.iter()
            .zip(gone)
            .filter(|(_, g)| !**g)
            .map(|(r, _)| *r)
            .collect::<Vec<_>>()
    };
    (keep(zeros, &zero_gone), keep(poles, &pole_gone), n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::TransferFunction;

    fn cont(num: Vec<f64>, den: Vec<f64>) -> LinearModel {
        LinearModel::continuous(&TransferFunction::new(num, den).unwrap())
    }

    #[test]
    fn a_model_without_negligible_pairs_comes_back_unchanged() {
        let m = cont(vec![2.0, 300.0], vec![1.0, 40.0, 300.0]);
        let (r, n) = m.without_negligible_pairs(100.0).unwrap();
        assert_eq!(n, 0);
        assert_eq!(r, m);
        let d = LinearModel::discrete(vec![0.0, 0.1, 0.05], vec![1.0, -0.85], 1e-3).unwrap();
        let (r, n) = d.without_negligible_pairs(100.0).unwrap();
        assert_eq!((n, r), (0, d));
    }

    #[test]
    fn a_differentiator_behind_a_near_integrator_is_the_lag_it_behaves_as() {
        // the shape of an output-error fit of an S-curve: K·s / (s⁵ + … + K·s + c)
        // with c/K = 1.9e-11 rad/s — steady-state gain 0, unit gain in practice
        let lag = [1.0, 6079.9, 1.4937e7, 1.68043e10, 2.2634557e12];
        let k = 2.2634557e12;
        let mut den = lag.to_vec();
        den.push(42.57);
        let m = cont(vec![k, -9.5e-24], den);
        assert!(m.dc_gain().unwrap().abs() < 1e-20);
        let (r, n) = m.without_negligible_pairs(25.0).unwrap();
        assert_eq!(n, 1);
        let LinearModel::Continuous { num, den } = &r else {
            panic!("continuous stays continuous")
        };
        assert_eq!((num.len(), den.len()), (1, 5));
        for (a, b) in den.iter().zip(lag) {
            assert!((a - b).abs() <= 1e-6 * b.abs(), "{den:?}");
        }
        assert!((r.dc_gain().unwrap() - 1.0).abs() < 1e-6);
        // the responses agree within the span (a step of 1 mm over 2 s at 1 kHz)
        let u: Vec<f64> = (0..2000).map(|k| if k > 10 { 1e-3 } else { 0.0 }).collect();
        let (y0, y1) = (
            m.simulate_at(&u, 1e-3).unwrap(),
            r.simulate_at(&u, 1e-3).unwrap(),
        );
        let worst = y0
            .iter()
            .zip(&y1)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-8, "{worst}");
    }

    #[test]
    fn a_discrete_pair_at_one_goes_and_the_delay_stays() {
        // y = q⁻²·0.2·(1 − q⁻¹)/((1 − 0.8 q⁻¹)(1 − (1 − 1e-13) q⁻¹))
        let c = 1.0 - 1e-13;
        let a = vec![1.0, -(0.8 + c), 0.8 * c];
        let m = LinearModel::discrete(vec![0.0, 0.0, 0.2, -0.2], a, 1e-3).unwrap();
        let (r, n) = m.without_negligible_pairs(60.0).unwrap();
        assert_eq!(n, 1);
        let LinearModel::Discrete { b, a, .. } = &r else {
            panic!("discrete stays discrete")
        };
        assert_eq!(b.len(), 3);
        assert_eq!(&b[..2], &[0.0, 0.0]);
        assert!(
            (b[2] - 0.2).abs() < 1e-12 && (a[1] + 0.8).abs() < 1e-9,
            "{b:?} {a:?}"
        );
        assert!((r.dc_gain().unwrap() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_pair_that_acts_within_the_span_is_kept() {
        // zero at −1.0, pole at −1.001: a 0.1 % slow mode over seconds
        let m = cont(vec![1.0, 1.0], vec![1.0, 101.001, 100.1]);
        assert_eq!(m.without_negligible_pairs(10.0).unwrap().1, 0);
        // an unstable pole is never hidden by a zero beside it
        let u = cont(vec![1.0, -2.0], vec![1.0, -2.0 - 1e-9]);
        assert_eq!(u.without_negligible_pairs(10.0).unwrap().1, 0);
        assert!(m.without_negligible_pairs(0.0).is_err());
        assert!(m.without_negligible_pairs(f64::NAN).is_err());
    }
}
