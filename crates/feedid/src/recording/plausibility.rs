//! Plausibility of a recording: what would make every figure computed from
//! it meaningless although the file is well formed. Shared by every command
//! that reads a recording; the warnings go to standard error and into the
//! summaries (`warnings: [...]`).
//!
//! With `c` the command, `x` the measured position, `Δt` the sample interval:
//!
//! - **command still** — `c` never moves by more than 1 nm: nothing to identify.
//! - **frozen position** (a dead encoder, a wrong column) — the longest run
//!   of samples with exactly the same `x` while the command moves over it by
//!   more than [`FROZEN_SHARE`] of its whole range *and* by more than
//!   [`FROZEN_QUANTA`] position steps (the smallest non-zero `|Δx|` of the
//!   recording: its resolution). A model that predicts a constant scores
//!   "rms 0, fit 100 %" there; the warning says that this means nothing.
//!   A run the axis only *lagged* through is not one: a slow or delayed
//!   loop behind a fast command (a step, a steep ramp) stays put for its
//!   dead time and more. The run is excused when the tracking error
//!   `c − x` then comes back to within half the run's command motion of its
//!   value before the run (within [`CATCH_UP_RUNS`] run lengths) without a
//!   position increment beyond [`CATCH_UP_STEP`] times the command's
//!   largest one. An encoder that resumes shows the true position at once
//!   (a jump) or counts on from where it stopped (the missed motion stays
//!   in the tracking error). (Behind a command step an encoder that
//!   resumes after a few samples looks like a delayed fast axis: no
//!   recording tells these apart.)
//! - **unit mismatch** — the standard deviations of `x` and `c` differ by a
//!   factor outside 1/10 … 10 (a loop follows its command); near 10³ or 10⁶
//!   the two are in different units (mm and m, µm and m).
//! - **sign or offset** — units agree, but the rms of the tracking error
//!   `c − x` exceeds half the command's range: a sign, an offset or the
//!   wrong axis.
//! - **implausible speed** — the position moves faster than
//!   [`MAX_PLAUSIBLE_SPEED`] (the 99th percentile of `|Δx|/Δt`), far beyond
//!   any feed drive: lengths in mm or µm read as metres.
//! - **implausible lag** — the least-squares lag `τ` of the position behind
//!   the command, from `c − x ≈ a + τ·ċ` (a position loop follows a ramp with
//!   the lag 1/Kv), lies outside [`LAG_RANGE`] while it explains the tracking
//!   error (correlation of `c − x` and `ċ` above 0.5) and spans at least half
//!   a sample: times in ms or µs read as seconds, or the reverse. Checked
//!   only when no frozen position, unit mismatch or sign/offset warning
//!   came first (each of those makes the lag meaningless, and the one found
//!   first hides the later ones of that group).
//! - **read notes** — what the reader had to decide (e.g. duplicate column
//!   names, see [`Recording::notes`]).
//!
//! A uniform error of the length or time unit changes no ratio of the
//! recording, so the last two checks compare with the physics of feed drives
//! instead (documented bounds, not tuning); the others are relative to the
//! recording's own range and resolution.
//!
//! ```
//! use feedid::{plausibility::check_recording, Recording};
//! let t: Vec<f64> = (0..200).map(|k| k as f64 * 1e-3).collect();
//! let c: Vec<f64> = t.iter().map(|&t| (t - 0.05).max(0.0) * 0.05).collect();
//! let dead = vec![0.0; 200]; // the encoder never counts
//! let rec = Recording::new(t, c, dead).unwrap();
//! let w = check_recording(&rec);
//! assert!(w.iter().any(|w| w.kind == feedid::plausibility::WarningKind::FrozenPosition));
//! ```

use serde::Serialize;

use crate::error::{phrase_hints, Hint, Syntax};
use crate::recording::{Recording, MOTION_THRESHOLD};

/// Share of the command's range it must cover while the position stays frozen.
pub const FROZEN_SHARE: f64 = 0.1;

/// Position steps (resolution) the command must cover while the position stays frozen.
pub const FROZEN_QUANTA: f64 = 100.0;

/// Largest position increment, in units of the command's largest increment,
/// of an axis catching up after a lag (overshoot included): a frozen
/// position that ends with a larger jump is an encoder that resumed.
pub const CATCH_UP_STEP: f64 = 3.0;

/// Samples, in units of the frozen run's length, within which a lagging
/// axis must have caught up with its command (a slow loop takes many times
/// its dead time).
pub const CATCH_UP_RUNS: usize = 100;

/// Fastest plausible position speed of a feed drive \[m/s\] (linear-motor axes reach about 5 m/s).
pub const MAX_PLAUSIBLE_SPEED: f64 = 20.0;

/// Plausible lag of a position loop behind its command \[s\]: 1/Kv of feed
/// drives lies between about 1 ms and 100 ms (Kv 10 … 1000 1/s); the bounds
/// 0.1 ms and 0.5 s leave room on either side and still catch a factor 1000
/// (ms read as s: 1 ms becomes 1 s; s read as ms: 100 ms becomes 0.1 ms).
pub const LAG_RANGE: (f64, f64) = (1e-4, 0.5);

/// What a warning is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// The command never moves.
    CommandStill,
    /// The position stays constant while the command moves.
    FrozenPosition,
    /// Position and command seem to be in different units.
    UnitMismatch,
    /// The tracking error is as large as the motion (sign, offset, wrong axis).
    SignOrOffset,
    /// The position moves faster than a feed drive can.
    ImplausibleSpeed,
    /// The position lags the command by an implausible time.
    ImplausibleLag,
    /// Something the reader decided (e.g. renamed duplicate columns).
    ReadNote,
}

/// One plausibility warning.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Warning {
    /// What it is about.
    pub kind: WarningKind,
    /// One line for people, with the numbers and what to check; the
    /// settings it suggests are written in [`Syntax::Library`]
    /// (`unit = mm`), see [`Warning::phrased`].
    pub message: String,
    /// The settings the message suggests, in the order it names them.
    #[serde(skip)]
    pub hints: Vec<Hint>,
}

impl Warning {
    /// The message with its hints in a front end's syntax (`Display` is
    /// [`Syntax::Library`]'s): the CLI names `--unit mm`, Python `unit="mm"`.
    pub fn phrased(&self, syntax: Syntax) -> String {
        phrase_hints(&self.message, &self.hints, syntax)
    }
}

const fn set(key: &'static str, value: &'static str) -> Hint {
    Hint::SetOption { key, value }
}

const fn opt(key: &'static str) -> Hint {
    Hint::Option { key }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// The warnings of a recording (see the module doc), in the order of the list above.
pub fn check_recording<S: AsRef<[f64]>>(rec: &Recording<S>) -> Vec<Warning> {
    let mut out = Vec::new();
    let (t, c, x) = (rec.time(), rec.command(), rec.position());
    let warn = |kind, (message, hints)| Warning {
        kind,
        message,
        hints,
    };
    let range = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &a| {
                (lo.min(a), hi.max(a))
            });
        hi - lo
    };
    let c_range = range(c);
    let moves = rec.command_moves();
    if !moves {
        out.push(warn(
            WarningKind::CommandStill,
            (
                "command never moves (range <= 1 nm): there is nothing to identify".to_string(),
                Vec::new(),
            ),
        ));
    }
    // the first of these that applies: each makes the later ones meaningless
    let mut tracking_ok = moves;
    if moves {
        if let Some(w) = frozen_position(t, c, x, c_range) {
            out.push(warn(WarningKind::FrozenPosition, (w, Vec::new())));
            tracking_ok = false;
        } else if let Some(w) = unit_mismatch(c, x) {
            out.push(warn(WarningKind::UnitMismatch, w));
            tracking_ok = false;
        } else if let Some(w) = sign_or_offset(c, x, c_range) {
            out.push(warn(WarningKind::SignOrOffset, (w, Vec::new())));
            tracking_ok = false;
        }
    }
    if let Some(w) = implausible_speed(x, rec.dt()) {
        out.push(warn(WarningKind::ImplausibleSpeed, w));
    }
    if tracking_ok {
        if let Some(w) = implausible_lag(c, x, rec.dt()) {
            out.push(warn(WarningKind::ImplausibleLag, w));
        }
    }
    for n in rec.notes() {
        out.push(warn(WarningKind::ReadNote, (n.clone(), Vec::new())));
    }
    out
}

/// A length for a message: mm with µm resolution, or e-notation when tiny or huge.
fn length(m: f64) -> String {
    let a = m.abs();
    if (1e-7..1e4).contains(&a) {
        format!("{:.4} mm", 1e3 * m)
    } else {
        format!("{m:.3e} m")
    }
}

/// The longest run of identical positions while the command moves (see the module doc).
fn frozen_position(t: &[f64], c: &[f64], x: &[f64], c_range: f64) -> Option<String> {
    let quantum = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let quantum = if quantum.is_finite() { quantum } else { 0.0 };
    let suspect =
        |r: f64| r > FROZEN_SHARE * c_range && r > FROZEN_QUANTA * quantum && r > MOTION_THRESHOLD;
    let step = c
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    // (start, end inclusive, command range over the run)
    let mut best: Option<(usize, usize, f64)> = None;
    let mut start = 0;
    let (mut lo, mut hi) = (c[0], c[0]);
    for k in 1..=x.len() {
        if k < x.len() && x[k] == x[start] {
            lo = lo.min(c[k]);
            hi = hi.max(c[k]);
            continue;
        }
        let r = hi - lo;
        if best.is_none_or(|b| r > b.2) && !(suspect(r) && catches_up(c, x, start, k - 1, r, step))
        {
            best = Some((start, k - 1, r));
        }
        if k < x.len() {
            start = k;
            lo = c[k];
            hi = c[k];
        }
    }
    let (a, b, r) = best?;
    if !suspect(r) {
        return None;
    }
    let what = "a dead encoder or a wrong column? Predictions of a constant score \"rms 0, fit 100 %\" there, which means nothing";
    Some(if a == 0 && b + 1 == x.len() {
        format!(
            "the position never changes (stays at {}) while the command moves over {}: {what}",
            length(x[a]),
            length(c_range)
        )
    } else {
        format!(
            "the position stays at {} from {:.6} s to {:.6} s ({} samples) while the command moves over {} ({:.0} % of its range): {what}",
            length(x[a]),
            t[a],
            t[b],
            b - a + 1,
            length(r),
            100.0 * r / c_range
        )
    })
}

/// Whether the position, frozen over `a..=b` while the command moved over
/// `r`, was only lagging: within [`CATCH_UP_RUNS`] times the run's length after it the
/// tracking error `c − x` comes back to within `r/2` of its value before the
/// run, and no position increment on the way exceeds [`CATCH_UP_STEP`] times
/// the command's largest increment `step` (an encoder that resumes jumps by
/// the missed motion at once; one that lost counts keeps the offset).
fn catches_up(c: &[f64], x: &[f64], a: usize, b: usize, r: f64, step: f64) -> bool {
    let before = a.checked_sub(1).map_or(c[a] - x[a], |k| c[k] - x[k]);
    let end = (b + 1)
        .saturating_add(CATCH_UP_RUNS.saturating_mul(b - a + 1))
        .min(x.len());
    for k in b + 1..end {
        if (x[k] - x[k - 1]).abs() > CATCH_UP_STEP * step {
            return false;
        }
        if ((c[k] - x[k]) - before).abs() <= 0.5 * r {
            return true;
        }
    }
    false
}

/// Standard deviation.
fn std_dev(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|a| (a - mean) * (a - mean)).sum::<f64>() / n).sqrt()
}

/// Position and command in different units (see the module doc).
fn unit_mismatch(c: &[f64], x: &[f64]) -> Option<(String, Vec<Hint>)> {
    let (sc, sx) = (std_dev(c), std_dev(x));
    if !(sc > 0.0 && sx > 0.0) {
        return None;
    }
    let ratio = sx / sc;
    if (0.1..=10.0).contains(&ratio) {
        return None;
    }
    let decade = ratio.log10();
    let near = [3.0_f64, 6.0, -3.0, -6.0]
        .into_iter()
        .find(|k| (decade - k).abs() < 0.5);
    Some(match near {
        Some(k) => (format!(
            "the position varies {ratio:.3e} times as much as the command, near 10^{k}: the two are in different units (mm and m? µm and m?); convert one of them (unit and scale apply to both)"
        ), vec![opt("unit"), opt("scale")]),
        None => (format!(
            "the position varies {ratio:.3e} times as much as the command: are both in the same unit, and is this the command of this axis?"
        ), Vec::new()),
    })
}

/// A tracking error as large as the motion (see the module doc).
fn sign_or_offset(c: &[f64], x: &[f64], c_range: f64) -> Option<String> {
    let n = c.len() as f64;
    let e_rms = (c.iter().zip(x).map(|(a, b)| (a - b) * (a - b)).sum::<f64>() / n).sqrt();
    (e_rms > 0.5 * c_range).then(|| {
        format!(
            "the tracking error (command − position) has an rms of {}, more than half the command's range {}: a sign, an offset or another axis?",
            length(e_rms),
            length(c_range)
        )
    })
}

/// The position faster than a feed drive (see the module doc).
fn implausible_speed(x: &[f64], dt: f64) -> Option<(String, Vec<Hint>)> {
    if x.len() < 3 {
        return None;
    }
    let mut speeds: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs() / dt).collect();
    let k = ((speeds.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = speeds.select_nth_unstable_by(k, f64::total_cmp);
    let v = *p99;
    (v > MAX_PLAUSIBLE_SPEED).then(|| {
        (format!(
            "the position moves at {v:.3e} m/s (99th percentile), far beyond any feed drive (about 5 m/s at most): are the lengths in mm or µm (unit = mm, unit = um), or the times in another unit (time_unit)?"
        ), vec![set("unit", "mm"), set("unit", "um"), opt("time_unit")])
    })
}

/// The lag of the position behind the command, if it explains the tracking
/// error: `(τ [s], correlation)`.
pub fn following_lag(c: &[f64], x: &[f64], dt: f64) -> Option<(f64, f64)> {
    let n = c.len();
    if n < 5 {
        return None;
    }
    // central differences of the command; e = c − x
    let (mut sv, mut se, mut svv, mut see, mut sve, mut m) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 1..n - 1 {
        let v = (c[k + 1] - c[k - 1]) / (2.0 * dt);
        let e = c[k] - x[k];
        sv += v;
        se += e;
        svv += v * v;
        see += e * e;
        sve += v * e;
        m += 1.0;
    }
    let cov = sve / m - (sv / m) * (se / m);
    let var_v = svv / m - (sv / m) * (sv / m);
    let var_e = see / m - (se / m) * (se / m);
    if !(var_v > 0.0 && var_e > 0.0) {
        return None;
    }
    let tau = cov / var_v;
    let rho = cov / (var_v * var_e).sqrt();
    (tau.is_finite() && rho.is_finite()).then_some((tau, rho))
}

/// A lag outside the range of feed drives (see the module doc).
fn implausible_lag(c: &[f64], x: &[f64], dt: f64) -> Option<(String, Vec<Hint>)> {
    let (tau, rho) = following_lag(c, x, dt)?;
    if rho < 0.5 || tau < 0.5 * dt {
        return None;
    }
    let (lo, hi) = LAG_RANGE;
    let plausible = |t: f64| (lo..=hi).contains(&t);
    let hint = if tau > hi {
        if plausible(tau * 1e-3) {
            (
                "are the times in ms? (time_unit = ms)",
                set("time_unit", "ms"),
            )
        } else if plausible(tau * 1e-6) {
            (
                "are the times in µs? (time_unit = us)",
                set("time_unit", "us"),
            )
        } else {
            (
                "check the time unit (time_unit) and the columns",
                opt("time_unit"),
            )
        }
    } else if tau < lo {
        if plausible(tau * 1e3) {
            (
                "are the times in s or ms rather than the unit given? (time_unit)",
                opt("time_unit"),
            )
        } else {
            (
                "check the time unit (time_unit) and the columns",
                opt("time_unit"),
            )
        }
    } else {
        return None;
    };
    let (hint, h) = hint;
    Some((format!(
        "the position lags the command by {tau:.3e} s at a sampling rate of {:.4e} Hz; the following lag 1/Kv of a feed drive lies between about 1 ms and 100 ms: {hint}",
        1.0 / dt
    ), vec![h]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A first-order loop (lag `tau`) following a ramp that starts at 10 % of the recording.
    fn ramp(n: usize, dt: f64, tau: f64, speed: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let t0 = 0.1 * n as f64 * dt;
        let c: Vec<f64> = t.iter().map(|&t| speed * (t - t0).max(0.0)).collect();
        let mut x = vec![0.0; n];
        let a = (-dt / tau).exp();
        for k in 1..n {
            x[k] = a * x[k - 1] + (1.0 - a) * c[k - 1];
        }
        (t, c, x)
    }

    fn kinds(rec: &Recording) -> Vec<WarningKind> {
        check_recording(rec).into_iter().map(|w| w.kind).collect()
    }

    #[test]
    fn a_good_recording_gives_no_warning_at_any_plausible_scale() {
        for scale in [1.0, 0.1, 1e-3] {
            let (t, c, x) = ramp(2000, 2e-4, 1.4e-3, 0.05 * scale);
            let rec = Recording::new(t, c, x).unwrap();
            assert!(
                kinds(&rec).is_empty(),
                "{scale}: {:?}",
                check_recording(&rec)
            );
        }
    }

    #[test]
    fn the_lag_of_a_first_order_loop_is_its_time_constant() {
        let (_, c, x) = ramp(5000, 2e-4, 2e-3, 0.05);
        let (tau, rho) = following_lag(&c, &x, 2e-4).unwrap();
        // the discrete loop lags by τ plus half a sample
        assert!((tau / (2e-3 + 1e-4) - 1.0).abs() < 0.05, "{tau}");
        assert!(rho > 0.9, "{rho}");
    }

    #[test]
    fn a_dead_encoder_is_found_whole_or_in_part() {
        let (t, c, x) = ramp(2000, 2e-4, 1.4e-3, 0.05);
        let dead = Recording::new(t.clone(), c.clone(), vec![1e-3; 2000]).unwrap();
        let w = check_recording(&dead);
        assert!(
            w.iter()
                .any(|w| w.kind == WarningKind::FrozenPosition
                    && w.message.contains("never changes")),
            "{w:?}"
        );
        // frozen from the middle on (the encoder cable comes loose)
        let mut x2 = x.clone();
        let v = x2[1200];
        x2[1200..].iter_mut().for_each(|a| *a = v);
        let rec = Recording::new(t.clone(), c.clone(), x2).unwrap();
        let w = check_recording(&rec);
        assert!(
            w.iter().any(|w| w.kind == WarningKind::FrozenPosition
                && w.message.contains("800 samples")),
            "{w:?}"
        );
        // the position upside down
        let neg: Vec<f64> = x.iter().map(|v| -v).collect();
        let rec = Recording::new(t.clone(), c.clone(), neg).unwrap();
        assert!(kinds(&rec).contains(&WarningKind::SignOrOffset));
        // a quantised position that rests while the command rests: no warning
        let xq: Vec<f64> = x.iter().map(|v| (v / 1e-6).round() * 1e-6).collect();
        let rec = Recording::new(t, c, xq).unwrap();
        assert!(!kinds(&rec).contains(&WarningKind::FrozenPosition));
    }

    /// A first-order loop (time constant `tau` samples) with `dead` samples
    /// of dead time behind a command step of 2 mm at sample 50.
    fn lagging_step(n: usize, tau: f64, dead: usize) -> Recording {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let c: Vec<f64> = (0..n).map(|k| if k >= 50 { 2e-3 } else { 0.0 }).collect();
        let a = (-1.0 / tau).exp();
        let mut x = vec![0.0; n];
        for k in 1..n {
            let u = if k > dead { c[k - 1 - dead] } else { 0.0 };
            x[k] = a * x[k - 1] + (1.0 - a) * u;
        }
        Recording::new(t, c, x).unwrap()
    }

    #[test]
    fn a_position_that_lags_behind_a_fast_command_is_not_a_dead_encoder() {
        // frozen for the dead time after the step, then catching up
        // smoothly (slowly: half-way after 35 samples)
        for (tau, dead) in [(5.0, 3), (50.0, 3), (50.0, 12)] {
            let rec = lagging_step(400, tau, dead);
            assert!(
                !kinds(&rec).contains(&WarningKind::FrozenPosition),
                "{tau} {dead}"
            );
        }
    }

    #[test]
    fn an_encoder_that_resumes_with_a_jump_or_lost_counts_is_found() {
        // a ramp (2000 samples, the motion from sample 200 on); the encoder
        // stops counting over samples 1000..1300 of the move
        let (t, c, x) = ramp(2000, 2e-4, 1.4e-3, 0.05);
        let (a, b) = (1000, 1300);
        // then shows the true position again: a jump by the missed motion
        let mut jump = x.clone();
        jump[a..b].iter_mut().for_each(|v| *v = x[a - 1]);
        let rec = Recording::new(t.clone(), c.clone(), jump).unwrap();
        assert!(kinds(&rec).contains(&WarningKind::FrozenPosition));
        // or counts on from where it stopped: the missed motion stays as an
        // offset of the tracking error
        let mut lost = x.clone();
        let missed = x[b - 1] - x[a - 1];
        lost[a..b].iter_mut().for_each(|v| *v = x[a - 1]);
        lost[b..].iter_mut().for_each(|v| *v -= missed);
        let rec = Recording::new(t, c, lost).unwrap();
        assert!(kinds(&rec).contains(&WarningKind::FrozenPosition));
    }

    #[test]
    fn a_position_in_mm_against_a_command_in_m_is_named() {
        let (t, c, x) = ramp(2000, 2e-4, 1.4e-3, 0.05);
        for (f, needle) in [
            (1e3, "10^3"),
            (1e6, "10^6"),
            (1e-3, "10^-3"),
            (50.0, "same unit"),
        ] {
            let xs: Vec<f64> = x.iter().map(|v| v * f).collect();
            let rec = Recording::new(t.clone(), c.clone(), xs).unwrap();
            let w = check_recording(&rec);
            assert!(
                w.iter()
                    .any(|w| w.kind == WarningKind::UnitMismatch && w.message.contains(needle)),
                "{f}: {w:?}"
            );
        }
    }

    #[test]
    fn times_in_ms_read_as_seconds_are_named_and_so_are_mm_read_as_m() {
        // the same recording with its time stamps 1000× too large
        let (t, c, x) = ramp(2000, 2e-4, 1.4e-3, 0.05);
        let slow: Vec<f64> = t.iter().map(|v| v * 1e3).collect();
        let rec = Recording::new(slow, c.clone(), x.clone()).unwrap();
        let w = check_recording(&rec);
        assert!(
            w.iter()
                .any(|w| w.kind == WarningKind::ImplausibleLag && w.message.contains("ms")),
            "{w:?}"
        );
        let fast: Vec<f64> = t.iter().map(|v| v * 1e-3).collect();
        let rec = Recording::new(fast, c.clone(), x.clone()).unwrap();
        assert!(kinds(&rec).contains(&WarningKind::ImplausibleLag));
        // lengths in mm read as metres: 50 m/s
        let cm: Vec<f64> = c.iter().map(|v| v * 1e3).collect();
        let xm: Vec<f64> = x.iter().map(|v| v * 1e3).collect();
        let rec = Recording::new(t, cm, xm).unwrap();
        let w = check_recording(&rec);
        let speed = w
            .iter()
            .find(|w| w.kind == WarningKind::ImplausibleSpeed)
            .unwrap_or_else(|| panic!("{w:?}"));
        assert!(speed.message.contains("unit = mm"), "{speed}");
        let cli = speed.phrased(Syntax::Cli);
        assert!(
            cli.contains("(--unit mm, --unit um), or the times in another unit (--time-unit)?"),
            "{cli}"
        );
        let py = speed.phrased(Syntax::Python);
        assert!(
            py.contains("unit=\"mm\"") && py.contains("(time_unit)"),
            "{py}"
        );
        assert!(!speed.to_string().contains("--"), "{speed}");
        assert_eq!(speed.phrased(Syntax::Library), speed.to_string());
    }

    /// No warning's own text names a command-line flag (`--` and a letter):
    /// the front ends phrase the hints ([`Warning::phrased`]).
    #[test]
    fn library_texts_name_no_command_line_flags() {
        let flag = |s: &str| {
            s.as_bytes()
                .windows(3)
                .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_alphabetic())
        };
        let t: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
        let c: Vec<f64> = t.iter().map(|&t| 0.01 * (2.0 * t).sin()).collect();
        let mut texts = Vec::new();
        // lengths in mm, times in ms, position in µm, lagging a lot
        for (fc, fx, ft, lag) in [
            (1e3, 1e3, 1.0, 0),
            (1.0, 1e3, 1.0, 0),
            (1.0, 1e6, 1.0, 0),
            (1.0, 1.0, 1e3, 5),
            (1.0, 1.0, 1e-3, 5),
            (1.0, 1.0, 1.0, 500),
        ] {
            let tt: Vec<f64> = t.iter().map(|v| v * ft).collect();
            let cc: Vec<f64> = c.iter().map(|v| v * fc).collect();
            let xx: Vec<f64> = (0..c.len())
                .map(|k| c[k.saturating_sub(lag)] * fx)
                .collect();
            let rec = Recording::new(tt, cc, xx).unwrap();
            for w in check_recording(&rec) {
                texts.push(w.to_string());
                let cli = w.phrased(Syntax::Cli);
                if !w.hints.is_empty() {
                    assert!(flag(&cli), "{cli}");
                }
            }
        }
        assert!(texts.len() >= 4, "{texts:?}");
        for s in &texts {
            assert!(!flag(s), "{s}");
        }
    }

    #[test]
    fn a_still_command_and_read_notes_are_reported() {
        let t: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let rec = Recording::new(t, vec![1.0; 10], vec![1.0; 10])
            .unwrap()
            .with_note("columns 4, 5 …".into());
        assert_eq!(
            kinds(&rec),
            vec![WarningKind::CommandStill, WarningKind::ReadNote]
        );
    }
}
