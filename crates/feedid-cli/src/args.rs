//! Command-line arguments.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use feedid::error::Syntax;
use feedid::ident::{OptionKind, Span};

/// Identify feed-drive dynamics in short sliding windows and predict the next milliseconds.
#[derive(Debug, Parser)]
#[command(name = "feedid", version, about, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a scenario on the virtual rig and write a recording.
    Simulate(SimulateArgs),
    /// Identify over sliding windows and predict the next samples (restarting after dropped samples).
    Identify(Box<IdentifyArgs>),
    /// Select ARX orders: FPE, AIC, AICc, BIC over a grid, and FROLS term selection (on the stretch between dropped samples where the command moves most).
    Order(Box<OrderArgs>),
    /// Run the paper's experiments (ramp and step) end to end on the virtual rig.
    Reproduce(ReproduceArgs),
    /// Summarise a recording: samples, rate and jitter, gaps, channel ranges, motion segments.
    Info(Box<InfoArgs>),
    /// Print the nominal model: stiffness, inertia, N and D, poles, bandwidth, following error.
    Model(ModelArgs),
    /// Identify and predict online: CSV samples on stdin, predictions on stdout as they are due.
    Stream(Box<StreamArgs>),
    /// Write a self-contained HTML report of a recording: figures, residuals, Bode plot, summary.
    Report(Box<ReportArgs>),
    /// Error of every window × horizon × method × order combination, heat map, best choice (restarting after dropped samples).
    Sweep(Box<SweepArgs>),
    /// Estimate physical parameters (Kv, Kp, Ki, C2, M, K, ...) from a recording or identified N, D.
    Greybox(Box<GreyboxArgs>),
    /// Compute the command that makes the predicted position follow a desired trajectory.
    Compensate(Box<CompensateArgs>),
    /// List the drive zoo (generated recordings of many drives) or write its members as CSV.
    Zoo(crate::cmd::zoo::ZooArgs),
    /// Retune the loop gains of a drive structure (P/P, P/PI, PD or PID commanding force) for a bandwidth and damping.
    Tune(crate::cmd::tune::TuneArgs),
}

/// Which D1 coefficient to use.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum D1Arg {
    /// Consistent with the state equations (following error 1/Kv).
    Corrected,
    /// As printed in the paper's appendix (lacks +N1; for comparison only).
    Paper,
}

/// `feedid model`.
#[derive(Debug, Args)]
pub struct ModelArgs {
    /// Rig parameters (TOML), or a drive structure file (its `[drive]` and
    /// `[mechanics]` tables: loops, drive gain, mass, friction law; see
    /// examples/emps.toml); default: the built-in default rig.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// D1 coefficient variant.
    #[arg(long, value_enum, default_value = "corrected")]
    pub d1: D1Arg,
    /// Write the parameters used as TOML to this file (a template to edit).
    #[arg(long, value_name = "rig.toml")]
    pub save_params: Option<PathBuf>,
}

/// How to read a recording (every command that reads one uses these).
#[derive(Debug, Clone, Args)]
pub struct RecordingArgs {
    /// Time column/variable, by name or 1-based index [default: time_s in text files].
    #[arg(long, value_name = "NAME|N")]
    pub time: Option<String>,
    /// Command (set-point) column/variable [default: command_m in text files].
    #[arg(long, value_name = "NAME|N")]
    pub command: Option<String>,
    /// Measured-position column/variable [default: position_m in text files].
    #[arg(long, value_name = "NAME|N")]
    pub position: Option<String>,
    /// Sampling rate when the file has no time column [Hz].
    #[arg(long, value_name = "HZ")]
    pub rate: Option<f64>,
    /// Delimiter of text files: ',', ';', 'tab', 'space' [default: detected].
    #[arg(long, value_name = "CHAR")]
    pub delimiter: Option<String>,
    /// The first row is data, not a header [default: detected].
    #[arg(long, conflicts_with = "header")]
    pub no_header: bool,
    /// The first row is a header [default: detected].
    #[arg(long)]
    pub header: bool,
    /// Unit of command and position in the file: m, mm, um, nm.
    #[arg(long, value_name = "UNIT", default_value = "m")]
    pub unit: String,
    /// Metres per file unit of command and position (e.g. encoder counts → m).
    #[arg(long, value_name = "M_PER_UNIT")]
    pub scale: Option<f64>,
    /// Unit of the time column: s, ms, us.
    #[arg(long, value_name = "UNIT", default_value = "s")]
    pub time_unit: String,
    /// Allowed relative deviation of a sampling interval from the mean one.
    #[arg(long, value_name = "FRACTION", default_value_t = 0.01)]
    pub jitter_tol: f64,
}

/// `feedid info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Recording: CSV/text or MATLAB v5 .mat file.
    pub input: PathBuf,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `feedid simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Command: ramp (30 mm at 50 mm/s), step (1 mm in 0.2 ms), scurve, chirp, prbs, multisine.
    #[arg(long, value_name = "NAME", required_unless_present = "command")]
    pub scenario: Option<String>,
    /// Run this command instead of a scenario: a CSV with a time column (time_s) and the command (--command-column), at its own sampling rate (e.g. the output of `feedid compensate`).
    #[arg(long, value_name = "cmd.csv", conflicts_with_all = ["scenario", "rate", "duration"])]
    pub command: Option<PathBuf>,
    /// Column of the command in --command, by name or 1-based index.
    #[arg(
        long,
        value_name = "NAME|N",
        default_value = "command_m",
        requires = "command"
    )]
    pub command_column: String,
    /// Time column (or `.mat` variable) of --command, by name or 1-based index;
    /// default: found by its name (time_s, time, t) in a CSV.
    #[arg(long, value_name = "NAME|N", requires = "command")]
    pub time_column: Option<String>,
    /// Rig parameters (TOML), or a drive structure file (examples/emps.toml:
    /// loops, drive gain, mass, friction law; a sampled controller runs at
    /// the command's rate); default: the built-in default rig.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Nonlinear effects of the virtual rig: a TOML file of any of the keys friction
    /// ([motor_friction], [table_friction]), variable_stiffness, limits (current_limit,
    /// voltage_limit), quantisation (resolution), noise (noise_std), position_loop
    /// (sampled, continuous, interpolated), backlash (backlash_width), dead_time and
    /// [pulses] (force, width, period, first); missing keys keep the default: all on
    /// but backlash, dead time and pulses.
    #[arg(long, value_name = "effects.toml", conflicts_with = "linear", long_help = crate::cmd::simulate::effects_long_help())]
    pub effects: Option<PathBuf>,
    /// Seed of the measurement noise (and of the PRBS).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Switch every nonlinear effect off (continuous linear cascade, no noise).
    #[arg(long)]
    pub linear: bool,
    /// Use an unstable physical model anyway (its simulation diverges; refused by default).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Duration [s]; default: the scenario's.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Sampling rate [Hz].
    #[arg(long, value_name = "HZ", default_value_t = 5000.0)]
    pub rate: f64,
    /// Output CSV: time_s,command_m,position_m,true_position_m,current_a,velocity_m_per_s.
    #[arg(short, long, value_name = "out.csv")]
    pub output: PathBuf,
}

/// The per-method options of every subcommand that takes a method
/// (identify, stream, report, sweep), flattened into each: one flag per
/// library option description ([`feedid::ident::Method::options`]: flag,
/// value name, help with the methods that have it and their defaults),
/// turned into [`feedid::ident::Method`]s by `cmd::method`. An option given
/// for a method that does not have it is refused, never ignored.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MethodOptions {
    /// The options given: key (`"lambda"`) and value as text, in the order of
    /// [`feedid::ident::Method::options`].
    pub values: Vec<(&'static str, String)>,
}

impl clap::FromArgMatches for MethodOptions {
    fn from_arg_matches(m: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut values = Vec::new();
        for o in feedid::ident::Method::options() {
            let key = o.spec.key;
            let v = match o.spec.kind {
                OptionKind::Float => m.get_one::<f64>(key).map(f64::to_string),
                OptionKind::Int => m.get_one::<usize>(key).map(usize::to_string),
                OptionKind::Choice(_) | OptionKind::Orders => m.get_one::<String>(key).cloned(),
            };
            if let Some(v) = v {
                values.push((key, v));
            }
        }
        Ok(Self { values })
    }

    fn update_from_arg_matches(&mut self, m: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl Args for MethodOptions {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        feedid::ident::Method::options()
            .into_iter()
            .fold(cmd, |cmd, o| {
                let arg = clap::Arg::new(o.spec.key)
                    .long(o.spec.flag().trim_start_matches('-').to_string())
                    .value_name(o.spec.value_name)
                    .help(o.help(Syntax::Cli))
                    .action(clap::ArgAction::Set);
                cmd.arg(match o.spec.kind {
                    OptionKind::Float => arg.value_parser(clap::value_parser!(f64)),
                    OptionKind::Int => arg.value_parser(clap::value_parser!(usize)),
                    OptionKind::Choice(_) | OptionKind::Orders => arg,
                })
            })
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

/// Sliding-window options.
#[derive(Debug, Clone, Args)]
pub struct WindowArgs {
    /// Window length W [samples, or a time: 10ms] [default: the method's, see below].
    #[arg(long, value_name = "N|TIME", long_help = window_help())]
    pub window: Option<Span>,
    /// Prediction horizon H: samples (10) or a time (2ms, at the recording's rate).
    #[arg(long, value_name = "N|TIME", default_value = "10")]
    pub horizon: Span,
    /// Shift between windows: samples or a time; default: the horizon.
    #[arg(long, value_name = "N|TIME")]
    pub hop: Option<Span>,
}

/// `--window`'s help, with every method's default window.
fn window_help() -> String {
    let defaults: Vec<String> = feedid::ident::Method::all()
        .iter()
        .map(|m| format!("{} {}", m.name(), m.default_window()))
        .collect();
    format!(
        "Window length W: samples, or a time with its unit (20ms, at the recording's rate); default: the method's, in samples ({})",
        defaults.join(", ")
    )
}

/// The methods `feedid report` compares by default.
pub const REPORT_METHODS: &str = "paper,arx,rls,oe,auto";

/// The methods `feedid sweep` compares by default.
pub const SWEEP_METHODS: &str = "paper,arx";

/// `--methods`' help, with every method's name and the default list.
fn methods_help(default: &str) -> String {
    format!(
        "Methods, comma-separated: {} [default: {default}]",
        feedid::ident::METHOD_NAMES
    )
}

/// `--method`'s help, with every method's name.
fn method_help() -> String {
    format!(
        "Identification method: {} (auto: validated choice of model, order and memory)",
        feedid::ident::METHOD_NAMES
    )
}

/// `feedid identify`.
#[derive(Debug, Args)]
pub struct IdentifyArgs {
    /// Recording(s): CSV/text or MATLAB v5 .mat files; several need --out-dir.
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Identification method.
    #[arg(long, default_value = "auto", value_name = "NAME", help = method_help())]
    pub method: String,
    /// Options of the method.
    #[command(flatten)]
    pub options: MethodOptions,
    /// Windows.
    #[command(flatten)]
    pub windows: WindowArgs,
    /// Probability of the prediction intervals (lower_m, upper_m) [%], in (0, 100).
    #[arg(long, value_name = "P", default_value_t = 95.0)]
    pub interval: f64,
    /// Cut back a predicted sample that leaves FACTOR times the motion the
    /// axis has shown in as many samples, or the hull of where its command
    /// goes (its interval widened to the hold); `off` keeps every prediction
    /// as the method made it.
    #[arg(long, value_name = "FACTOR|off", default_value = "1.5")]
    pub runaway: Runaway,
    /// Rig parameters of the nominal simulation model (TOML); default: the built-in rig.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Use an unstable physical model anyway (its simulation diverges; refused by default).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Predictions CSV: time_s,command_m,measured_m,predicted_m,lower_m,upper_m,simulated_m.
    #[arg(
        short,
        long,
        value_name = "predictions.csv",
        required_unless_present = "out_dir"
    )]
    pub output: Option<PathBuf>,
    /// Batch mode: identify every input in parallel (all cores) and write
    /// NAME.predictions.csv, NAME.coefficients.csv and NAME.summary.json here.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["output", "coefficients", "summary"])]
    pub out_dir: Option<PathBuf>,
    /// Per-window coefficients CSV.
    #[arg(long, value_name = "coef.csv")]
    pub coefficients: Option<PathBuf>,
    /// Summary JSON.
    #[arg(long, value_name = "summary.json")]
    pub summary: Option<PathBuf>,
    /// Also fit a global model of the whole recording and write it as JSON
    /// (for `feedid compensate --model` and `feedid greybox --from-model`).
    #[arg(long, value_name = "model.json", conflicts_with = "out_dir")]
    pub model_out: Option<PathBuf>,
    /// Kind of the global model: auto (best free-run fit of arx 8,8,1, oe 7,2, oe 5,1), arx, oe [default: auto].
    #[arg(long, value_name = "NAME", requires = "model_out")]
    pub model_kind: Option<String>,
    /// Orders of the global model: na,nb,nk (arx) or poles,zeros (oe) [default: 8,8,1 / 7,2].
    #[arg(long, value_name = "ORDERS", requires = "model_out")]
    pub model_order: Option<String>,
}

/// `feedid reproduce`.
#[derive(Debug, Args)]
pub struct ReproduceArgs {
    /// Output directory for figures and summary.md.
    #[arg(long, value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
    /// Rig parameters (TOML); default: the built-in default rig.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Seed of the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Use an unstable physical model anyway (its simulation diverges; refused by default).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Solver of the paper method: qr or simplex.
    #[arg(long, default_value = "simplex", value_name = "NAME")]
    pub solver: String,
    /// Methods compared with the paper's in report.html (comma-separated).
    #[arg(long, default_value = "arx,rls,oe,auto", value_name = "LIST")]
    pub compare: String,
    /// Measured axis: nominal (the rig is the simulation model plus its effects) or real (off the nominal model: mass ×1.25, stiffness ×0.75, C2 ×1.5, Kt and Ke ×0.92, table friction ×1.6, 2 samples dead time).
    #[arg(long, default_value = "nominal", value_name = "AXIS")]
    pub axis: String,
}

/// `feedid order`.
#[derive(Debug, Args)]
pub struct OrderArgs {
    /// Recording: CSV/text or MATLAB v5 .mat file.
    pub input: PathBuf,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Range of na (poles), `lo..hi` or `n`.
    #[arg(long, default_value = "1..8", value_name = "LO..HI")]
    pub na: String,
    /// Range of nb (input terms).
    #[arg(long, default_value = "1..8", value_name = "LO..HI")]
    pub nb: String,
    /// Range of nk (input delay in samples).
    #[arg(long, default_value = "0..2", value_name = "LO..HI")]
    pub nk: String,
    /// Criterion of the choice: fpe, aic, aicc, bic.
    #[arg(long, default_value = "bic", value_name = "NAME")]
    pub criterion: String,
    /// Fraction of the samples at the end held out for validation.
    #[arg(long, default_value_t = 0.0, value_name = "FRACTION")]
    pub validation: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `feedid stream`.
#[derive(Debug, Args)]
pub struct StreamArgs {
    /// Identification method.
    #[arg(long, default_value = "auto", value_name = "NAME", help = method_help(), conflicts_with = "compensate")]
    pub method: String,
    /// Options of the method.
    #[command(flatten)]
    pub options: MethodOptions,
    /// Windows.
    #[command(flatten)]
    pub windows: WindowArgs,
    /// Probability of the prediction intervals (lower_m, upper_m) [%], in (0, 100).
    #[arg(long, value_name = "P", default_value_t = 95.0)]
    pub interval: f64,
    /// Cut back a predicted sample that leaves FACTOR times the motion the
    /// axis has shown in as many samples, or the hull of where its command
    /// goes (its interval widened to the hold); `off` keeps every prediction
    /// as the method made it.
    #[arg(long, value_name = "FACTOR|off", default_value = "1.5")]
    pub runaway: Runaway,
    /// How to read the lines (as a recording file; without a header and
    /// without column options: time, command, position are columns 1, 2, 3).
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// The command on each line belongs to the sample N lines later (an
    /// interpolator's look-ahead) [samples]; with N ≥ the horizon every
    /// prediction is written before the line of its measurement is read.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub command_lead: usize,
    /// Command over the horizon beyond the lead: acceleration (from the last
    /// three commands), velocity (last two), hold, or wait (no extrapolation:
    /// predictions come after their measurement, as identify's)
    /// [default: acceleration].
    #[arg(long, value_name = "HOW")]
    pub extrapolate: Option<String>,
    /// Online compensation instead of predictions: each line's command is
    /// the desired program, --command-lead N ≥ 3 lines ahead; for each
    /// coming sample the corrected command is written (time_s, desired_m,
    /// command_m) as soon as the line before it is read, from feed-forward
    /// time constants identified while the axis runs (the method and window
    /// options do not apply).
    #[arg(long)]
    pub compensate: bool,
    /// With --compensate: the positions answer the input's own command
    /// column (a recorded run replayed), not the commands written.
    #[arg(long, requires = "compensate")]
    pub replay: bool,
    /// With --compensate: start from an identified model (model.json of
    /// `identify --model-out`, at the stream's sample interval) instead of
    /// from nothing: compensated from the first sample, refined as it runs.
    #[arg(long, value_name = "model.json", requires = "compensate")]
    pub model: Option<std::path::PathBuf>,
    /// With --compensate: command velocity limit [m/s] (inf: none).
    #[arg(long, value_name = "V", default_value_t = 1.0, requires = "compensate")]
    pub max_velocity: f64,
    /// With --compensate: command acceleration limit [m/s²] (inf: none).
    #[arg(
        long,
        value_name = "A",
        default_value_t = 30.0,
        requires = "compensate"
    )]
    pub max_acceleration: f64,
}

/// `feedid report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Recording: CSV/text or MATLAB v5 .mat file.
    pub input: PathBuf,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Methods, comma-separated [default: paper,arx,rls,oe,auto].
    #[arg(long, value_name = "LIST", help = methods_help(REPORT_METHODS))]
    pub methods: Option<String>,
    /// Options of the methods (each goes to the methods that have it).
    #[command(flatten)]
    pub options: MethodOptions,
    /// Windows (one --window applies to every method).
    #[command(flatten)]
    pub windows: WindowArgs,
    /// Rig parameters of the nominal model (TOML); default: the built-in rig.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Use an unstable physical model anyway (its simulation diverges; refused by default).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Length of the zoom after the motion start [ms]; widened where it would hold too few samples or no method's first predictions.
    #[arg(long, value_name = "MS", default_value_t = 60.0)]
    pub zoom: f64,
    /// Output HTML file.
    #[arg(short, long, value_name = "report.html")]
    pub output: PathBuf,
}

/// `feedid sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Recording: CSV/text or MATLAB v5 .mat file.
    pub input: PathBuf,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Methods, comma-separated [default: paper,arx].
    #[arg(long, value_name = "LIST", help = methods_help(SWEEP_METHODS))]
    pub methods: Option<String>,
    /// Options of the methods (each goes to the methods that have it).
    #[command(flatten)]
    pub options: MethodOptions,
    /// Window lengths W [samples], comma-separated.
    #[arg(long, value_name = "LIST", default_value = "10,20,40,80,160")]
    pub windows: String,
    /// Horizons H [samples], comma-separated.
    #[arg(long, value_name = "LIST", default_value = "10")]
    pub horizons: String,
    /// ARX/RLS orders to sweep, each `na,nb,nk` (several after one flag, or the flag repeated).
    #[arg(long, value_name = "NA,NB,NK", num_args = 1..)]
    pub orders: Vec<String>,
    /// Shift between windows [samples]; default: the horizon.
    #[arg(long)]
    pub hop: Option<usize>,
    /// Output CSV, one row per combination.
    #[arg(short, long, value_name = "sweep.csv")]
    pub output: PathBuf,
    /// Heat map SVG (window × method/order, colour = rms error).
    #[arg(long, value_name = "sweep.svg")]
    pub plot: Option<PathBuf>,
}

/// `feedid greybox`.
#[derive(Debug, Args)]
pub struct GreyboxArgs {
    /// Recording: CSV/text or MATLAB v5 .mat file (omit with --from-model).
    #[arg(required_unless_present = "from_model", conflicts_with = "from_model")]
    pub input: Option<PathBuf>,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Starting (nominal) rig parameters, or a drive structure file (examples/emps.toml);
    /// the others stay fixed at these values [default: the built-in rig].
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Parameters to estimate, comma separated: Kv, Kp, Ki, Kvff, Kaff, Kpi, Kii, Kt, Ke, R, L, C1, C2, M, J, K, Fc, Tc;
    /// for a drive structure: M, Fv, Fc, offset, gain, kp, kv, and Fs (static friction),
    /// Mm, k, c (two-mass: motor mass, transmission stiffness and damping).
    #[arg(long, value_name = "LIST")]
    pub estimate: String,
    /// Measured motor-current column/variable [A], used as a second output; for a
    /// drive structure, the controller output (force = drive gain × it), for an
    /// inverse-dynamics (IDIM-LS) cross-check.
    #[arg(long, value_name = "NAME")]
    pub current: Option<String>,
    /// Simulate the nonlinear virtual rig (friction, variable stiffness, limits) instead of the linear model.
    #[arg(long)]
    pub friction: bool,
    /// Friction law and limits of the nonlinear model (TOML, as for `feedid simulate --effects`).
    #[arg(long, value_name = "effects.toml", requires = "friction")]
    pub effects: Option<PathBuf>,
    /// Position loop of the model: sampled (P controller at the sample rate) or continuous.
    #[arg(long, default_value = "sampled", value_name = "NAME")]
    pub position_loop: String,
    /// Estimate from an identified model's N and D instead of a recording
    /// (continuous, 7 poles and 2 zeros: `feedid identify --model-out M --model-kind oe`).
    #[arg(long, value_name = "model.json")]
    pub from_model: Option<PathBuf>,
    /// Fit a set that is not identifiable anyway and report it, instead of refusing.
    #[arg(long)]
    pub allow_unidentifiable: bool,
    /// Use an unstable physical model anyway (its simulation diverges; refused by default).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Levenberg–Marquardt iteration cap.
    #[arg(long, default_value_t = 100, value_name = "N")]
    pub max_iterations: usize,
    /// Fits restarted from the estimate moved ±22 % to check that the data pin it (0: no check).
    #[arg(long, default_value_t = 2, value_name = "N")]
    pub restarts: usize,
    /// Summary JSON.
    #[arg(long, value_name = "gb.json")]
    pub summary: Option<PathBuf>,
    /// Simulate the estimated model (the paper's rig, or a drive structure) on
    /// another recording of the axis (read with the same column options) and
    /// report how it fits.
    #[arg(long, value_name = "rec.csv")]
    pub validate: Option<PathBuf>,
    /// Write the rig parameters with the estimates in place (TOML), e.g. for `feedid compensate --params`.
    #[arg(long, value_name = "rig.toml")]
    pub params_out: Option<PathBuf>,
    /// Track the parameters over sliding windows of this length [s] (linear model).
    #[arg(long, value_name = "S", conflicts_with = "from_model")]
    pub track_window: Option<f64>,
    /// Shift between tracking windows [s] [default: half the window].
    #[arg(long, value_name = "S", requires = "track_window")]
    pub track_hop: Option<f64>,
    /// Tracking CSV: time_s,nut_position_m,mean_position_m, then NAME,NAME_std_error,NAME_verdict per parameter, residual_rms_m, termination.
    #[arg(long, value_name = "track.csv", requires = "track_window")]
    pub track_out: Option<PathBuf>,
}

/// `feedid compensate`.
#[derive(Debug, Args)]
pub struct CompensateArgs {
    /// Desired trajectory: CSV with a time column and a position column.
    #[arg(long, value_name = "desired.csv")]
    pub desired: PathBuf,
    /// Column of the desired position, by name or 1-based index.
    #[arg(long, value_name = "NAME|N", default_value = "position_m")]
    pub desired_column: String,
    /// Time column of the desired trajectory, by name or 1-based index.
    #[arg(long, value_name = "NAME|N", default_value = "time_s")]
    pub desired_time: String,
    /// Identified model (`feedid identify --model-out`).
    #[arg(
        long,
        value_name = "model.json",
        conflicts_with = "params",
        required_unless_present = "params"
    )]
    pub model: Option<PathBuf>,
    /// Physical model instead: rig parameters (TOML), e.g. from `feedid greybox --params-out`.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Position loop of the physical model: sampled or continuous.
    #[arg(long, default_value = "sampled", value_name = "NAME")]
    pub position_loop: String,
    /// Output CSV: time_s,command_m,desired_m,predicted_m.
    #[arg(short, long, value_name = "command.csv")]
    pub output: PathBuf,
    /// Zero-phase Gaussian smoothing σ of the correction to the desired trajectory [s], or auto (smallest σ within the limits).
    #[arg(long, default_value = "auto", value_name = "S|auto")]
    pub smooth: String,
    /// Largest σ tried by --smooth auto [s].
    #[arg(long, default_value_t = 0.02, value_name = "S")]
    pub max_smoothing: f64,
    /// Command velocity limit [m/s] (inf: none).
    #[arg(long, default_value_t = 1.0, value_name = "M_PER_S")]
    pub max_velocity: f64,
    /// Command acceleration limit [m/s²] (inf: none).
    #[arg(long, default_value_t = 30.0, value_name = "M_PER_S2")]
    pub max_acceleration: f64,
    /// Keep the model's DC gain instead of rescaling it to 1 (a position loop has 1).
    #[arg(long)]
    pub keep_dc_gain: bool,
    /// The axis before the first desired sample: rest (at the first value) or moving (a segment cut from a longer program, at the first sample's velocity).
    #[arg(long, default_value = "rest", value_name = "rest|moving")]
    pub start: String,
    /// Send the plain command when the model expects the rms error to fall less than this many times.
    #[arg(long, default_value_t = 1.25, value_name = "X")]
    pub min_benefit: f64,
    /// Send the plain command when the model's free-run position fit is below this [%].
    #[arg(long, default_value_t = 90.0, value_name = "PCT")]
    pub min_fit: f64,
    /// Always send the compensated command (no fall-back to the plain one).
    #[arg(long)]
    pub no_fallback: bool,
    /// A recording of the axis (time_s,command_m,position_m; e.g. the identification run) on which the model's fits are measured for the fall-back [default: the model file's fit]. Given twice, two complete runs of the same program: the noise is taken out by their cross-products.
    #[arg(long, value_name = "rec.csv", requires = "model", action = clap::ArgAction::Append)]
    pub check: Vec<PathBuf>,
    /// The encoder's resolution [m] (its data sheet): with two --check runs whose positions lie on no grid (noise after the count), the rounding both runs share is not counted as the model's error.
    #[arg(long, value_name = "M", requires = "check")]
    pub encoder_resolution: Option<f64>,
    /// Use an unstable physical model anyway (its simulation diverges; refused by default).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Run the compensated and the plain command through the nonlinear virtual rig and report both tracking errors.
    #[arg(long)]
    pub verify: bool,
    /// Rig parameters of the virtual rig for --verify [default: the built-in rig].
    #[arg(long, value_name = "rig.toml", requires = "verify")]
    pub rig: Option<PathBuf>,
    /// Effects of the virtual rig for --verify (TOML) [default: all on, with noise].
    #[arg(long, value_name = "effects.toml", requires = "verify")]
    pub effects: Option<PathBuf>,
    /// Noise seed of the virtual rig for --verify.
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub seed: u64,
    /// Verification CSV: time_s,desired_m,position_uncompensated_m,position_compensated_m.
    #[arg(long, value_name = "verify.csv", requires = "verify")]
    pub verify_out: Option<PathBuf>,
    /// Summary JSON.
    #[arg(long, value_name = "comp.json")]
    pub summary: Option<PathBuf>,
    /// Learn from a measured run of the program (time_s,command_m,position_m on the desired trajectory's samples): the output is the next run's command (iterative learning control with the model, see docs/GUIDE.md).
    #[arg(
        long,
        value_name = "run.csv",
        requires = "model",
        conflicts_with = "check"
    )]
    pub measured: Option<PathBuf>,
    /// The command sent in the measured run (a CSV with time_s and command_m, e.g. the last `compensate -o`) [default: the run's own command_m column].
    #[arg(long, value_name = "cmd.csv", requires = "measured")]
    pub sent: Option<PathBuf>,
    /// Learning history (JSON, read if it exists and rewritten): numbers the runs, checks that the error shrinks and keeps the best run to return to.
    #[arg(long, value_name = "history.json", requires = "measured")]
    pub history: Option<PathBuf>,
    /// Learning gain of a step (0 < g < 2; 1: the model's full correction).
    #[arg(long, default_value_t = 1.0, value_name = "G", requires = "measured")]
    pub learning_gain: f64,
    /// σ of the zero-phase filter of the measured error [s], or auto (as much as the run's own noise allows).
    #[arg(
        long,
        default_value = "auto",
        value_name = "S|auto",
        requires = "measured"
    )]
    pub noise_filter: String,
}

/// `--runaway`: a factor ≥ 1, or `off`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Runaway(pub Option<f64>);

impl std::str::FromStr for Runaway {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("off") {
            return Ok(Runaway(None));
        }
        match s.parse::<f64>() {
            Ok(k) if k.is_finite() && k >= 1.0 => Ok(Runaway(Some(k))),
            _ => Err(format!(
                "{s:?}: expected a factor ≥ 1 (the default is 1.5) or `off`"
            )),
        }
    }
}
