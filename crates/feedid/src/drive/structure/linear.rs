//! The linear closed loop of a drive structure: the friction law reduced to
//! its viscous term, no saturation, the controller continuous.
//!
//! With the mechanics `P(s) = P_n/P_d` from force to the measured position
//! ([`DriveStructure::plant`]; rigid `1/(s·(M·s + Fv))`), `P_v/P_d` to the
//! position whose velocity the velocity loop feeds back and `P_m/P_d` to
//! the motor's, and each controller `C = N/D` as polynomials, the drive
//! from the controller's output `u` to the force is `F = g·u` (a force
//! source) or, with a current loop `C_i = N_i/D_i` on a winding `L, R` with
//! back-EMF `ke`, `F = g·(N_i·u − D_i·ke·s·X_m)/Δ_i`, `Δ_i = D_i·(L·s + R) +
//! N_i`. With `Q = Δ_i·P_d + g·D_i·ke·s·P_m` (`P_d` for a force source,
//! `N_i = 1`), `A_n = g·N_i·P_n` and `A_v = g·N_i·P_v`, the
//! command-to-position transfer function is, with a velocity loop,
//!
//! ```text
//! X/X_s = A_n·(N_v·(N_p + kvff·s·D_p) + (kaff·M/g)·s²·D_p·D_v)
//!         ──────────────────────────────────────────────────────
//!         Q·D_p·D_v + N_v·(N_p·A_n + s·D_p·A_v)
//! ```
//!
//! and without one (`N_v = D_v = 1`, no velocity feedback)
//! `A_n·(N_p + (kaff·M/g)·s²·D_p) / (Q·D_p + A_n·N_p)`. The following
//! error of a ramp of velocity `v` is `v·lim_{s→0} (D − N)/(s·D)`: with a
//! velocity loop of kind P on a P position loop, `v·(1 − kvff)/kp + v·Fv/(g·kv·kp)`.

use std::fmt;

use serde::Serialize;

use super::{DriveStructure, LoopGains, LoopKind};
use crate::drive::{bandwidth_hz, PoleInfo};
use crate::error::{Error, Result};
use crate::lti::TransferFunction;

/// The linear closed loop of a structure in numbers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StructureSummary {
    /// Numerator of X/X_s, descending powers of s.
    pub numerator: Vec<f64>,
    /// Denominator of X/X_s, descending powers of s.
    pub denominator: Vec<f64>,
    /// Closed-loop poles.
    pub poles: Vec<PoleInfo>,
    /// Every pole in the open left half-plane.
    pub stable: bool,
    /// −3 dB bandwidth of X/X_s \[Hz\], if it has one.
    pub bandwidth_hz: Option<f64>,
    /// Steady following error of a ramp per unit of its velocity \[s\]
    /// (`None`: it grows without bound).
    pub following_error_per_velocity: Option<f64>,
}

/// `a·b` of polynomials in descending powers.
fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// `a + b` of polynomials in descending powers.
fn add(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = a.len().max(b.len());
    let at = |p: &[f64], i: usize| {
        let k = n - p.len();
        if i >= k {
            p[i - k]
        } else {
            0.0
        }
    };
    (0..n).map(|i| at(a, i) + at(b, i)).collect()
}

fn scale(a: &[f64], k: f64) -> Vec<f64> {
    a.iter().map(|x| x * k).collect()
}

/// `C(s) = kp·(1 + ki/s + kd·s)` as `(N, D)`.
fn controller(c: &LoopGains) -> (Vec<f64>, Vec<f64>) {
    let (kp, ki, kd) = c.terms();
    if c.kind == LoopKind::None {
        return (vec![1.0], vec![1.0]);
    }
    if ki > 0.0 {
        // kp·(kd·s² + s + ki)/s
        (vec![kp * kd, kp, kp * ki], vec![1.0, 0.0])
    } else {
        (vec![kp * kd, kp], vec![1.0])
    }
}

/// Drop leading zeros (keeping at least one coefficient).
fn trim(mut p: Vec<f64>) -> Vec<f64> {
    while p.len() > 1 && p[0] == 0.0 {
        p.remove(0);
    }
    p
}

impl DriveStructure {
    /// The command-to-position transfer function of the linear closed loop
    /// (module doc of `linear.rs`).
    pub fn transfer_function(&self) -> Result<TransferFunction> {
        let (np, dp) = controller(&self.position);
        let (nv, dv) = controller(&self.velocity);
        let g = self.drive.gain;
        let m = self.mechanics.total_mass();
        let (kvff, kaff) = (self.feed_forward.velocity, self.feed_forward.acceleration);
        // force to the load's, the motor's position: P = p/pd
        let (pl, pm, pd) = self.plant_sides();
        let side = |measured: super::Measured| match measured {
            super::Measured::Load => pl.clone(),
            super::Measured::Motor => pm.clone(),
        };
        let two_mass = self.mechanics.two_mass();
        let pn = if two_mass {
            side(self.mechanics.measured)
        } else {
            pl.clone()
        };
        let pv = match (two_mass, self.controller.velocity_feedback) {
            (true, Some(v)) => side(v),
            _ => pn.clone(),
        };
        // the drive, output to force F = g·(N_i·u − D_i·ke·s·X_m)/Δ_i:
        // with the plant, F = g·N_i·P_d·u/Q, Q = Δ_i·P_d + g·D_i·ke·s·P_m
        let (ni, q) = match &self.current {
            Some(c) => {
                let (ni, di) = if c.ki > 0.0 {
                    (vec![c.kp, c.kp * c.ki], vec![1.0, 0.0])
                } else {
                    (vec![c.kp], vec![1.0])
                };
                let delta = add(&mul(&di, &[c.inductance, c.resistance]), &ni);
                let emf = scale(&mul(&di, &mul(&[1.0, 0.0], &pm)), g * c.back_emf);
                (ni, add(&mul(&delta, &pd), &emf))
            }
            None => (vec![1.0], pd.clone()),
        };
        // output to measured position: g·N_i·P_n/Q
        let an = scale(&mul(&ni, &pn), g);
        let av = scale(&mul(&ni, &pv), g);
        let s = [1.0, 0.0];
        // the acceleration feed-forward's output kaff·M/g·s²·Xs
        let accel = scale(&mul(&[m, 0.0, 0.0], &an), kaff / g);
        let (num, den) = if self.velocity.kind == LoopKind::None {
            let num = add(&mul(&an, &np), &mul(&accel, &dp));
            let den = add(&mul(&q, &dp), &mul(&an, &np));
            (num, den)
        } else {
            let inner = add(&np, &scale(&mul(&s, &dp), kvff));
            let num = add(&mul(&an, &mul(&nv, &inner)), &mul(&accel, &mul(&dp, &dv)));
            let feedback = add(&mul(&np, &an), &mul(&s, &mul(&dp, &av)));
            let den = add(&mul(&q, &mul(&dp, &dv)), &mul(&nv, &feedback));
            (num, den)
        };
        TransferFunction::new(trim(num), trim(den))
    }

    /// The mechanics from force to the measured position, `(numerator,
    /// denominator)`, viscous friction only: rigid `1/(s·(M·s + Fv + Fv_m))`;
    /// two-mass, with `K = c·s + k`, `A_m = M_m·s² + (c + Fv_m)·s + k`,
    /// `A_l = M_l·s² + (Fv + c)·s + k` and `Δ = A_m·A_l − K²`, `K/Δ` on the
    /// load and `A_l/Δ` on the motor (`Fv_m` the motor side's viscous
    /// friction).
    pub fn plant(&self) -> (Vec<f64>, Vec<f64>) {
        let (pl, pm, pd) = self.plant_sides();
        match self.mechanics.measured {
            super::Measured::Motor if self.mechanics.two_mass() => (pm, pd),
            _ => (pl, pd),
        }
    }

    /// Force to the load's and to the motor's position: `(load numerator,
    /// motor numerator, denominator)` ([`DriveStructure::plant`]).
    fn plant_sides(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mech = &self.mechanics;
        let fv = self.friction.viscous;
        match (mech.stiffness, mech.motor_mass) {
            (Some(k), Some(mm)) => {
                let kk = [mech.damping, k];
                let am = [mm, mech.damping + mech.motor_viscous, k];
                let al = [mech.mass, fv + mech.damping, k];
                let delta = add(&mul(&am, &al), &scale(&mul(&kk, &kk), -1.0));
                (trim(kk.to_vec()), trim(al.to_vec()), trim(delta))
            }
            _ => (
                vec![1.0],
                vec![1.0],
                vec![mech.total_mass(), fv + mech.motor_viscous, 0.0],
            ),
        }
    }

    /// The linear closed loop in numbers: poles, stability, bandwidth,
    /// following error.
    pub fn closed_loop(&self) -> Result<StructureSummary> {
        let tf = self.transfer_function()?;
        let poles = tf.poles()?;
        let stable = poles.iter().all(|p| p.re < 0.0);
        let (num, den) = (tf.num().to_vec(), tf.den().to_vec());
        // e/X_s = (D − N)/D; a ramp's error v·lim (D − N)/(s·D)
        let diff = add(&den, &scale(&num, -1.0));
        let c = |p: &[f64], k: usize| p.len().checked_sub(k + 1).map_or(0.0, |i| p[i]);
        let d0 = c(&den, 0);
        if d0 == 0.0 {
            return Err(Error::InvalidModel {
                reason: "the closed loop has a pole at 0: the structure does not hold a position",
            });
        }
        let scale_of = diff.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        let following_error_per_velocity =
            (c(&diff, 0).abs() <= 1e-12 * scale_of).then(|| c(&diff, 1) / d0);
        Ok(StructureSummary {
            poles: poles.iter().map(|&p| PoleInfo::new(p)).collect(),
            stable,
            bandwidth_hz: if stable { bandwidth_hz(&tf) } else { None },
            following_error_per_velocity,
            numerator: num,
            denominator: den,
        })
    }
}

impl fmt::Display for StructureSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let poly = |p: &[f64]| {
            p.iter()
                .map(|v| format!("{v:.6e}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        writeln!(f, "closed loop X/Xs (descending powers of s):")?;
        writeln!(f, "  numerator   [{}]", poly(&self.numerator))?;
        writeln!(f, "  denominator [{}]", poly(&self.denominator))?;
        writeln!(
            f,
            "poles ({}):",
            if self.stable { "stable" } else { "UNSTABLE" }
        )?;
        for p in &self.poles {
            writeln!(
                f,
                "  {:>12.4} {:+12.4}j rad/s   {:>9.3} Hz   damping {:.3}",
                p.re, p.im, p.freq_hz, p.damping
            )?;
        }
        match self.bandwidth_hz {
            Some(b) => writeln!(f, "bandwidth (−3 dB): {b:.3} Hz")?,
            None => writeln!(f, "bandwidth (−3 dB): none")?,
        }
        match self.following_error_per_velocity {
            Some(e) => writeln!(
                f,
                "following error of a ramp: {:.4} µm per mm/s ({:.6e} s)",
                e * 1e3,
                e
            ),
            None => writeln!(f, "following error of a ramp: grows without bound"),
        }
    }
}
