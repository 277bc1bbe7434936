//! Closed-loop co-simulation of the online compensation: an axis stepped
//! sample by sample with the [`OnlineCompensator`] in the loop, against the
//! same axis (same noise) driven by the plain desired trajectory.
//!
//! At every sample `k` the axis's measured position `y[k]` goes to the
//! compensator, which returns the command of sample `k + 1` from the model
//! it has identified so far; the desired trajectory is given
//! [`OnlineConfig::preview`] samples ahead. The program may be run several
//! times back to back (a machine tool repeats its programs), each pass
//! continuing from where the last one ended (the desired positions shifted
//! by the program's net travel): the compensator starts knowing nothing and
//! keeps what it learnt from pass to pass. The tracking error is the
//! **true** (noise-free) position minus the desired one, per pass, over
//! every sample of the pass.

use serde::Serialize;

use super::online::{OnlineCompensator, OnlineConfig, OnlineStats};
use crate::drive::RigStepper;
use crate::error::{Error, Result};
use crate::stats::ErrorStats;
use crate::zoo::PlantStepper;

/// An axis that can be stepped one sample at a time.
pub trait SteppedAxis {
    /// Measured position at the current sample \[m\].
    fn position(&self) -> f64;
    /// True position at the current sample \[m\].
    fn true_position(&self) -> f64;
    /// Give the next sample's command \[m\]; returns its measured position \[m\].
    fn advance(&mut self, next: f64) -> Result<f64>;
}

impl SteppedAxis for RigStepper {
    fn position(&self) -> f64 {
        RigStepper::position(self)
    }
    fn true_position(&self) -> f64 {
        RigStepper::true_position(self)
    }
    fn advance(&mut self, next: f64) -> Result<f64> {
        RigStepper::advance(self, next)
    }
}

impl SteppedAxis for PlantStepper {
    fn position(&self) -> f64 {
        PlantStepper::position(self)
    }
    fn true_position(&self) -> f64 {
        PlantStepper::true_position(self)
    }
    fn advance(&mut self, next: f64) -> Result<f64> {
        PlantStepper::advance(self, next)
    }
}

/// The tracking errors of one pass of the program.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PassError {
    /// True − desired with the compensator \[m\].
    pub error: ErrorStats,
    /// True − desired with the plain command \[m\].
    pub plain_error: ErrorStats,
    /// Plain rms over compensated rms (1 when both are 0).
    pub reduction: f64,
}

/// The outcome of a co-simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoSimulation {
    /// The desired positions of every pass \[m\].
    #[serde(skip)]
    pub desired: Vec<f64>,
    /// Commands sent by the compensator \[m\].
    #[serde(skip)]
    pub command: Vec<f64>,
    /// True position with the compensator in the loop \[m\].
    #[serde(skip)]
    pub position: Vec<f64>,
    /// True position under the plain desired trajectory \[m\].
    #[serde(skip)]
    pub plain_position: Vec<f64>,
    /// Per pass, in order (the first: the compensator learning from nothing).
    pub passes: Vec<PassError>,
    /// The last pass's errors.
    pub last: PassError,
    /// Peak command velocity \[m/s\] and acceleration \[m/s²\] sent.
    pub peak_velocity: f64,
    /// Peak command acceleration \[m/s²\] sent.
    pub peak_acceleration: f64,
    /// The compensator's counters.
    pub stats: OnlineStats,
}

/// Run the program `desired` (samples `dt` \[s\] apart) `passes` times
/// back to back on two fresh axes from `axis` (called with the first
/// command): once plain, once with an [`OnlineCompensator`] of `cfg` in the
/// loop, starting from the following-error model `prior` if given
/// ([`OnlineCompensator::set_prior`]).
pub fn co_simulate<A, F>(
    axis: F,
    desired: &[f64],
    dt: f64,
    cfg: &OnlineConfig,
    passes: usize,
    prior: Option<[f64; 3]>,
) -> Result<CoSimulation>
where
    A: SteppedAxis,
    F: Fn(f64) -> Result<A>,
{
    let len = desired.len();
    if passes == 0 {
        return Err(Error::InvalidParameter {
            name: "passes",
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    if len < 2 {
        return Err(Error::TooFewSamples {
            what: "a desired trajectory",
            needed: 2,
            actual: len,
        });
    }
    if let Some(i) = desired.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "desired".to_string(),
            index: i,
            value: desired[i],
        });
    }
    let travel = desired[len - 1] - desired[0];
    let program: Vec<f64> = (0..passes)
        .flat_map(|p| desired.iter().map(move |v| v + p as f64 * travel))
        .collect();
    let desired = &program[..];
    let n = desired.len();
    // plain
    let mut plain = axis(desired[0])?;
    let mut plain_position = Vec::with_capacity(n);
    plain_position.push(plain.true_position());
    for &r in &desired[1..] {
        plain.advance(r)?;
        plain_position.push(plain.true_position());
    }
    // compensated
    let mut comp = OnlineCompensator::new(*cfg, dt)?;
    if let Some(alpha) = prior {
        comp.set_prior(alpha)?;
    }
    let preview = cfg.preview;
    let mut fed = 0;
    while fed < n && fed <= preview {
        comp.push_desired(desired[fed])?;
        fed += 1;
    }
    let first = comp.first_command()?;
    let mut ax = axis(first)?;
    let mut command = Vec::with_capacity(n);
    let mut position = Vec::with_capacity(n);
    command.push(first);
    position.push(ax.true_position());
    for _ in 1..n {
        // the desired trajectory `preview` samples beyond the next command
        if fed < n {
            comp.push_desired(desired[fed])?;
            fed += 1;
        } else {
            comp.finish_desired();
        }
        let u = comp.step(ax.position())?;
        ax.advance(u)?;
        command.push(u);
        position.push(ax.true_position());
    }
    let pass_errors: Vec<PassError> = (0..passes)
        .map(|p| {
            let r = p * len..(p + 1) * len;
            let stats = |y: &[f64]| {
                ErrorStats::from_pairs(
                    desired[r.clone()]
                        .iter()
                        .copied()
                        .zip(y[r.clone()].iter().copied()),
                )
            };
            let (error, plain_error) = (stats(&position), stats(&plain_position));
            let reduction = if error.rms > 0.0 {
                plain_error.rms / error.rms
            } else {
                1.0
            };
            PassError {
                error,
                plain_error,
                reduction,
            }
        })
        .collect();
    let last = pass_errors[passes - 1];
    let (mut pv, mut pa) = (0.0_f64, 0.0_f64);
    for k in 1..n {
        pv = pv.max((command[k] - command[k - 1]).abs() / dt);
        if k + 1 < n {
            pa = pa.max((command[k + 1] - 2.0 * command[k] + command[k - 1]).abs() / (dt * dt));
        }
    }
    Ok(CoSimulation {
        desired: program,
        command,
        position,
        plain_position,
        passes: pass_errors,
        last,
        peak_velocity: pv,
        peak_acceleration: pa,
        stats: comp.stats(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;
    use crate::zoo::{CommandSpec, PlantKind, Zoo};

    #[test]
    fn the_online_compensator_removes_most_of_a_linear_servos_following_error() {
        // the first linear servo of the zoo with an S-curve or a contour
        let zoo = Zoo::standard();
        let member = zoo
            .regular()
            .filter_map(|i| zoo.member(i).ok())
            .find(|m| {
                m.spec.plant == PlantKind::SecondOrder
                    && matches!(
                        m.spec.command,
                        CommandSpec::Scurve(_) | CommandSpec::Contour(_)
                    )
            })
            .unwrap();
        let spec = &member.spec;
        let dt = 1.0 / spec.rate_hz;
        let cfg = OnlineConfig {
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            ..OnlineConfig::default()
        };
        let sim = co_simulate(|f| spec.stepper(f, 3), &member.command, dt, &cfg, 2, None).unwrap();
        assert_eq!(sim.passes.len(), 2);
        assert_eq!(sim.desired.len(), 2 * member.command.len());
        // the plain runs of both passes are the same program
        let (p0, p1) = (sim.passes[0].plain_error.rms, sim.passes[1].plain_error.rms);
        assert!((p0 - p1).abs() < 0.05 * p0, "{p0} {p1}");
        assert!(
            sim.last.reduction > 5.0,
            "{} ({})",
            sim.last.reduction,
            spec.label
        );
        assert!(sim.stats.compensated > 0);
    }

    #[test]
    fn on_the_rig_the_compensator_is_never_worse_than_the_plain_command() {
        let rate = 5000.0;
        let rig = VirtualRig::new(RigParams::default()).with_seed(2);
        for scenario in [Scenario::Ramp, Scenario::Scurve] {
            let desired = scenario.command(rate, 0.8, 0).unwrap();
            let sim = co_simulate(
                |f| rig.stepper(rate, f),
                &desired,
                1.0 / rate,
                &OnlineConfig::default(),
                2,
                None,
            )
            .unwrap();
            for p in &sim.passes {
                assert!(
                    p.error.rms <= 1.05 * p.plain_error.rms,
                    "{scenario:?}: {} vs plain {}",
                    p.error.rms,
                    p.plain_error.rms
                );
            }
            // the stepped plain run is the batch simulation
            let batch = rig.simulate(&desired, rate).unwrap();
            assert_eq!(
                &sim.plain_position[..desired.len()],
                &batch.true_position[..]
            );
            // limits hold on every command sent
            let dt = 1.0 / rate;
            let (v, a) = (sim.peak_velocity, sim.peak_acceleration);
            let cfg = OnlineConfig::default();
            let pv = desired
                .windows(2)
                .map(|w| (w[1] - w[0]).abs() / dt)
                .fold(0.0, f64::max);
            assert!(v <= cfg.max_velocity.max(pv) * (1.0 + 1e-9), "{v}");
            assert!(a.is_finite());
        }
    }

    #[test]
    fn a_prior_from_the_rigs_model_compensates_from_the_first_pass() {
        use crate::compensate::following_error_of;
        use crate::drive::{closed_loop_coefficients, D1Variant};
        use crate::ident::LinearModel;
        let rate = 5000.0;
        let dt = 1.0 / rate;
        let p = RigParams::default();
        let tf = closed_loop_coefficients(&p, D1Variant::Corrected)
            .transfer_function()
            .unwrap();
        let alpha = following_error_of(&LinearModel::continuous(&tf), dt).unwrap();
        // the P position loop's lag 1/Kv (the sampled loop adds half a sample)
        assert!((alpha[0] * p.control.kv - 1.0).abs() < 0.1, "{alpha:?}");
        let rig = VirtualRig::new(p).with_seed(2);
        let desired = Scenario::Scurve.command(rate, 0.8, 0).unwrap();
        let cfg = OnlineConfig::default();
        let cold = co_simulate(|f| rig.stepper(rate, f), &desired, dt, &cfg, 1, None).unwrap();
        let warm =
            co_simulate(|f| rig.stepper(rate, f), &desired, dt, &cfg, 1, Some(alpha)).unwrap();
        assert!(
            warm.last.reduction > 1.3 * cold.last.reduction,
            "with the prior {}×, without {}×",
            warm.last.reduction,
            cold.last.reduction
        );
        assert!(co_simulate(
            |f| rig.stepper(rate, f),
            &desired,
            dt,
            &cfg,
            1,
            Some([f64::NAN; 3])
        )
        .is_err());
    }

    #[test]
    fn bad_programs_are_refused() {
        let rig = VirtualRig::new(RigParams::default());
        let axis = |f| rig.stepper(5000.0, f);
        let cfg = OnlineConfig::default();
        assert!(co_simulate(axis, &[0.0], 2e-4, &cfg, 1, None).is_err());
        assert!(co_simulate(axis, &[0.0, f64::NAN], 2e-4, &cfg, 1, None).is_err());
        assert!(co_simulate(axis, &[0.0, 1e-6], 2e-4, &cfg, 0, None).is_err());
    }
}
