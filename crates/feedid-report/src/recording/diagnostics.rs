//! The diagnostics of a recording's report: residual correlations, the
//! frequency response of the global models, the summary tables.

use super::analysis::RecordingAnalysis;
use crate::error::Result;
use crate::html::{Block, Section, Table};
use crate::plot::{Band, LegendPosition, LineChart, Series};
use feedid::ident::{LinearModel, Regime};
use feedid::lti::{Complex, TransferFunction};

impl RecordingAnalysis {
    pub(super) fn residual_section(&self, p: &str) -> Result<Section> {
        let dt_ms = 1e3 * self.recording.dt();
        let mut sec = Section::new(&format!("{p}-resid-sec"), "Residual analysis");
        sec.blocks.push(Block::Paragraph(
            "Correlations of the prediction errors (residuals) e = measurement − prediction over all predicted samples. \
             Left: autocorrelation r_ee(τ); for a model that captured all predictable dynamics the residual is white and \
             every bar for τ at or beyond the prediction horizon stays inside the grey 99 % band ±2.58/√N (errors of \
             one prediction, from a common origin, are correlated below the horizon whatever the model). Right: cross-correlation r_ue(τ) of the \
             command and the residual; bars outside the band at τ > 0 mean part of the command's effect was missed."
                .into(),
        ));
        for m in &self.runs {
            let Some(ra) = &m.residuals else {
                sec.blocks.push(Block::Paragraph(format!(
                    "{}: too few predicted samples for a residual analysis.",
                    m.label
                )));
                continue;
            };
            let band = Band {
                y0: -ra.bound,
                y1: ra.bound,
                label: "99 % confidence band".into(),
            };
            let stems = |lags: &mut dyn Iterator<Item = (isize, f64)>| {
                let (mut x, mut y) = (Vec::new(), Vec::new());
                for (tau, v) in lags {
                    let xv = tau as f64 * dt_ms;
                    x.extend([xv, xv, f64::NAN]);
                    y.extend([0.0, v, f64::NAN]);
                }
                (x, y)
            };
            let mut ee = LineChart::new(
                &format!("{}: r_ee", m.label),
                "lag τ [ms]",
                "autocorrelation [–]",
            )
            .with_legend(LegendPosition::Below)
            .with_size(560, 320);
            let (x, y) = stems(&mut ra.r_ee.iter().enumerate().map(|(k, &v)| (k as isize, v)));
            ee.push(Series::new("r_ee(τ)", x, y).with_color(1));
            ee.bands.push(band.clone());
            ee.y_range = Some((-1.05, 1.05));
            let mut ue = LineChart::new(
                &format!("{}: r_ue", m.label),
                "lag τ [ms]",
                "cross-correlation [–]",
            )
            .with_legend(LegendPosition::Below)
            .with_size(560, 320);
            let ml = ra.max_lag as isize;
            let (x, y) = stems(
                &mut ra
                    .r_ue
                    .iter()
                    .enumerate()
                    .map(|(k, &v)| (k as isize - ml, v)),
            );
            ue.push(Series::new("r_ue(τ)", x, y).with_color(2));
            ue.bands.push(band);
            let peak = ra.r_ue.iter().fold(ra.bound, |a, v| a.max(v.abs()));
            ue.y_range = Some((-1.1 * peak, 1.1 * peak));
            let verdict = |inside: bool| {
                if inside {
                    "independent of the command"
                } else {
                    "the residual depends on the command"
                }
            };
            sec.blocks.push(Block::Grid(vec![
                Self::figure(
                    format!("{p}-ree-{}", m.slug),
                    &format!("{}: residual autocorrelation", m.label),
                    &ee,
                    &format!(
                        "{} of the {} lags τ = {} … {} outside the 99 % band (N = {}): {}. \
                         Lags below the horizon ({} samples) are correlated for any model: \
                         errors predicted from one origin share its innovations.",
                        ra.ee_outside,
                        ra.max_lag + 1 - ra.ee_first_lag,
                        ra.ee_first_lag,
                        ra.max_lag,
                        ra.samples,
                        if ra.ee_inside {
                            "white enough beyond the horizon"
                        } else {
                            "correlated beyond the horizon — predictable structure is left in the error"
                        },
                        ra.ee_first_lag
                    ),
                )?,
                Self::figure(
                    format!("{p}-rue-{}", m.slug),
                    &format!("{}: command–residual cross-correlation", m.label),
                    &ue,
                    &format!(
                        "{} of the {} lags outside the 99 % band: {} (τ > 0: residual after the command).",
                        ra.ue_outside,
                        2 * ra.max_lag + 1,
                        verdict(ra.ue_inside)
                    ),
                )?,
            ]));
        }
        Ok(sec)
    }

    pub(super) fn bode_section(&self, p: &str) -> Result<Section> {
        let r = &self.recording;
        let nyq = 0.5 * r.rate_hz();
        let f_lo = (1.0 / r.duration().max(1e-9)).max(0.1).min(nyq / 100.0);
        let f_hi = 0.98 * nyq;
        let n = 400;
        let freqs: Vec<f64> = (0..n)
            .map(|i| f_lo * (f_hi / f_lo).powf(i as f64 / (n - 1) as f64))
            .collect();
        let mut mag = LineChart::new(
            "Bode magnitude",
            "frequency [Hz] (log scale)",
            "magnitude [dB]",
        )
        .with_legend(LegendPosition::Below);
        mag.log_x = true;
        let mut ph = LineChart::new("Bode phase", "frequency [Hz] (log scale)", "phase [deg]")
            .with_legend(LegendPosition::Below);
        ph.log_x = true;
        let mut curves = vec![(
            "nominal physical model (7 poles, 2 zeros)".to_string(),
            response_tf(&self.nominal, &freqs),
            0usize,
        )];
        for (i, g) in self.global.iter().enumerate() {
            curves.push((
                format!(
                    "{} (free-run rms {:.2} µm)",
                    g.label,
                    1e6 * g.simulation.rms
                ),
                response_model(&g.model, &freqs)?,
                i + 1,
            ));
        }
        for (label, resp, color) in &curves {
            let db: Vec<f64> = resp.iter().map(|c| 20.0 * c.norm().log10()).collect();
            let phase = unwrap_phase(resp);
            let mut s = Series::new(label, freqs.clone(), db).with_color(*color);
            let mut q = Series::new(label, freqs.clone(), phase).with_color(*color);
            if *color == 0 {
                s = s.dashed();
                q = q.dashed();
            }
            mag.push(s);
            ph.push(q);
        }
        // magnitudes far below the pass band carry no information: floor at −80 dB below the peak
        let top = curves
            .iter()
            .flat_map(|(_, r, _)| r.iter().map(|c| 20.0 * c.norm().log10()))
            .filter(|v| v.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        if top.is_finite() {
            mag.y_range = Some((top - 80.0, top + 10.0));
        }
        let mut sec = Section::new(&format!("{p}-bode-sec"), "Frequency response: identified global models vs nominal model")
            .with(Block::Paragraph(format!(
                "Models fitted over the whole recording (not per window), next to the nominal physical model from {}. \
                 The rms error of each global model's free-run simulation is in the legend. An identified model is only \
                 trustworthy at frequencies the command excited: a ramp or step mostly determines the low-frequency \
                 gain and lag; chirps, PRBS or multisines reveal the resonances.",
                self.options.params_source
            )))
            .with(Block::Figure(Self::figure(
                format!("{p}-bode-mag"),
                "Bode magnitude",
                &mag,
                "0 dB at low frequencies means the table follows the command; the bandwidth is where the magnitude \
                 drops 3 dB; peaks are resonances. Compare the identified curves with the dashed nominal model.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-bode-phase"),
                "Bode phase",
                &ph,
                "Phase lag of the table behind the command; at low frequency the slope corresponds to the following \
                 error (delay 1/Kv).",
            )?));
        for n in &self.notes {
            sec.blocks.push(Block::Paragraph(n.clone()));
        }
        Ok(sec)
    }

    /// The answer in one paragraph: which method predicts best, its error
    /// and coverage, the simulation model beside it, and what to look at.
    /// "Best" is the lowest rms among the methods that predict at least
    /// 95 % of the largest coverage any method reaches (an rms over fewer
    /// samples is not comparable).
    pub(super) fn verdict(&self) -> String {
        let n = self.recording.len().max(1);
        let cov =
            |m: &super::MethodRun| m.identification.summary().samples_predicted as f64 / n as f64;
        let max_cov = self.runs.iter().map(cov).fold(0.0f64, f64::max);
        let best = self
            .runs
            .iter()
            .filter(|m| cov(m) >= 0.95 * max_cov && max_cov > 0.0)
            .filter_map(|m| {
                let s = m.identification.summary();
                s.rms_error_m.filter(|r| r.is_finite()).map(|r| (m, r, s))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let sim = if self.simulation_stats.samples > 0 && self.simulation_stats.rms.is_finite() {
            format!(
                " The nominal simulation model is off by {:.3} µm rms over all {} samples.",
                1e6 * self.simulation_stats.rms,
                self.simulation_stats.samples
            )
        } else {
            String::new()
        };
        match best {
            Some((m, rms, s)) => format!(
                "Answer: {} predicts best here, {} samples ({:.1} ms) ahead: rms {:.3} µm, max {:.3} µm \
                 over {} of {} samples ({:.1} %).{sim} Look first at the prediction error per method \
                 below; coefficients, residual correlations and frequency responses are folded \
                 further down (one click).",
                m.label,
                s.horizon,
                1e3 * s.horizon as f64 / s.rate_hz,
                1e6 * rms,
                1e6 * s.max_abs_error_m.unwrap_or(f64::NAN),
                s.samples_predicted,
                n,
                100.0 * cov(m),
            ),
            None => format!(
                "Answer: no method predicted any sample of this recording, so no prediction error \
                 is reported.{sim}"
            ),
        }
    }

    /// Per method: interval coverage and median width, in all and per
    /// command regime, and the windows cut back as runaways.
    fn interval_table(&self, p: &str) -> Table {
        let mut rows = Vec::new();
        let mut interval = 95.0;
        for m in &self.runs {
            let s = m.identification.summary();
            interval = s.interval_percent;
            let mut row = vec![
                m.label.clone(),
                s.interval_coverage_percent
                    .map_or("–".into(), |c| format!("{c:.1}")),
                s.interval_median_width_m
                    .map_or("–".into(), |w| format!("{:.3}", 1e6 * w)),
            ];
            for r in Regime::ALL {
                row.push(
                    match s.interval_by_regime.iter().find(|x| x.regime == r.name()) {
                        Some(x) => format!("{:.1} ({})", x.coverage_percent, x.samples),
                        None => "–".into(),
                    },
                );
            }
            row.push(format!(
                "{} ({} samples)",
                s.runaway_windows, s.runaway_samples
            ));
            rows.push(row);
        }
        let mut header = vec![
            "method".into(),
            "inside [%]".into(),
            "median width [µm]".into(),
        ];
        header.extend(
            Regime::ALL
                .iter()
                .map(|r| format!("{} [%] (samples)", r.label())),
        );
        header.push("cut back as runaways".into());
        // a regime no method predicted a sample in is left out (a column of "–")
        let absent: Vec<String> = Regime::ALL
            .iter()
            .enumerate()
            .filter(|(i, _)| rows.iter().all(|r| r[3 + i] == "–"))
            .map(|(_, r)| r.label().to_string())
            .collect();
        let keep: Vec<bool> = (0..header.len())
            .map(|j| !(3..3 + Regime::ALL.len()).contains(&j) || rows.iter().any(|r| r[j] != "–"))
            .collect();
        let pick = |v: Vec<String>| -> Vec<String> {
            v.into_iter()
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(c, _)| c)
                .collect()
        };
        let header = pick(header);
        let rows: Vec<Vec<String>> = rows.into_iter().map(pick).collect();
        let left_out = if absent.is_empty() {
            String::new()
        } else {
            format!(
                " No method predicted a sample in: {} (not shown).",
                absent.join(", ")
            )
        };
        Table {
            id: format!("{p}-intervals"),
            caption: format!(
                "The {} % prediction intervals: the share of the predicted samples inside \
                 their interval, in all and by the command's regime at the sample (calibrated per \
                 step ahead and per regime from the method's own recent errors), their median \
                 width, and the windows whose prediction left the motion the axis has shown or \
                 where its command goes and \
                 was cut back (their interval spans the hold).{left_out}",
                feedid::error::short_number(interval)
            ),
            header,
            rows,
        }
    }

    pub(super) fn summary_section(&self, p: &str) -> Section {
        let um = |v: f64| {
            if v.is_finite() {
                format!("{:.3}", 1e6 * v)
            } else {
                "–".into()
            }
        };
        let pct = |v: f64| {
            if v.is_finite() && v > -1e6 {
                format!("{v:.2}")
            } else {
                "–".into()
            }
        };
        let z = self.zoom_text();
        let mut rows = Vec::new();
        for m in &self.runs {
            let s = m.identification.summary();
            rows.push(vec![
                m.label.clone(),
                format!("{}", s.window),
                format!("{}", s.horizon),
                format!("{}", s.windows),
                format!("{}", s.failed_windows),
                format!("{}", s.samples_predicted),
                um(s.rms_error_m.unwrap_or(f64::NAN)),
                um(s.max_abs_error_m.unwrap_or(f64::NAN)),
                pct(s.fit_percent.unwrap_or(f64::NAN)),
                if m.zoom_stats.samples > 0 {
                    um(m.zoom_stats.rms)
                } else {
                    "–".into()
                },
                format!("{:.2}", s.per_window_us),
            ]);
        }
        rows.push(vec![
            "simulation model (nominal)".into(),
            "–".into(),
            "–".into(),
            "–".into(),
            "–".into(),
            format!("{}", self.simulation_stats.samples),
            um(self.simulation_stats.rms),
            um(self.simulation_stats.max_abs),
            pct(self.simulation_stats.fit_percent),
            um(self.simulation_zoom.rms),
            "–".into(),
        ]);
        let table = Table {
            id: format!("{p}-summary"),
            caption: format!(
                "k-step-ahead prediction errors (measurement − prediction) over every predicted sample; the \
                 simulation model over all samples. Fit = NRMSE fit (100 % is perfect). The rms over the first {z} \
                 after the motion start is that of the zoomed figures.{} Time = identification and prediction per \
                 window, methods run in parallel.",
                self.zoom_note()
            ),
            header: vec![
                "method".into(),
                "W".into(),
                "H".into(),
                "windows".into(),
                "failed".into(),
                "samples".into(),
                "rms [µm]".into(),
                "max [µm]".into(),
                "fit [%]".into(),
                format!("rms first {z} [µm]"),
                "time per window [µs]".into(),
            ],
            rows,
        };
        let mut sec = Section::new(&format!("{p}-summary-sec"), "Summary")
            .with(Block::Answer {
                id: format!("{p}-answer"),
                text: self.verdict(),
            })
            .with(Block::Table(table))
            .with(Block::Table(self.interval_table(p)));
        if !self.global.is_empty() {
            sec.blocks.push(Block::Table(Table {
                id: format!("{p}-global"),
                caption: "Global models: free-run simulation from the first sample (no measured positions used), \
                          against the measurement."
                    .into(),
                header: vec!["model".into(), "rms [µm]".into(), "max [µm]".into(), "fit [%]".into()],
                rows: self
                    .global
                    .iter()
                    .map(|g| {
                        vec![
                            g.label.clone(),
                            um(g.simulation.rms),
                            um(g.simulation.max_abs),
                            pct(g.simulation.fit_percent),
                        ]
                    })
                    .collect(),
            }));
        }
        sec
    }
}

/// Complex frequency response of a continuous transfer function.
pub(super) fn response_tf(tf: &TransferFunction, freqs: &[f64]) -> Vec<Complex<f64>> {
    freqs
        .iter()
        .map(|&f| tf.eval(Complex::new(0.0, 2.0 * std::f64::consts::PI * f)))
        .collect()
}

/// Complex frequency response of an identified model (discrete at `z = e^{jωΔt}`).
pub(super) fn response_model(m: &LinearModel, freqs: &[f64]) -> Result<Vec<Complex<f64>>> {
    Ok(match m {
        LinearModel::Continuous { num, den } => {
            response_tf(&TransferFunction::new(num.clone(), den.clone())?, freqs)
        }
        LinearModel::Discrete { b, a, dt } => freqs
            .iter()
            .map(|&f| {
                let w = 2.0 * std::f64::consts::PI * f * dt;
                let zinv = |k: usize| Complex::from_polar(1.0, -w * k as f64);
                let num: Complex<f64> = b.iter().enumerate().map(|(k, &c)| zinv(k) * c).sum();
                let den: Complex<f64> = a.iter().enumerate().map(|(k, &c)| zinv(k) * c).sum();
                num / den
            })
            .collect(),
    })
}

/// Phase in degrees, unwrapped along the list (jumps of more than 180° removed).
pub(super) fn unwrap_phase(resp: &[Complex<f64>]) -> Vec<f64> {
    let mut out = Vec::with_capacity(resp.len());
    let mut prev: Option<f64> = None;
    for c in resp {
        let raw = c.im.atan2(c.re).to_degrees();
        let v = match prev {
            Some(q) if raw.is_finite() => raw + 360.0 * ((q - raw) / 360.0).round(),
            _ => raw,
        };
        if v.is_finite() {
            prev = Some(v);
        }
        out.push(v);
    }
    out
}
