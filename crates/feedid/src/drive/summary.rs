//! A summary of the nominal model for people: stiffness and inertia, N and D,
//! poles with frequency and damping, bandwidth and following error.

use std::fmt;

use serde::Serialize;

use crate::drive::{closed_loop_coefficients, D1Variant, RigParams};
use crate::error::Result;
use crate::lti::{Complex, TransferFunction};

/// One pole with its natural frequency and damping ratio.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PoleInfo {
    /// Real part \[rad/s\].
    pub re: f64,
    /// Imaginary part \[rad/s\].
    pub im: f64,
    /// Natural frequency |p|/2π \[Hz\].
    pub freq_hz: f64,
    /// Damping ratio −Re(p)/|p| (1 for a real stable pole).
    pub damping: f64,
}

impl PoleInfo {
    /// Describe a pole.
    pub fn new(p: Complex<f64>) -> Self {
        let w = p.norm();
        Self {
            re: p.re,
            im: p.im,
            freq_hz: w / (2.0 * std::f64::consts::PI),
            damping: if w > 0.0 { -p.re / w } else { 1.0 },
        }
    }
}

/// Everything `feedid model` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSummary {
    /// Equivalent axial stiffness K \[N/m\] (eq. 1).
    #[serde(rename = "K")]
    pub k: f64,
    /// Total inertia J \[kg·m²\] (eq. 2).
    #[serde(rename = "J")]
    pub j: f64,
    /// Screw stiffness E·A/l \[N/m\].
    pub k_screw: f64,
    /// Screw inertia \[kg·m²\].
    pub j_screw: f64,
    /// Transmission ratio r = lead/2π \[m/rad\].
    pub r: f64,
    /// Numerator `[N2, N1, N0]`, descending powers of s, normalised so D7 = J·L·M
    /// (`[N4, N3, N2, N1, N0]` with acceleration feed-forward, `[N3, …, N0]` with
    /// velocity feed-forward only).
    pub num: Vec<f64>,
    /// Denominator `[D7, …, D0]`, descending powers of s.
    pub den: Vec<f64>,
    /// Poles as `[re, im]` pairs \[rad/s\].
    pub poles: Vec<[f64; 2]>,
    /// Poles with frequency and damping, sorted by frequency.
    pub pole_details: Vec<PoleInfo>,
    /// Whether every pole has a negative real part ([`crate::drive::check_model`]).
    pub stable: bool,
    /// −3 dB bandwidth of Xa/Xs \[Hz\]; `None` (JSON `null`) when outside the
    /// scanned 0.01 Hz … 100 kHz (see [`bandwidth_hz`]) or the loop is unstable.
    pub bandwidth_hz: Option<f64>,
    /// DC gain (1 for the corrected coefficients).
    pub dc_gain: f64,
    /// Steady ramp following error per command velocity `(D1 − N1)/D0` \[s\] (= (1 − kvff)/Kv).
    pub following_error_s: f64,
    /// Which D1 was used.
    pub d1_variant: String,
}

impl ModelSummary {
    /// The time constant of the slowest pole, `1/|Re p|` \[s\] (∞ for a pole
    /// at 0, 0 without poles).
    pub fn slowest_pole_s(&self) -> f64 {
        self.pole_details
            .iter()
            .map(|p| 1.0 / p.re.abs())
            .fold(0.0, f64::max)
    }

    /// Summarise the nominal model of `params`.
    pub fn new(params: &RigParams, variant: D1Variant) -> Result<Self> {
        let stable = crate::drive::check_model(params)?.stable;
        let c = closed_loop_coefficients(params, variant);
        let tf = c.transfer_function()?;
        let mut poles = tf.poles()?;
        poles.sort_by(|a, b| a.norm().total_cmp(&b.norm()).then(a.im.total_cmp(&b.im)));
        Ok(Self {
            k: params.stiffness_k(),
            j: params.inertia_j(),
            k_screw: params.screw_stiffness(),
            j_screw: params.screw_inertia(),
            r: params.r(),
            num: tf.num().to_vec(),
            den: c.den.to_vec(),
            poles: poles.iter().map(|p| [p.re, p.im]).collect(),
            pole_details: poles.iter().map(|&p| PoleInfo::new(p)).collect(),
            stable,
            bandwidth_hz: if stable { bandwidth_hz(&tf) } else { None },
            dc_gain: c.dc_gain(),
            following_error_s: c.following_error_per_velocity(),
            d1_variant: match variant {
                D1Variant::Corrected => "corrected".to_string(),
                D1Variant::PaperPrinted => "paper-printed".to_string(),
            },
        })
    }
}

/// −3 dB bandwidth \[Hz\]: first frequency where |G| falls below |G(0)|/√2
/// (log scan 0.01 Hz … 100 kHz, refined by bisection); `None` if the gain
/// is already below at 0.01 Hz, does not fall below up to 100 kHz, or is not finite.
pub fn bandwidth_hz(tf: &TransferFunction) -> Option<f64> {
    let g0 = tf.dc_gain().abs();
    let target = g0 / std::f64::consts::SQRT_2;
    let mag = |f: f64| {
        tf.eval(Complex::new(0.0, 2.0 * std::f64::consts::PI * f))
            .norm()
    };
    let mut lo = 0.01;
    let m0 = mag(lo);
    if !g0.is_finite() || g0 == 0.0 || m0.is_nan() || m0 < target {
        return None;
    }
    let steps = 700;
    for k in 1..=steps {
        let f = 0.01 * 10f64.powf(7.0 * k as f64 / steps as f64);
        if mag(f) < target {
            let mut hi = f;
            for _ in 0..60 {
                let mid = (lo * hi).sqrt();
                if mag(mid) < target {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let bw = (lo * hi).sqrt();
            return bw.is_finite().then_some(bw);
        }
        lo = f;
    }
    None
}

impl fmt::Display for ModelSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "Mechanics (paper eq. 1, 2)")?;
        writeln!(
            f,
            "  equivalent stiffness K  {:.4e} N/m   (screw E·A/l {:.4e} N/m)",
            self.k, self.k_screw
        )?;
        writeln!(
            f,
            "  total inertia J         {:.4e} kg·m² (screw {:.4e} kg·m²)",
            self.j, self.j_screw
        )?;
        writeln!(f, "  r = lead/2π             {:.6e} m/rad", self.r)?;
        writeln!(
            f,
            "Closed loop Xa/Xs = N(s)/D(s), normalised D7 = J·L·M (D1: {})",
            self.d1_variant
        )?;
        for (k, v) in self.num.iter().enumerate() {
            writeln!(f, "  N{} = {:.6e}", self.num.len() - 1 - k, v)?;
        }
        for (k, v) in self.den.iter().enumerate() {
            writeln!(f, "  D{} = {:.6e}", 7 - k, v)?;
        }
        writeln!(f, "Poles")?;
        writeln!(
            f,
            "  {:>14} {:>14} {:>10} {:>8}",
            "re [rad/s]", "im [rad/s]", "f [Hz]", "zeta"
        )?;
        for p in &self.pole_details {
            writeln!(
                f,
                "  {:>14.3} {:>14.3} {:>10.1} {:>8.3}",
                p.re, p.im, p.freq_hz, p.damping
            )?;
        }
        if self.stable {
            writeln!(
                f,
                "Stability                 stable (every pole has a negative real part)"
            )?;
        } else {
            let n = self.poles.iter().filter(|p| p[0] >= 0.0).count();
            if n > 0 {
                writeln!(
                    f,
                    "Stability                 UNSTABLE: {n} poles with a non-negative real part; \
                     the axis would run away, so the bandwidth and following error do not apply"
                )?;
            } else {
                // no pole in the right half plane, yet not stable: the poles
                // could not be computed (gains or masses of absurd sizes)
                writeln!(
                    f,
                    "Stability                 NOT STABLE: the closed loop's poles cannot be \
                     computed from these parameters (a gain or mass of an absurd size?), so the \
                     bandwidth and following error do not apply"
                )?;
            }
        }
        match (self.stable, self.bandwidth_hz) {
            (false, _) => writeln!(f, "Bandwidth (−3 dB)         none (unstable)")?,
            (true, Some(bw)) => writeln!(f, "Bandwidth (−3 dB)         {bw:.1} Hz")?,
            (true, None) => writeln!(f, "Bandwidth (−3 dB)         outside 0.01 Hz … 100 kHz")?,
        }
        writeln!(f, "DC gain                   {:.9}", self.dc_gain)?;
        write!(
            f,
            "Following error           {} ms × velocity ({} µm at 50 mm/s){}",
            fixed_or_e(1e3 * self.following_error_s, 4),
            fixed_or_e(0.05 * self.following_error_s * 1e6, 1),
            if !self.stable {
                " — not reached: unstable"
            } else if self.following_error_s > SLOW_FOLLOWING_S
                || self.slowest_pole_s() > SLOW_POLE_S
            {
                " — the axis barely follows its command: a gain far too small?"
            } else {
                ""
            }
        )
    }
}

/// A pole slower than this time constant \[s\] (a current or velocity
/// loop gain of an absurd size) marks a loop whose axis barely moves,
/// whatever the position loop's following error says.
const SLOW_POLE_S: f64 = 100.0;

/// A following error beyond this many seconds per m/s (the axis lags a
/// 50 mm/s move by more than 50 mm) marks a loop too slow to be meant.
const SLOW_FOLLOWING_S: f64 = 1.0;

/// `v` with `decimals` decimals when its magnitude is within [1e-3, 1e6),
/// else in e-notation (`1e300`, not three hundred digits).
fn fixed_or_e(v: f64, decimals: usize) -> String {
    if v == 0.0 || !v.is_finite() || (1e-3..1e6).contains(&v.abs()) {
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first_order(corner_hz: f64) -> TransferFunction {
        let w = 2.0 * std::f64::consts::PI * corner_hz;
        TransferFunction::new(vec![1.0], vec![1.0 / w, 1.0]).unwrap()
    }

    #[test]
    fn bandwidth_of_first_order_is_its_corner_frequency() {
        let bw = bandwidth_hz(&first_order(120.0)).unwrap();
        assert!((bw / 120.0 - 1.0).abs() < 1e-6, "{bw}");
    }

    #[test]
    fn bandwidth_outside_the_scan_is_none_not_infinite() {
        assert_eq!(bandwidth_hz(&first_order(1e-4)), None);
        assert_eq!(bandwidth_hz(&first_order(1e7)), None);
    }

    #[test]
    fn an_unstable_rig_says_so_and_has_no_bandwidth() {
        let mut p = RigParams::default();
        p.control.kv = 5000.0;
        p.control.kp = 1e5;
        let s = ModelSummary::new(&p, D1Variant::Corrected).unwrap();
        assert!(!s.stable);
        assert_eq!(s.bandwidth_hz, None);
        let text = s.to_string();
        assert!(text.contains("UNSTABLE: 2 poles"), "{text}");
        let json = serde_json::to_value(&s).unwrap();
        assert_eq!(json["stable"], serde_json::Value::Bool(false));
        let ok = ModelSummary::new(&RigParams::default(), D1Variant::Corrected).unwrap();
        assert!(ok.stable && ok.to_string().contains("stable (every pole"));
    }

    #[test]
    fn extreme_gains_give_a_finite_summary_or_an_error() {
        // kv = 1e-300 used to print "inf Hz": the bandwidth is far below 0.01 Hz
        let mut p = RigParams::default();
        p.control.kv = 1e-300;
        if let Ok(s) = ModelSummary::new(&p, D1Variant::Corrected) {
            assert_eq!(s.bandwidth_hz, None);
            let json = serde_json::to_string(&s).unwrap();
            assert!(
                !json.replace("\"bandwidth_hz\":null", "").contains("null"),
                "{json}"
            );
        }
    }
}
