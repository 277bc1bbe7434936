//! Whether a rig's physical model can be used at all, and whether it is
//! stable — the one check every command makes on a parameter file.
//!
//! [`check_model`] validates the parameters ([`RigParams::validate`]: each
//! value finite and in range, the derived K, J, r finite), then builds the
//! closed loop `Xa/Xs = N(s)/D(s)` and the 7-state model: every coefficient
//! and matrix entry must be finite (values fine one by one, like `kv = 1e300`,
//! overflow together) and the poles must be found. The model is *stable*
//! when every pole of the 7-state matrix has a negative real part
//! (eigenvalues of the balanced state matrix; the poles of `D(s)` agree).
//!
//! [`require_stable`] turns an unstable model into [`Error::UnstableModel`]
//! naming the poles with a positive (or zero) real part: simulating it
//! diverges, and identification against it or compensation with it means
//! nothing.
//!
//! ```
//! use feedid::drive::{check_model, RigParams};
//! assert!(check_model(&RigParams::default()).unwrap().stable);
//! let mut p = RigParams::default();
//! p.control.kv = 5000.0;
//! p.control.kp = 1e5;
//! let c = check_model(&p).unwrap();
//! assert!(!c.stable);
//! assert_eq!(c.unstable_poles().len(), 2);
//! ```

use serde::Serialize;

use crate::drive::{closed_loop_coefficients, closed_loop_state_space, D1Variant, RigParams};
use crate::error::{Error, Result};
use crate::lti::Complex;

/// The outcome of [`check_model`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelCheck {
    /// Poles of the closed loop as `[re, im]` \[rad/s\], sorted by magnitude.
    pub poles: Vec<[f64; 2]>,
    /// Whether every pole has a negative real part.
    pub stable: bool,
}

impl ModelCheck {
    /// The poles with a real part ≥ 0.
    pub fn unstable_poles(&self) -> Vec<[f64; 2]> {
        self.poles.iter().copied().filter(|p| p[0] >= 0.0).collect()
    }

    /// The unstable poles for a message: `1391.3 ± 3976.6j rad/s (670.5 Hz)`, …
    pub fn describe_unstable(&self) -> String {
        let mut parts = Vec::new();
        for p in self.unstable_poles() {
            if p[1] < 0.0 {
                continue; // its conjugate is listed
            }
            let f = p[0].hypot(p[1]) / (2.0 * std::f64::consts::PI);
            parts.push(if p[1] > 0.0 {
                format!("{:.4e} ± {:.4e}j rad/s ({:.4e} Hz)", p[0], p[1], f)
            } else {
                format!("{:.4e} rad/s", p[0])
            });
        }
        parts.join(", ")
    }
}

/// Validate `params` and their model (see the module doc); errors name the
/// offending value or say which part of the model is not finite.
pub fn check_model(params: &RigParams) -> Result<ModelCheck> {
    params.validate()?;
    let c = closed_loop_coefficients(params, D1Variant::Corrected);
    if c.num.iter().chain(&c.den).any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "non-finite closed-loop coefficient (the values overflow together)",
        });
    }
    if c.den.first().is_none_or(|d| *d == 0.0) {
        return Err(Error::InvalidModel {
            reason: "zero leading coefficient of the closed loop",
        });
    }
    let ss = closed_loop_state_space(params)?;
    let mut poles: Vec<Complex<f64>> = ss.balance().poles()?;
    if poles
        .iter()
        .any(|p| !(p.re.is_finite() && p.im.is_finite()))
    {
        return Err(Error::InvalidModel {
            reason: "non-finite pole of the closed loop",
        });
    }
    poles.sort_by(|a, b| a.norm().total_cmp(&b.norm()).then(a.im.total_cmp(&b.im)));
    Ok(ModelCheck {
        stable: poles.iter().all(|p| p.re < 0.0),
        poles: poles.iter().map(|p| [p.re, p.im]).collect(),
    })
}

/// [`check_model`], and [`Error::UnstableModel`] when the model is unstable
/// and `allow_unstable` is false.
pub fn require_stable(params: &RigParams, allow_unstable: bool) -> Result<ModelCheck> {
    let c = check_model(params)?;
    if !c.stable && !allow_unstable {
        return Err(Error::UnstableModel {
            poles: c.describe_unstable(),
        });
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::TransferFunction;

    #[test]
    fn the_default_rig_is_stable_and_its_poles_match_those_of_d() {
        let p = RigParams::default();
        let c = check_model(&p).unwrap();
        assert!(c.stable);
        assert_eq!(c.poles.len(), 7);
        let cl = closed_loop_coefficients(&p, D1Variant::Corrected);
        let tf = TransferFunction::new(cl.num.to_vec(), cl.den.to_vec()).unwrap();
        let mut from_d = tf.poles().unwrap();
        from_d.sort_by(|a, b| a.norm().total_cmp(&b.norm()).then(a.im.total_cmp(&b.im)));
        for (a, b) in c.poles.iter().zip(&from_d) {
            let d = (a[0] - b.re).hypot(a[1] - b.im);
            assert!(d < 1e-6 * b.norm(), "{a:?} vs {b}");
        }
    }

    #[test]
    fn high_gains_are_unstable_and_named_with_their_poles() {
        let mut p = RigParams::default();
        p.control.kv = 5000.0;
        p.control.kp = 1e5;
        let c = check_model(&p).unwrap();
        assert!(!c.stable);
        let e = require_stable(&p, false).unwrap_err().to_string();
        // the pair near 1391 ± 3977j rad/s that `feedid model` prints
        assert!(e.contains("unstable") && e.contains("1.39"), "{e}");
        assert!(e.contains("3.97"), "{e}");
        assert!(require_stable(&p, true).is_ok());
    }

    #[test]
    fn stable_means_no_pole_in_the_right_half_plane() {
        // every value valid one by one; a soft screw with a stiff loop
        let mut p = RigParams::default();
        p.stiffness.nut = 1e3;
        p.stiffness.bearing = 1e3;
        let c = check_model(&p).unwrap();
        assert_eq!(c.stable, c.unstable_poles().is_empty());
    }

    #[test]
    fn values_that_overflow_together_are_refused() {
        let mut p = RigParams::default();
        p.control.kv = 1e300;
        let e = check_model(&p).unwrap_err().to_string();
        assert!(e.contains("non-finite"), "{e}");
        p.control.kv = f64::NAN;
        assert!(check_model(&p).is_err());
    }
}
