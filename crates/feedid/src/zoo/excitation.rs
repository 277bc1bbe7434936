//! An identification run for a member's axis: a logarithmic sine sweep its
//! program's speed and acceleration allow, for identifying a model of the
//! axis before compensating its program (`zoo_compensate`, `zoo_online`).

use super::spec::{CommandSpec, MemberSpec};
use crate::error::Result;
use crate::signal::{Chirp, Sweep};

impl MemberSpec {
    /// Speed \[m/s\] and acceleration \[m/s²\] the member's program
    /// `command` asks of the axis: its peak finite-difference velocity, and
    /// the acceleration of its S-curve, point-to-point program or contour
    /// (for a ramp `v·Kv`, what the loop asks at the corner).
    pub fn program_references(&self, command: &[f64]) -> (f64, f64) {
        let dt = 1.0 / self.rate_hz;
        let v = command
            .windows(2)
            .map(|w| ((w[1] - w[0]) / dt).abs())
            .fold(0.0, f64::max);
        let a = match &self.command {
            CommandSpec::Scurve(s) => s.max_acceleration,
            CommandSpec::PointToPoint { program, .. } => program.max_acceleration,
            CommandSpec::Contour(c) => c.max_acceleration.min(c.feed * c.feed / c.radius.abs()),
            _ => v * self.kv,
        };
        (v, a)
    }

    /// A chirp to identify this axis with, as long as `command` (the
    /// member's program): a logarithmic sweep from `f_max/100` to
    /// `f_max = min(rate/8, max(6·Kv/2π, 5 Hz))`, amplitude
    /// `0.8·min(A, 10 mm, v/(2π·f_max), a/(2π·f_max)²)` (`A` the member's
    /// amplitude, `v`, `a` [`MemberSpec::program_references`]), `f_max`
    /// lowered until the amplitude is at least 50 encoder counts.
    pub fn identification_chirp(&self, command: &[f64]) -> Result<Vec<f64>> {
        let n = command.len();
        let rate = self.rate_hz;
        let dt = 1.0 / rate;
        let (v, a) = self.program_references(command);
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut f_max = (rate / 8.0).min((6.0 * self.kv / two_pi).max(5.0));
        let amp = |f: f64| {
            0.8 * self
                .amplitude_m
                .min(1e-2)
                .min(v / (two_pi * f))
                .min(a / (two_pi * f).powi(2))
        };
        while amp(f_max) < 50.0 * self.resolution_m && f_max > 2.0 {
            f_max /= 1.5;
        }
        Chirp {
            amplitude: amp(f_max),
            f_start: f_max / 100.0,
            f_end: f_max,
            sweep: Sweep::Logarithmic,
            taper: 0.05_f64.min(0.1 * n as f64 * dt),
            rest: 10.0 * dt,
        }
        .generate(rate, n as f64 * dt)
    }
}
