//! Online compensation of a stream of lines, as `feedid stream` reads them:
//! each line carries the measured position of its own sample and the
//! desired position (the program's command) of the sample `lead` lines
//! later — an interpolator's look-ahead ([`crate::ident::StreamOptions::command_lead`]).
//!
//! Line `i` (`i ≥ lead`) gives `y[i]` and `r[i + lead]`: the
//! [`OnlineCompensator`] then has `lead − 1` samples of preview beyond
//! sample `i + 1` and returns its command, written before the drive needs
//! it. Line 0 gives the command of sample `lead` (the first desired value,
//! plain); the positions of lines `1 … lead − 1` belong to samples whose
//! commands were sent before the stream began (not used). Samples are `dt`
//! apart; a line whose time is off by more than half an interval from the
//! expected one starts the compensation again (a gap).
//!
//! **Online or replayed.** Online, the positions answer the commands this
//! stream writes, and the model learns from those. Replaying a recorded
//! run ([`CommandStream::new`] `replay`), each line carries the command and
//! the position of its own sample, as recorded: the stream holds the
//! positions back `lead` lines to pair them as above, the positions answer
//! the recording's own command and the model learns from that — the
//! commands written are then what the compensation would have sent.

use serde::Serialize;

use super::online::{OnlineCompensator, OnlineConfig, OnlineState, OnlineStats, MAX_PREVIEW};
use crate::error::{Error, Result};

/// A command written by the stream.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CommandRow {
    /// Time of the sample it is for \[s\].
    pub time: f64,
    /// Desired position of that sample \[m\].
    pub desired: f64,
    /// The command to send \[m\].
    pub command: f64,
}

/// Online compensation fed line by line (module doc).
#[derive(Debug, Clone)]
pub struct CommandStream {
    comp: OnlineCompensator,
    lead: usize,
    dt: f64,
    replay: bool,
    /// Lines of the current segment, and the time of its first line.
    lines: usize,
    t0: f64,
    /// Desired values of the current segment (the ring of the ones not yet
    /// commanded, for the replay's "command sent").
    pending: Vec<f64>,
    segments: usize,
    /// Counters of the finished segments.
    done: OnlineStats,
    /// Replay: the last `lead + 1` lines' times and positions, and the
    /// lines read.
    held: Vec<(f64, f64)>,
    read: usize,
    /// Time of the last line accepted.
    last_time: Option<f64>,
}

impl CommandStream {
    /// A stream with the command `lead` ≥ 3 lines ahead (the compensator's
    /// preview is `lead − 1`; the other settings from `cfg`), samples `dt`
    /// \[s\] apart; `replay`: the positions answer the recording's own
    /// commands, not the ones written.
    pub fn new(cfg: OnlineConfig, lead: usize, dt: f64, replay: bool) -> Result<Self> {
        if !(3..=MAX_PREVIEW + 1).contains(&lead) {
            return Err(Error::InvalidParameter {
                name: "command lead",
                value: lead as f64,
                reason: "online compensation needs the command 3 to 33 samples ahead (2 to 32 samples of preview)",
            });
        }
        let cfg = OnlineConfig {
            preview: lead - 1,
            ..cfg
        };
        Ok(Self {
            comp: OnlineCompensator::new(cfg, dt)?,
            lead,
            dt,
            replay,
            lines: 0,
            t0: 0.0,
            pending: vec![0.0; 2 * lead + 2],
            segments: 0,
            done: OnlineStats::default(),
            held: vec![(0.0, 0.0); lead + 1],
            read: 0,
            last_time: None,
        })
    }

    /// Start every segment from a following-error model `[α₁, α₂, α₃]`
    /// ([`OnlineCompensator::set_prior`]).
    pub fn set_prior(&mut self, alpha: [f64; 3]) -> Result<()> {
        self.comp.set_prior(alpha)
    }

    /// The compensator (its model, state and counters in this segment).
    pub fn compensator(&self) -> &OnlineCompensator {
        &self.comp
    }

    /// Segments so far (a gap starts a new one).
    pub fn segments(&self) -> usize {
        self.segments
    }

    /// Counters over every segment.
    pub fn stats(&self) -> OnlineStats {
        let s = self.comp.stats();
        let d = self.done;
        OnlineStats {
            commands: d.commands + s.commands,
            model_updates: d.model_updates + s.model_updates,
            compensated: d.compensated + s.compensated,
            limited: d.limited + s.limited,
            implausible: d.implausible + s.implausible,
            withheld: d.withheld + s.withheld,
        }
    }

    /// What the guard thinks of the current model.
    pub fn state(&self) -> OnlineState {
        self.comp.state()
    }

    fn restart(&mut self) {
        let s = self.comp.stats();
        self.done.commands += s.commands;
        self.done.model_updates += s.model_updates;
        self.done.compensated += s.compensated;
        self.done.limited += s.limited;
        self.done.implausible += s.implausible;
        self.done.withheld += s.withheld;
        // the model is kept across a gap only as far as the compensator
        // keeps it: it starts again from nothing, as after any restart
        self.comp.reset();
        self.lines = 0;
    }

    /// One line: its time \[s\], the command \[m\] — online the desired
    /// position of the sample `lead` lines later, replayed the recorded
    /// command of its own sample — and the measured position of its own
    /// sample \[m\]. Returns the command due next, if any.
    /// A line whose values are not finite or whose time is not after the
    /// last accepted one is refused (nothing is stored).
    pub fn push(&mut self, time: f64, command: f64, position: f64) -> Result<Option<CommandRow>> {
        for (channel, v) in [("time", time), ("command", command), ("position", position)] {
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    channel: channel.to_string(),
                    index: self.read,
                    value: v,
                });
            }
        }
        if let Some(previous) = self.last_time.filter(|&p| time <= p) {
            return Err(Error::NonMonotoneTime {
                index: self.read,
                previous,
                value: time,
            });
        }
        self.last_time = Some(time);
        if !self.replay {
            self.read += 1;
            return self.feed(time, command, position);
        }
        // this line's command is the desired position `lead` lines after
        // the line held back longest
        let ring = self.held.len();
        self.held[self.read % ring] = (time, position);
        self.read += 1;
        if self.read <= self.lead {
            return Ok(None);
        }
        let (t, y) = self.held[(self.read - 1 - self.lead) % ring];
        self.feed(t, command, y)
    }

    /// One line as the online stream reads it (module doc).
    fn feed(&mut self, time: f64, desired_ahead: f64, position: f64) -> Result<Option<CommandRow>> {
        if self.lines > 0 {
            let expected = self.t0 + self.lines as f64 * self.dt;
            if (time - expected).abs() > 0.5 * self.dt {
                self.restart();
            }
        }
        if self.lines == 0 {
            self.t0 = time;
            self.segments += 1;
        }
        let i = self.lines;
        self.lines += 1;
        self.comp.push_desired(desired_ahead)?;
        let ring = self.pending.len();
        self.pending[(i + self.lead) % ring] = desired_ahead;
        let lead = self.lead;
        let row = if i == 0 {
            let u = self.comp.first_command()?;
            Some((lead, desired_ahead, u))
        } else if i >= lead {
            let u = if self.replay {
                // the axis received the recording's own command of sample i
                let sent = self.pending[i % ring];
                self.comp.step_sent(position, sent)?
            } else {
                self.comp.step(position)?
            };
            let desired = self.pending[(i + 1) % ring];
            Some((i + 1, desired, u))
        } else {
            None
        };
        Ok(row.map(|(sample, desired, command)| CommandRow {
            time: self.t0 + sample as f64 * self.dt,
            desired,
            command,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::co_simulate;
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;

    #[test]
    fn a_stream_with_a_lead_issues_the_commands_of_the_co_simulation() {
        // online: the stream's commands drive the rig, the rig's positions
        // come back as the stream's lines, the command `lead` lines ahead
        let rate = 5000.0;
        let dt = 1.0 / rate;
        let lead = 5;
        let desired = Scenario::Scurve.command(rate, 0.6, 0).unwrap();
        let rig = VirtualRig::new(RigParams::default()).with_seed(4);
        let cfg = OnlineConfig {
            preview: lead - 1,
            ..OnlineConfig::default()
        };
        let sim = co_simulate(|f| rig.stepper(rate, f), &desired, dt, &cfg, 1, None).unwrap();
        let mut stream = CommandStream::new(OnlineConfig::default(), lead, dt, false).unwrap();
        // the stream's sample `lead + j` is the co-simulation's sample j; the
        // lines before carry positions of commands sent before (at rest)
        let n = desired.len();
        let mut axis = rig.stepper(rate, desired[0]).unwrap();
        let mut commands = Vec::new();
        for (i, &ahead) in desired.iter().enumerate() {
            // the position of the stream's sample i is the co-simulation's
            // sample i − lead (at rest before)
            let t = i as f64 * dt;
            if let Some(row) = stream.push(t, ahead, axis.position()).unwrap() {
                commands.push(row.command);
                if row.time > (lead as f64 + 0.5) * dt {
                    axis.advance(row.command).unwrap();
                }
                assert!((row.time - (commands.len() - 1 + lead) as f64 * dt).abs() < 1e-12);
            }
        }
        // the same commands as the co-simulation, sample for sample
        let m = commands.len().min(sim.command.len());
        assert!(m > n - 2 * lead, "{m}");
        for (k, (a, b)) in commands.iter().zip(&sim.command).enumerate() {
            assert_eq!(a, b, "sample {k}");
        }
    }

    #[test]
    fn a_replayed_run_learns_from_the_recordings_own_command() {
        let rate = 5000.0;
        let dt = 1.0 / rate;
        // the S-curve twice: the compensator learns on the first
        let once = Scenario::Scurve.command(rate, 0.8, 0).unwrap();
        let travel = once[once.len() - 1] - once[0];
        let desired: Vec<f64> = once
            .iter()
            .copied()
            .chain(once.iter().map(|v| v + travel))
            .collect();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(1)
            .simulate(&desired, rate)
            .unwrap();
        let lead = 4;
        let free = OnlineConfig {
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            ..OnlineConfig::default()
        };
        let mut stream = CommandStream::new(free, lead, dt, true).unwrap();
        let mut rows = Vec::new();
        // the recording as it is: command and position of each sample
        for (i, (&u, &y)) in desired.iter().zip(&out.position).enumerate() {
            if let Some(r) = stream.push(i as f64 * dt, u, y).unwrap() {
                rows.push(r);
            }
        }
        assert_eq!(stream.state(), OnlineState::Active);
        // the lag of the rig's P position loop without feed-forward: the
        // ramp error v/Kv, 1/Kv = 1/700 s
        let [t1, t2, _] = stream.compensator().time_constants();
        let kv = RigParams::default().control.kv;
        assert!((t1 * kv - 1.0).abs() < 0.05, "{t1} vs {}", 1.0 / kv);
        // each row is for its sample: desired as given, command ahead of it while moving
        for r in &rows {
            let k = (r.time / dt).round() as usize;
            assert_eq!(r.desired, desired[k]);
        }
        // once active, the command leads the desired position by T₁·ṙ + T₂·r̈
        // (the final time constants: within 5 % of the ones then in use)
        // (checked on the second half of the moving samples, at speed)
        let vel = |k: usize| (desired[k + 1] - desired[k - 1]) / (2.0 * dt);
        let vmax = (1..desired.len() - 1)
            .map(|k| vel(k).abs())
            .fold(0.0, f64::max);
        let fast: Vec<usize> = (1..desired.len() - 1)
            .filter(|&k| vel(k).abs() > 0.3 * vmax)
            .collect();
        let from = fast[fast.len() / 2 + 1];
        let mut checked = 0;
        for r in &rows {
            let k = (r.time / dt).round() as usize;
            if k >= from && k + 1 < desired.len() && vel(k).abs() > 0.3 * vmax {
                let lead = r.command - r.desired;
                let acc = (desired[k + 1] - 2.0 * desired[k] + desired[k - 1]) / (dt * dt);
                let want = t1 * vel(k) + t2 * acc;
                assert!(
                    (lead - want).abs() < 0.05 * want.abs(),
                    "{k}: {lead} vs {want}"
                );
                checked += 1;
            }
        }
        assert!(checked > 100, "{checked}");
    }

    #[test]
    fn a_gap_restarts_and_a_short_lead_is_refused() {
        assert!(CommandStream::new(OnlineConfig::default(), 2, 1e-3, false).is_err());
        let mut s = CommandStream::new(OnlineConfig::default(), 3, 1e-3, false).unwrap();
        for i in 0..10 {
            s.push(i as f64 * 1e-3, 0.0, 0.0).unwrap();
        }
        assert_eq!(s.segments(), 1);
        let row = s.push(0.1, 0.0, 0.0).unwrap();
        assert_eq!(s.segments(), 2);
        // the first line of a segment issues the command `lead` samples on
        let row = row.unwrap();
        assert!((row.time - 0.103).abs() < 1e-12);
        assert!(s.push(0.101, f64::NAN, 0.0).is_err());
        // a time not after the last accepted one is refused, nothing stored
        let e = s.push(0.1, 0.0, 0.0).unwrap_err();
        assert!(matches!(e, Error::NonMonotoneTime { .. }), "{e}");
        s.push(0.101, 0.0, 0.0).unwrap();
        assert_eq!(s.segments(), 2, "the refused lines made no gap");
        assert!(CommandStream::new(OnlineConfig::default(), 34, 1e-3, false).is_err());
    }
}
