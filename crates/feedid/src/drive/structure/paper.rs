//! The paper's cascade as a drive structure: a P position loop on the
//! table, a PI velocity loop on the motor's speed, a PI current loop on the
//! winding (inductance, resistance, back-EMF), and the motor joined to the
//! table by the screw's axial stiffness — the rig's parameters
//! ([`RigParams`]) at the load side, through the screw's `r = h/2π`:
//!
//! ```text
//! motor mass  J/r²      motor viscous  C1/r²     drive gain  Kt/r  (N/A)
//! table mass  M         table viscous  C2        back-EMF    Ke/r  (V/(m/s))
//! stiffness   K (eq. 1)  position kp  Kv   velocity kp, ki  Kp, Ki   current kp, ki  Kpi, Kii
//! ```
//!
//! Its linear closed loop is the paper's 7th-order transfer function
//! ([`crate::drive::closed_loop_coefficients`], corrected `D1`), feed-forward
//! included; its nonlinear simulation adds the structure's friction law and
//! limits to it.

use super::{
    Controller, CurrentLoop, Drive, DriveStructure, FeedForward, FrictionLaw, LoopGains, LoopKind,
    Measured, Mechanics, VelocityEstimate,
};
use crate::drive::RigParams;
use crate::error::Result;

impl DriveStructure {
    /// The paper's cascade with the rig's parameters `params` (module doc
    /// of `paper.rs`): the continuous controller, no output limit, viscous
    /// friction only.
    ///
    /// ```
    /// use feedid::drive::{closed_loop_coefficients, D1Variant, DriveStructure, RigParams};
    /// let p = RigParams::default();
    /// let s = DriveStructure::paper(&p).unwrap();
    /// let den = s.closed_loop().unwrap().denominator;
    /// let paper = closed_loop_coefficients(&p, D1Variant::Corrected).den;
    /// for (a, b) in den.iter().zip(paper) {
    ///     assert!((a / den[0] - b / paper[0]).abs() <= 1e-9 * (b / paper[0]).abs());
    /// }
    /// ```
    pub fn paper(params: &RigParams) -> Result<DriveStructure> {
        params.validate()?;
        let r = params.r();
        let c = &params.control;
        let loop_gains = |kind, kp, ki| LoopGains {
            kind,
            kp,
            ki,
            kd: 0.0,
        };
        let s = DriveStructure {
            source: Some("the paper's cascade (feedid's rig parameters)".to_string()),
            controller: Controller {
                sample_time: None,
                velocity_estimate: VelocityEstimate::Central,
                velocity_feedback: Some(Measured::Motor),
            },
            position: loop_gains(LoopKind::P, c.kv, 0.0),
            velocity: loop_gains(LoopKind::PI, c.kp, c.ki),
            drive: Drive {
                gain: params.motor.kt / r,
                limit: None,
            },
            current: Some(CurrentLoop {
                kp: c.kpi,
                ki: c.kii,
                inductance: params.motor.inductance,
                resistance: params.motor.resistance,
                back_emf: params.motor.ke / r,
            }),
            mechanics: Mechanics {
                mass: params.table.mass,
                motor_mass: Some(params.inertia_j() / (r * r)),
                stiffness: Some(params.stiffness_k()),
                damping: 0.0,
                measured: Measured::Load,
                motor_viscous: params.damping.c1 / (r * r),
            },
            friction: FrictionLaw {
                viscous: params.damping.c2,
                ..FrictionLaw::default()
            },
            feed_forward: FeedForward {
                velocity: c.kvff,
                acceleration: c.kaff,
            },
        };
        s.validate()?;
        Ok(s)
    }
}
