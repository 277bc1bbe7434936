//! The figures of a recording's report: the recording, measured vs
//! simulation model vs predictions, the prediction errors, the coefficients.

use super::analysis::{
    method_color, MethodRun, RecordingAnalysis, COMMAND, MEASUREMENT, SIMULATION,
};
use crate::error::Result;
use crate::html::{Block, Section};
use crate::plot::{decimate_minmax, LegendPosition, LineChart, Series};
use feedid::ident::WindowOutcome;
use feedid::stats::ErrorStats;

impl RecordingAnalysis {
    // ------------------------------------------------------------ sections

    pub(super) fn overview_section(&self, p: &str) -> Result<Section> {
        let (sc, unit) = self.position_unit();
        let (_, tl) = self.time_axis();
        let r = &self.recording;
        let mut c = LineChart::new(
            "Command and measured position",
            tl,
            &format!("position [{unit}]"),
        )
        .with_legend(LegendPosition::Below);
        c.push(
            self.whole("measured position", &|k| Some(r.position()[k]), sc)
                .with_color(MEASUREMENT),
        );
        c.push(
            self.whole("command (set-point)", &|k| Some(r.command()[k]), sc)
                .dashed()
                .with_color(COMMAND),
        );
        let mut e = LineChart::new(
            "Tracking error: command − measured position",
            tl,
            "tracking error [µm]",
        )
        .with_legend(LegendPosition::Hidden);
        e.push(
            self.whole(
                "command − position",
                &|k| Some(r.command()[k] - r.position()[k]),
                1e6,
            )
            .with_color(1),
        );
        Ok(Section::new(&format!("{p}-overview-sec"), "Recording overview")
            .with(Block::Paragraph(format!(
                "The whole recording as read: the command the controller received and the position the encoder measured. \
                 The motion starts {:.1} ms after the first sample; the zoomed figures below start there.",
                1e3 * (self.motion_start - r.time()[0])
            )))
            .with(Block::Figure(Self::figure(
                format!("{p}-overview"),
                "Command and measured position",
                &c,
                "The dashed line is the command, the solid line the measurement. Check that the move looks as intended \
                 and that the two lie on top of each other at this scale.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-tracking"),
                "Tracking error",
                &e,
                "Command minus measured position in µm. A constant offset during a constant-speed move is the \
                 following error of the position loop (speed/Kv); peaks mark accelerations.",
            )?)))
    }

    /// The two charts of the response section (the whole recording and the
    /// zoom after the motion start), each with the sentence naming the curves
    /// cut at its frame (empty when none is).
    pub(super) fn response_charts(&self) -> ((LineChart, String), (LineChart, String)) {
        let (sc, unit) = self.position_unit();
        let (_, tl) = self.time_axis();
        let r = &self.recording;
        let y0 = {
            let k = r
                .time()
                .iter()
                .position(|&t| t >= self.motion_start)
                .unwrap_or(0);
            r.position()[k]
        };
        let mut full = LineChart::new(
            "Measured position, simulation model and predictions",
            tl,
            &format!("position [{unit}]"),
        )
        .with_legend(LegendPosition::Below);
        let mut zoom = LineChart::new(
            &format!("First {} after the motion start", self.zoom_text()),
            "time since motion start [ms]",
            "position from rest [µm]",
        )
        .with_legend(LegendPosition::Below);
        zoom.x_range = Some((0.0, self.zoom_ms()));
        let sim = &self.simulated;
        zoom.push(
            self.zoomed("command", &|k| Some(r.command()[k] - y0), 1e6)
                .with_color(COMMAND)
                .dashed(),
        );
        for (i, m) in self.runs.iter().enumerate() {
            let s = &m.identification.sliding;
            full.push(
                self.whole(&m.label, &|k| s.prediction(k), sc)
                    .with_color(method_color(i)),
            );
            zoom.push(
                self.zoomed(&m.label, &|k| s.prediction(k).map(|v| v - y0), 1e6)
                    .with_color(method_color(i)),
            );
        }
        // measurement and simulation model on top, as the references
        full.push(
            self.whole("simulation model (nominal)", &|k| Some(sim[k]), sc)
                .with_color(SIMULATION)
                .dashed(),
        );
        full.push(
            self.whole("measurement", &|k| Some(r.position()[k]), sc)
                .with_color(MEASUREMENT),
        );
        zoom.push(
            self.zoomed("simulation model (nominal)", &|k| Some(sim[k] - y0), 1e6)
                .with_color(SIMULATION)
                .dashed(),
        );
        zoom.push(
            self.zoomed("measurement", &|k| Some(r.position()[k] - y0), 1e6)
                .with_color(MEASUREMENT),
        );
        // Keep both readable when a method blows up: the y range covers the
        // measurement and the command with a margin; lines leaving it are
        // cut at the frame, and the caption names them and how far they go.
        let references = ["command", "measurement"];
        let whole_range =
            value_range((0..r.len()).flat_map(|k| [sc * r.position()[k], sc * r.command()[k]]));
        let mut full_note = String::new();
        if let Some(frame) = whole_range.map(|(lo, hi)| with_margin(lo, hi, 0.1)) {
            let off = off_frame(&full, frame, unit, tl, &references);
            if !off.is_empty() {
                // only then: a chart nothing leaves keeps its own data range
                full.y_range = Some(frame);
                full.pin_to_edges = true;
                full_note = format!(
                    " The y axis follows the measurement and the command ({} … {} {unit} with a 10 % \
                     margin); curves beyond it run along the frame: {}.",
                    num3(frame.0),
                    num3(frame.1),
                    off.join("; ")
                );
            }
        }
        let idx = self.zoom_indices();
        let zoom_range = value_range(
            idx.iter()
                .flat_map(|&k| [1e6 * (r.position()[k] - y0), 1e6 * (r.command()[k] - y0)]),
        );
        let mut zoom_note = String::new();
        if let Some((lo, hi)) = zoom_range.filter(|(lo, hi)| hi > lo) {
            let frame = with_margin(lo, hi, 0.15);
            zoom.y_range = Some(frame);
            let off = off_frame(
                &zoom,
                frame,
                "µm",
                "time since motion start [ms]",
                &references,
            );
            if !off.is_empty() {
                zoom_note = format!(" Cut at the frame: {}.", off.join("; "));
            }
        }
        ((full, full_note), (zoom, zoom_note))
    }

    pub(super) fn response_section(&self, p: &str) -> Result<Section> {
        let r = &self.recording;
        let ((full, full_note), (zoom, zoom_note)) = self.response_charts();
        let h = self
            .runs
            .first()
            .map_or(10, |m| m.identification.config.horizon);
        Ok(Section::new(&format!("{p}-response-sec"), "Measured vs simulation model vs predictions")
            .with(Block::Paragraph(format!(
                "Each method fits a model to the last W samples and predicts the next H = {h} samples ({:.1} ms) \
                 from it and the known command; the window then moves on by H. The simulation model is the nominal \
                 physical model of the rig parameters driven by the measured command from the start (no data used).{}",
                1e3 * h as f64 * r.dt(),
                self.zoom_note()
            )))
            .with(Block::Figure(Self::figure(
                format!("{p}-response"),
                "Whole recording",
                &full,
                &format!(
                    "The black measurement is drawn on top; at this scale all curves should lie under it, and a \
                     coloured curve that leaves it shows where a method blows up. Gaps are samples without a \
                     prediction (before the first window, or a failed window).{full_note}"
                ),
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-response-zoom"),
                &format!("Zoom on the first {} of the motion (as the paper's figures 5 and 7)", self.zoom_text()),
                &zoom,
                &format!(
                    "Positions relative to the rest position at the motion start. This is where identification is \
                     hardest: the window still contains the standstill. Lines leaving the plot are cut at its edge; \
                     the error figures below show by how much.{zoom_note}"
                ),
            )?)))
    }

    pub(super) fn error_section(&self, p: &str) -> Result<Section> {
        let r = &self.recording;
        let t = r.time();
        let y = r.position();
        let (tf, tl) = self.time_axis();
        let mut per = LineChart::new(
            "Prediction error per horizon (rms over each predicted stretch)",
            tl,
            "rms error [µm] (log scale)",
        )
        .with_legend(LegendPosition::Below);
        per.log_y = true;
        // simulation model over blocks as long as the first method's horizon
        let h = self
            .runs
            .first()
            .map_or(10, |m| m.identification.config.horizon)
            .max(1);
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for start in (0..y.len()).step_by(h) {
            let end = (start + h).min(y.len());
            let s = ErrorStats::from_pairs((start..end).map(|k| (y[k], self.simulated[k])));
            xs.push(tf * (t[end - 1] - t[0]));
            ys.push(1e6 * s.rms);
        }
        let (xs, ys) = decimate_minmax(&xs, &ys, self.options.max_points);
        per.push(
            Series::new("simulation model (nominal)", xs, ys)
                .with_color(SIMULATION)
                .dashed(),
        );
        let mut zoom = LineChart::new(
            &format!(
                "Error in the first {} (as the paper's figures 6 and 8)",
                self.zoom_text()
            ),
            "time since motion start [ms]",
            "measurement − model [µm]",
        )
        .with_legend(LegendPosition::Below);
        zoom.x_range = Some((0.0, self.zoom_ms()));
        for (i, m) in self.runs.iter().enumerate() {
            let s = &m.identification.sliding;
            let color = method_color(i);
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for w in &s.windows {
                let pairs = w
                    .horizon
                    .clone()
                    .filter_map(|k| s.prediction(k).map(|v| (y[k], v)));
                let st = ErrorStats::from_pairs(pairs);
                if st.samples > 0 && w.horizon.end > 0 {
                    xs.push(tf * (t[w.horizon.end - 1] - t[0]));
                    ys.push(1e6 * st.rms);
                } else if let Some(k) = w.horizon.end.checked_sub(1) {
                    xs.push(tf * (t[k] - t[0]));
                    ys.push(f64::NAN);
                }
            }
            let (xs, ys) = decimate_minmax(&xs, &ys, self.options.max_points);
            per.push(Series::new(&m.label, xs, ys).with_color(color));
            zoom.push(
                self.zoomed(&m.label, &|k| s.prediction(k).map(|v| y[k] - v), 1e6)
                    .with_color(color),
            );
        }
        zoom.push(
            self.zoomed(
                "simulation model (nominal)",
                &|k| Some(y[k] - self.simulated[k]),
                1e6,
            )
            .with_color(SIMULATION)
            .dashed(),
        );
        // the same, with the y axis at the simulation model's error scale
        let mut detail = zoom.clone();
        detail.title = format!(
            "Error in the first {}, detail at the simulation model's scale",
            self.zoom_text()
        );
        let lim = 1.3 * (1e6 * self.simulation_zoom.max_abs).max(1.0);
        detail.y_range = Some((-lim, lim));
        Ok(Section::new(&format!("{p}-error-sec"), "Prediction error per method")
            .with(Block::Figure(Self::figure(
                format!("{p}-error"),
                "Prediction error over the recording",
                &per,
                "One point per prediction horizon: the rms of measurement − prediction over the H predicted samples \
                 (log scale, so µm and mm errors are both visible). Lower is better; the dashed line is the nominal \
                 simulation model over blocks of the same length. Spikes show where a method fails.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-error-zoom"),
                &format!("Error in the first {} of the motion", self.zoom_text()),
                &zoom,
                "Measurement − model, sample by sample, in µm, at full scale: the largest errors of any method.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-error-zoom-detail"),
                &format!("Error in the first {}, detail", self.zoom_text()),
                &detail,
                &format!(
                    "The same errors with the y axis limited to ±{lim:.1} µm (1.3 × the simulation model's largest \
                     error here), so the accurate methods can be compared with the simulation model; larger errors \
                     are cut at the edge. The paper reports its identified model tracking the measurement better \
                     than the simulation model."
                ),
            )?)))
    }

    /// One chart of the coefficients `idx` of run `m`; returns it and whether its y axis is log.
    pub(super) fn coefficient_chart(
        &self,
        m: &MethodRun,
        idx: &[usize],
        title: &str,
        size: (u32, u32),
    ) -> (LineChart, bool) {
        let t = self.recording.time();
        let (tf, tl) = self.time_axis();
        let s = &m.identification.sliding;
        let mut c = LineChart::new(title, tl, "coef. / median |coef.|")
            .with_legend(LegendPosition::Below)
            .with_size(size.0, size.1);
        c.pin_to_edges = true;
        let x: Vec<f64> = s
            .windows
            .iter()
            .map(|w| tf * (t[w.window.end.saturating_sub(1)] - t[0]))
            .collect();
        let mut all = Vec::new();
        for (k, &j) in idx.iter().enumerate() {
            let vals: Vec<f64> = (0..s.windows.len())
                .map(|w| {
                    if s.windows[w].outcome == WindowOutcome::Failed {
                        f64::NAN
                    } else {
                        s.window_coefficients(w)[j]
                    }
                })
                .collect();
            let mut mags: Vec<f64> = vals
                .iter()
                .filter(|v| v.is_finite())
                .map(|v| v.abs())
                .collect();
            mags.sort_by(f64::total_cmp);
            let med = mags.get(mags.len() / 2).copied().unwrap_or(0.0);
            let y: Vec<f64> = vals
                .iter()
                .map(|&v| if med > 0.0 { v / med } else { f64::NAN })
                .collect();
            all.extend(y.iter().copied().filter(|v| v.is_finite()));
            let (xd, yd) = decimate_minmax(&x, &y, self.options.max_points / 5);
            c.push(Series::new(&s.coefficient_names[j], xd, yd).with_color(k % 8));
        }
        all.sort_by(f64::total_cmp);
        let mut log = false;
        if !all.is_empty() {
            let q = |f: f64| all[((all.len() - 1) as f64 * f).round() as usize];
            let (a, b) = (q(0.02), q(0.98));
            // keep ±1 in view (only +1 when every value is positive, −1 when negative)
            let lo = a.min(if a >= 0.0 { 0.8 } else { -1.2 });
            let hi = b.max(if b <= 0.0 { -0.8 } else { 1.2 });
            if hi - lo > 40.0 {
                // coefficients spanning decades: magnitudes on a log axis
                log = true;
                c.log_y = true;
                c.y_label = "|coef.| / median |coef.| (log scale)".into();
                c.y_range = Some((1e-3, 1e3));
                for series in &mut c.series {
                    for v in &mut series.y {
                        *v = v.abs();
                    }
                }
            } else {
                let pad = 0.08 * (hi - lo);
                c.y_range = Some((lo - pad, hi + pad));
            }
        }
        (c, log)
    }

    pub(super) fn coefficient_section(&self, p: &str) -> Result<Section> {
        let mut sec = Section::new(
            &format!("{p}-coef-sec"),
            "Identified coefficients over time",
        );
        sec.blocks.push(Block::Paragraph(
            "One point per window, at the window's last sample, each coefficient divided by the median of its \
             magnitude over all windows so that all share one scale: a steady coefficient is a flat line at +1 or \
             −1 (at 1 on a log axis, used when the values span decades; the sign is then not shown). A method that \
             identifies a consistent model gives flat lines while the motion is informative. Lines leaving the plot \
             (beyond the 2nd/98th percentile, or 1/1000 and 1000 of the median on a log axis) run along its edge. \
             Names as in the coefficients file of feedid identify: the paper method's N2…N0, D7…D0 (eq. 6), ARX/RLS \
             a1…a_na, b_nk…, OE N…, D…."
                .into(),
        ));
        for m in &self.runs {
            let names = &m.identification.sliding.coefficient_names;
            // groups by the name's first letter (N/D, a/b), merged while they fit 8 colours
            let mut groups: Vec<Vec<usize>> = Vec::new();
            let mut prev: Option<char> = None;
            for (j, name) in names.iter().enumerate() {
                let first = name.chars().next();
                match groups.last_mut() {
                    Some(g) if first == prev && g.len() < 8 => g.push(j),
                    _ => groups.push(vec![j]),
                }
                prev = first;
            }
            let mut merged: Vec<Vec<usize>> = Vec::new();
            for g in groups {
                match merged.last_mut() {
                    Some(last) if last.len() + g.len() <= 8 => last.extend(g),
                    _ => merged.push(g),
                }
            }
            let mut figs = Vec::new();
            for (gi, idx) in merged.iter().enumerate() {
                let (Some(&first), Some(&last)) = (idx.first(), idx.last()) else {
                    continue;
                };
                let span = if first == last {
                    names[first].clone()
                } else {
                    format!("{} … {}", names[first], names[last])
                };
                let title = format!("{}: coefficients {span}", m.label);
                let size = if merged.len() > 1 {
                    (620, 400)
                } else {
                    (900, 360)
                };
                let (chart, log) = self.coefficient_chart(m, idx, &title, size);
                let id = if gi == 0 {
                    format!("{p}-coef-{}", m.slug)
                } else {
                    format!("{p}-coef-{}-{}", m.slug, gi + 1)
                };
                figs.push(Self::figure(
                    id,
                    &format!("{} coefficients {span} over time", m.label),
                    &chart,
                    if log {
                        "Magnitudes relative to their medians on a log axis (the values span decades)."
                    } else {
                        "Values relative to their median magnitudes."
                    },
                )?);
            }
            match figs.len() {
                0 => {}
                1 => sec.blocks.extend(figs.into_iter().map(Block::Figure)),
                _ => sec.blocks.push(Block::Grid(figs)),
            }
        }
        Ok(sec)
    }
}

/// The smallest and largest finite value, if any.
fn value_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    (lo <= hi).then_some((lo, hi))
}

/// `lo … hi` widened by `share` of its span on each side (by 5 % of the
/// magnitude, or 1, for a flat range).
fn with_margin(lo: f64, hi: f64, share: f64) -> (f64, f64) {
    let m = if hi > lo {
        share * (hi - lo)
    } else if hi.abs() > 0.0 {
        0.05 * hi.abs()
    } else {
        1.0
    };
    (lo - m, hi + m)
}

/// A number to three significant digits, plainly written ("1090", "0.0123").
fn num3(v: f64) -> String {
    format!("{v:.2e}")
        .parse::<f64>()
        .map_or_else(|_| v.to_string(), |x| x.to_string())
}

/// The curves of `chart` (but those labelled in `skip`) that leave the y
/// range `frame`, one phrase each: the curve, its farthest value (in
/// `unit`), where it is (x as in `x_label`) and how far beyond the frame.
fn off_frame(
    chart: &LineChart,
    frame: (f64, f64),
    unit: &str,
    x_label: &str,
    skip: &[&str],
) -> Vec<String> {
    let (lo, hi) = frame;
    let x_unit = x_label
        .rsplit_once('[')
        .map_or("", |(_, u)| u.trim_end_matches(']'));
    let mut out = Vec::new();
    for s in chart
        .series
        .iter()
        .filter(|s| !skip.contains(&s.label.as_str()))
    {
        let far =
            s.x.iter()
                .zip(&s.y)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .filter(|(x, _)| chart.x_range.is_none_or(|(a, b)| **x >= a && **x <= b))
                .map(|(&x, &y)| (x, y, (y - hi).max(lo - y)))
                .filter(|&(_, _, beyond)| beyond > 0.0)
                .max_by(|a, b| a.2.total_cmp(&b.2));
        if let Some((x, y, beyond)) = far {
            out.push(format!(
                "{} reaches {} {unit} at {} {x_unit}, {} {unit} beyond it",
                s.label,
                num3(y),
                num3(x),
                num3(beyond)
            ));
        }
    }
    out
}
