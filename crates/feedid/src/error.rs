//! The one error type of the library.
//!
//! Every fallible library function returns [`Result`]. Variants carry the data
//! a user needs to find the problem (file, column or variable, line or index,
//! offending value); the `Display` text is a single line.

use std::path::PathBuf;

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in feedid.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    // ---------------------------------------------------------------- shapes
    /// Two sequences that must have the same length do not.
    #[error("length mismatch in {what}: expected {expected}, got {actual}")]
    LengthMismatch {
        /// What was being compared (e.g. `"command"`).
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        actual: usize,
    },

    /// A recording's sample time differs from a discrete model's.
    #[error("sample time {actual} s differs from the model's {model} s")]
    SampleTimeMismatch {
        /// The model's sample time \[s\].
        model: f64,
        /// The recording's mean sample interval \[s\].
        actual: f64,
    },

    /// Not enough samples for the requested operation.
    #[error("too few samples for {what}: need at least {needed}, got {actual}")]
    TooFewSamples {
        /// What needs the samples (e.g. `"window + horizon"`).
        what: &'static str,
        /// Minimum number of samples.
        needed: usize,
        /// Number available.
        actual: usize,
    },

    // ------------------------------------------------------------ parameters
    /// A numeric parameter or option is outside its valid range.
    #[error("invalid value for `{name}`: {} ({reason})", short_number(*value))]
    InvalidParameter {
        /// Parameter name as the user writes it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Why it is invalid (e.g. `"must be > 0"`).
        reason: &'static str,
    },

    /// An option that is not a number is invalid (e.g. an unknown method name).
    #[error("invalid {what} `{value}`; expected one of: {expected}")]
    InvalidChoice {
        /// What was chosen (e.g. `"method"`).
        what: &'static str,
        /// The offending choice.
        value: String,
        /// The accepted values, comma separated.
        expected: &'static str,
    },

    /// A setting was given for a method that has no such setting (it is
    /// refused, never silently ignored).
    #[error("{setting}: not applicable to the {method} method (only to {applies_to})")]
    NotApplicable {
        /// The setting, e.g. `"ARX orders (na,nb,nk)"`.
        setting: &'static str,
        /// The method it was given for.
        method: &'static str,
        /// The methods that take it, comma separated.
        applies_to: &'static str,
    },

    /// A method option was given for a method that does not have it (it is
    /// refused, never silently ignored).
    #[error("option `{key}` does not apply to method {method} (only to {applies_to})")]
    OptionNotApplicable {
        /// The option's key (`"lambda"`).
        key: &'static str,
        /// The method it was given for.
        method: &'static str,
        /// The methods that have it (`"rls"`).
        applies_to: String,
    },

    /// A method option's value does not parse or lies outside its range.
    #[error("invalid {key} `{value}`: {expected}")]
    InvalidOption {
        /// The option's key (`"lambda"`).
        key: &'static str,
        /// The value as given.
        value: String,
        /// What is accepted (`"expected a number in (0, 1]"`).
        expected: String,
    },

    /// No method has an option of this key.
    #[error("unknown method option `{key}`; the options are: {known}")]
    UnknownOption {
        /// The key given.
        key: String,
        /// The keys of all method options, comma separated.
        known: String,
    },

    /// A rig parameter file could not be parsed (unknown key, wrong type, ...).
    #[error("{}: {message}", display_path(path))]
    ParamsFile {
        /// File the parameters came from, if any.
        path: Option<PathBuf>,
        /// Parser message (names the key and line).
        message: String,
    },

    // ------------------------------------------------------------- recordings
    /// A value is NaN or infinite.
    #[error("non-finite value {value} in {channel} at sample {index}")]
    NonFinite {
        /// Channel name (column or variable).
        channel: String,
        /// Zero-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },

    /// Time stamps are not strictly increasing.
    #[error(
        "time is not strictly increasing at sample {index}: {previous} s followed by {value} s"
    )]
    NonMonotoneTime {
        /// Zero-based index of the offending sample.
        index: usize,
        /// Time of the previous sample \[s\].
        previous: f64,
        /// Time of the offending sample \[s\].
        value: f64,
    },

    /// Sampling interval deviates from the nominal one by more than the tolerance.
    #[error("sampling jitter at sample {index}: interval {interval} s vs nominal {nominal} s ({relative_percent:.3} % > tolerance {tolerance_percent} %){}", missing_note(*.missing))]
    SamplingJitter {
        /// Zero-based index of the sample ending the offending interval.
        index: usize,
        /// The interval \[s\].
        interval: f64,
        /// The nominal (median) interval \[s\].
        nominal: f64,
        /// Deviation relative to the nominal interval \[%\].
        relative_percent: f64,
        /// Allowed deviation \[%\].
        tolerance_percent: f64,
        /// Whole samples that look missing there (the interval is close to
        /// `missing + 1` nominal intervals; 0 otherwise).
        missing: usize,
    },

    /// With gaps allowed: more intervals look like dropped samples than a
    /// data acquisition drops ([`crate::recording::MAX_GAP_SHARE`]) — the
    /// sampling is irregular or changes its rate.
    #[error(
        "{gaps} of the {intervals} sampling intervals span a whole number of intervals, the \
         first at sample {index} (more than {max_percent} % of them): not a few dropped \
         samples but irregular sampling or a change of the rate — resample the recording or \
         cut it where the rate changes"
    )]
    TooManyGaps {
        /// Zero-based index of the sample after the first such interval.
        index: usize,
        /// Intervals that look like dropped samples.
        gaps: usize,
        /// All intervals.
        intervals: usize,
        /// The largest share accepted \[%\].
        max_percent: f64,
    },

    // ------------------------------------------------------------------- I/O
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },

    /// A requested column or variable does not exist.
    #[error("{}: no {kind} `{name}`; available: {available}", path.display())]
    MissingChannel {
        /// The file.
        path: PathBuf,
        /// `"column"` or `"variable"`.
        kind: &'static str,
        /// The requested name or index.
        name: String,
        /// What the file has, comma separated.
        available: String,
    },

    /// A cell could not be parsed as a number.
    #[error("{}: line {line}, column `{column}`: cannot read `{text}` as a number{hint}", path.display())]
    BadNumber {
        /// The file.
        path: PathBuf,
        /// One-based line number.
        line: usize,
        /// Column name or index.
        column: String,
        /// The cell text.
        text: String,
        /// Extra hint (e.g. about decimal commas), possibly empty.
        hint: &'static str,
    },

    /// A text file is malformed (ragged rows, invalid UTF-8, empty, ...).
    #[error("{}: line {line}: {reason}", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// One-based line number (0 when the whole file is concerned).
        line: usize,
        /// What is wrong.
        reason: String,
    },

    /// A MATLAB file is malformed or uses an unsupported feature.
    #[error("{}: {reason}", path.display())]
    MatFile {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },

    // -------------------------------------------------------------- numerics
    /// A linear system or least-squares problem is singular / rank deficient.
    #[error("singular problem in {context}")]
    Singular {
        /// Where it happened.
        context: &'static str,
    },

    /// A model is unusable (unstable, non-finite, wrong structure).
    #[error("invalid model: {reason}")]
    InvalidModel {
        /// Why.
        reason: &'static str,
    },

    /// A physical model has poles with a non-negative real part.
    #[error("the physical model is unstable: poles with a positive real part at {poles}; its simulation diverges (check the gains and the mechanics)")]
    UnstableModel {
        /// The unstable poles, e.g. `1.3913e3 ± 3.9766e3j rad/s (6.7051e2 Hz)`.
        poles: String,
    },

    /// The neural network's training or evaluation failed in its tensor
    /// library (candle).
    #[error("the neural network's {stage} failed: {message}")]
    Network {
        /// `"training"`.
        stage: &'static str,
        /// The library's message.
        message: String,
    },

    /// An iterative algorithm did not converge.
    #[error("{algorithm} did not converge after {iterations} iterations")]
    NotConverged {
        /// Algorithm name.
        algorithm: &'static str,
        /// Iterations performed.
        iterations: usize,
    },

    // --- io
    /// An error found in a recording file, with the place it was found: the
    /// wrapped error (e.g. [`Error::NonFinite`], [`Error::NonMonotoneTime`])
    /// prefixed by the file and the line / column or variable.
    #[error("{}", display_in_file(path, location, source))]
    InFile {
        /// The file.
        path: PathBuf,
        /// Where in the file, e.g. ``"line 7, column `position_m`"``; may be empty.
        location: String,
        /// The underlying error.
        #[source]
        source: Box<Error>,
    },

    // --- pipeline
    /// A stage of a run failed; the wrapped error says why (e.g.
    /// `order selection: too few samples for …`).
    #[error("{stage}: {source}")]
    Stage {
        /// The stage, e.g. `"order selection"`, `"global model"`.
        stage: &'static str,
        /// Why it failed.
        #[source]
        source: Box<Error>,
    },

    // --- greybox
    /// A chosen set of physical parameters cannot be estimated separately
    /// from the data (a null direction of the Jacobian).
    #[error("not identifiable from these data: {parameters} (the response does not change along {direction}); fix some of them at their nominal values or record a richer excitation")]
    NotIdentifiable {
        /// The parameters of the null directions, comma separated.
        parameters: String,
        /// One null direction, e.g. `Kp·λ^1.00, Kt·λ^-1.00`.
        direction: String,
    },

    // --- compensate
    /// No smoothing allowed brings the compensated command within a limit,
    /// and the plain trajectory exceeds it too.
    #[error("{}", self.message(Syntax::Library))]
    LimitUnreachable {
        /// `"velocity"` or `"acceleration"`.
        quantity: &'static str,
        /// The smallest peak the compensated command reached (magnitude).
        achievable: f64,
        /// Time of that peak \[s\].
        time: f64,
        /// The limit.
        limit: f64,
        /// The plain trajectory's own peak.
        plain: f64,
        /// Unit of the values.
        unit: &'static str,
        /// Largest σ tried \[ms\].
        smoothing_ms: f64,
    },

    /// A learning history is not of the program being learned (or not a
    /// history of this version).
    #[error("the learning history is of another program: its {what} is {}, this one's {}; start a new history for a new program", short_number(*history), short_number(*actual))]
    HistoryMismatch {
        /// What differs, e.g. `"number of samples"`.
        what: &'static str,
        /// The history's value.
        history: f64,
        /// This program's value.
        actual: f64,
    },

    /// Two runs that should be of the same program have different commands.
    #[error("the two check runs are not of the same program: their commands differ at sample {sample} ({} m against {} m); two runs of one program are needed", short_number(*first), short_number(*second))]
    DifferentPrograms {
        /// First sample where they differ.
        sample: usize,
        /// The first run's command there \[m\].
        first: f64,
        /// The second run's \[m\].
        second: f64,
    },

    /// One of two check runs has dropped samples: the cross-products of two
    /// runs need both complete.
    #[error("check run {run} has {dropped} dropped samples: two check runs must both be complete recordings of the program (a run with gaps can be the only check)")]
    GapsInCheckRun {
        /// Which run (1 or 2).
        run: usize,
        /// Samples dropped in it.
        dropped: usize,
    },

    /// A smoothing (σ of the Gaussian) longer than a compensation may use:
    /// its buffers grow with its square.
    #[error("{what} {} s is {samples:.0} samples at this rate, more than the {max_samples} samples ({} s) a compensation smooths over", short_number(*seconds), short_number(*max_seconds))]
    SmoothingTooLong {
        /// `"smoothing"` or `"max smoothing"`.
        what: &'static str,
        /// The σ asked for \[s\].
        seconds: f64,
        /// The σ in samples.
        samples: f64,
        /// The most samples allowed.
        max_samples: usize,
        /// The most allowed at this rate \[s\].
        max_seconds: f64,
    },

    /// The plain command, sent instead of a compensated one, violates a
    /// velocity or acceleration limit: the desired trajectory itself does.
    #[error("the plain command, sent because {because}, has a peak {quantity} of {value:.4} {unit} at t = {time:.4} s, beyond the limit {} {unit}: the desired trajectory itself exceeds it; slow the trajectory down or raise the limit", short_number(*limit))]
    PlainOverLimit {
        /// `"velocity"` or `"acceleration"`.
        quantity: &'static str,
        /// The peak value (magnitude).
        value: f64,
        /// The limit.
        limit: f64,
        /// Unit of value and limit.
        unit: &'static str,
        /// Time of the peak \[s\].
        time: f64,
        /// Why the plain command is sent (`"the model's fit is below the minimum"`).
        because: &'static str,
    },

    /// A computed command violates a velocity or acceleration limit.
    #[error("{}", self.message(Syntax::Library))]
    LimitExceeded {
        /// `"velocity"` or `"acceleration"`.
        quantity: &'static str,
        /// The peak value (magnitude).
        value: f64,
        /// The limit.
        limit: f64,
        /// Unit of value and limit.
        unit: &'static str,
        /// Time of the peak \[s\].
        time: f64,
        /// The settings that would allow the command (`smooth = auto`, `max_smoothing`).
        hints: &'static [Hint],
    },

    // --- harden
    /// A finite value too large in magnitude for the numerics (squares and
    /// sums of squares must stay finite), see [`crate::recording::MAX_MAGNITUDE`].
    #[error("value {value:e} in {channel} at sample {index} is beyond ±{limit:e}; check the unit or scale")]
    OutOfRange {
        /// Channel name (`"time"`, `"command"`, `"position"` or an extra channel).
        channel: String,
        /// Zero-based sample index.
        index: usize,
        /// The offending value.
        value: f64,
        /// The largest magnitude accepted.
        limit: f64,
    },

    /// A stream's window, hop, horizon and look-ahead (the command lead)
    /// together need more samples than a stream may keep.
    #[error("a stream keeps its window, hop, horizon and look-ahead: {window} + {hop} + {horizon} + {lookahead} samples, more than the {max} it may keep; shorten the command lead or the window")]
    StreamBufferTooLarge {
        /// Window \[samples\].
        window: usize,
        /// Hop \[samples\].
        hop: usize,
        /// Horizon \[samples\].
        horizon: usize,
        /// Look-ahead: the command lead or the horizon \[samples\].
        lookahead: usize,
        /// The most these may add up to \[samples\].
        max: usize,
    },

    /// An input larger than it may be: a stream (FIFO, device, pipe) that
    /// delivered more than a recording may hold, or a parameter, effects,
    /// model or history file beyond its bound.
    #[error("{}", input_too_large(path, *limit, *kind))]
    InputTooLarge {
        /// The input.
        path: PathBuf,
        /// The most bytes read \[bytes\].
        limit: u64,
        /// What kind of input it is (the message's advice depends on it).
        kind: InputKind,
    },

    /// The mean sampling interval of the time stamps is too short for a
    /// finite rate and finite derivatives, see [`crate::recording::MIN_INTERVAL`].
    #[error("mean sampling interval {interval:e} s is shorter than {min:e} s (a rate above {max_rate:e} Hz); check the time unit")]
    SamplingInterval {
        /// The mean interval \[s\].
        interval: f64,
        /// The shortest accepted \[s\].
        min: f64,
        /// `1 / min` \[Hz\].
        max_rate: f64,
    },
}

/// The syntax in which a message names a setting: each front end phrases
/// the library's settings as its users type them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Syntax {
    /// Neutral: `unit = mm`.
    Library,
    /// Command line: `--unit mm`.
    Cli,
    /// Python keyword: `unit="mm"` (numbers unquoted: `max_smoothing=0.05`).
    Python,
}

impl Syntax {
    /// The setting `key` = `value` in this syntax.
    ///
    /// ```
    /// use feedid::error::Syntax;
    /// assert_eq!(Syntax::Cli.setting("time_origin", "window"), "--time-origin window");
    /// assert_eq!(Syntax::Python.setting("unit", "mm"), "unit=\"mm\"");
    /// assert_eq!(Syntax::Python.setting("max_smoothing", "0.05"), "max_smoothing=0.05");
    /// assert_eq!(Syntax::Library.setting("unit", "mm"), "unit = mm");
    /// ```
    pub fn setting(self, key: &str, value: &str) -> String {
        match self {
            Syntax::Library => format!("{key} = {value}"),
            Syntax::Cli => format!("--{} {value}", key.replace('_', "-")),
            Syntax::Python => {
                if value.parse::<f64>().is_ok() {
                    format!("{key}={value}")
                } else {
                    format!("{key}={value:?}")
                }
            }
        }
    }
}

/// A setting a message suggests, kept apart from the text so that each
/// front end phrases it in its own syntax ([`Error::message`]): `--unit mm`
/// on the command line, `unit="mm"` in Python, `unit = mm` in the library's
/// own text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Hint {
    /// Set option `key` to `value` (`--smooth auto`).
    SetOption {
        /// The option's key, snake_case (`"smooth"`).
        key: &'static str,
        /// The value (`"auto"`).
        value: &'static str,
    },
    /// Set option `key` to a value known only at run time
    /// (`--estimate Kv,Kvff,Kaff`).
    SetValue {
        /// The option's key, snake_case (`"estimate"`).
        key: &'static str,
        /// The value (`"Kv,Kvff,Kaff"`).
        value: String,
    },
    /// Change option `key` (`--max-smoothing`).
    Option {
        /// The option's key, snake_case (`"max_smoothing"`).
        key: &'static str,
    },
}

impl Hint {
    /// The hint in `syntax`: `--smooth auto` / `smooth="auto"` / `smooth = auto`,
    /// or the option alone: `--max-smoothing` / `max_smoothing`.
    pub fn phrase(&self, syntax: Syntax) -> String {
        match self {
            Hint::SetOption { key, value } => syntax.setting(key, value),
            Hint::SetValue { key, value } => syntax.setting(key, value),
            Hint::Option { key } => match syntax {
                Syntax::Cli => format!("--{}", key.replace('_', "-")),
                Syntax::Library | Syntax::Python => key.to_string(),
            },
        }
    }
}

/// `text` written with `hints` in [`Syntax::Library`] (in the order they
/// appear), rewritten with the hints in `syntax`: scanning from the end, each
/// hint's Library phrase, the last whole-word occurrence before the previous
/// hint's, is replaced by its phrase in `syntax`.
///
/// ```
/// use feedid::error::{phrase_hints, Hint, Syntax};
/// let hints = [Hint::Option { key: "friction" }];
/// assert_eq!(phrase_hints("friction? friction", &hints, Syntax::Cli), "friction? --friction");
/// ```
pub fn phrase_hints(text: &str, hints: &[Hint], syntax: Syntax) -> String {
    let word = |c: char| c.is_alphanumeric() || c == '_' || c == '-';
    let mut out = text.to_string();
    let mut end = out.len();
    for hint in hints.iter().rev() {
        let lib = hint.phrase(Syntax::Library);
        let mut search_end = end;
        while let Some(start) = out[..search_end].rfind(&lib) {
            let stop = start + lib.len();
            let before = out[..start].chars().next_back();
            let after = out[stop..].chars().next();
            if before.is_some_and(word) || after.is_some_and(word) {
                search_end = start;
                continue;
            }
            out.replace_range(start..stop, &hint.phrase(syntax));
            end = start;
            break;
        }
    }
    out
}

/// The hint of [`Error::LimitUnreachable`]: more smoothing.
const MAX_SMOOTHING: Hint = Hint::Option {
    key: "max_smoothing",
};

/// The hints of [`Error::LimitExceeded`]: smoothing.
pub const SMOOTHING_HINTS: &[Hint] = &[
    Hint::SetOption {
        key: "smooth",
        value: "auto",
    },
    MAX_SMOOTHING,
];

/// Hints joined by `, `.
fn phrase_all(hints: &[Hint], syntax: Syntax) -> String {
    hints
        .iter()
        .map(|h| h.phrase(syntax))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Error {
    /// The settings the message suggests (empty for most errors; those of
    /// the wrapped error for [`Error::InFile`] and [`Error::Stage`]).
    pub fn hints(&self) -> Vec<Hint> {
        match self {
            Error::LimitExceeded { hints, .. } => hints.to_vec(),
            Error::LimitUnreachable { .. } => vec![MAX_SMOOTHING],
            Error::InFile { source, .. } | Error::Stage { source, .. } => source.hints(),
            _ => Vec::new(),
        }
    }

    /// The message with its hints in a front end's syntax (`Display` is
    /// [`Syntax::Library`]'s): the CLI names `--max-smoothing`, Python
    /// `max_smoothing`.
    pub fn message(&self, syntax: Syntax) -> String {
        match self {
            Error::LimitUnreachable {
                quantity,
                achievable,
                time,
                limit,
                plain,
                unit,
                smoothing_ms,
            } => format!(
                "the command {quantity} cannot be brought within the limit {limit} {unit}: with \
                 the most smoothing allowed (σ up to {smoothing_ms:.3} ms) the compensated \
                 command still peaks at {achievable:.4} {unit} at t = {time:.4} s, and the \
                 desired trajectory itself at {plain:.4} {unit}; raise the limit or {}, or slow \
                 the trajectory",
                MAX_SMOOTHING.phrase(syntax)
            ),
            Error::LimitExceeded {
                quantity,
                value,
                limit,
                unit,
                time,
                hints,
            } => format!(
                "command {quantity} {value:.4} {unit} at t = {time:.4} s exceeds the limit \
                 {limit} {unit}; allow smoothing ({}) or raise the limit",
                phrase_all(hints, syntax)
            ),
            Error::InFile {
                path,
                location,
                source,
            } => display_in_file_text(path, location, &source.message(syntax)),
            Error::Stage { stage, source } => format!("{stage}: {}", source.message(syntax)),
            other => other.to_string(),
        }
    }

    /// The innermost error: the wrapped one for [`Error::InFile`] and
    /// [`Error::Stage`], else `self`.
    pub fn root(&self) -> &Error {
        match self {
            Error::InFile { source, .. } | Error::Stage { source, .. } => source.root(),
            other => other,
        }
    }
}

fn display_in_file(path: &std::path::Path, location: &str, source: &Error) -> String {
    display_in_file_text(path, location, &source.to_string())
}

/// [`Error::InFile`]'s text around the wrapped error's text.
fn display_in_file_text(path: &std::path::Path, location: &str, source: &str) -> String {
    if location.is_empty() {
        format!("{}: {source}", path.display())
    } else {
        format!("{}: {location}: {source}", path.display())
    }
}

/// A number for a one-line message: plain when short, else in `e` notation
/// (`1e300`, not three hundred digits).
///
/// ```
/// use feedid::error::short_number;
/// assert_eq!(short_number(95.0), "95");
/// assert_eq!(short_number(1e-300), "1e-300");
/// ```
pub fn short_number(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 || (1e-4..1e15).contains(&a) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

fn display_path(path: &Option<PathBuf>) -> String {
    match path {
        Some(p) => p.display().to_string(),
        None => "parameters".to_string(),
    }
}

/// The note of [`Error::SamplingJitter`] on samples that look dropped.
fn missing_note(missing: usize) -> String {
    match missing {
        0 => String::new(),
        m => format!(
            "; the interval spans {} sampling intervals: {m} sample{} missing (dropped by the \
             acquisition?); this needs uniform sampling — cut the recording there; `feedid \
             identify`, `report`, `sweep` and `stream` restart their windows at such a gap, \
             `order` uses the stretch between gaps where the command moves most and `greybox` \
             simulates through it",
            m + 1,
            if m == 1 { " looks" } else { "s look" }
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(short_number(0.0), "0");
        assert_eq!(short_number(2.5), "2.5");
        assert_eq!(short_number(-1e300), "-1e300");
        assert_eq!(short_number(1e-300), "1e-300");
        assert_eq!(short_number(f64::NAN), "NaN");
        let e = Error::InvalidParameter {
            name: "duration",
            value: 1e300,
            reason: "too long",
        };
        assert_eq!(
            e.to_string(),
            "invalid value for `duration`: 1e300 (too long)"
        );
    }

    #[test]
    fn hints_are_phrased_in_each_front_ends_syntax() {
        let e = Error::LimitExceeded {
            quantity: "velocity",
            value: 2.0,
            limit: 1.0,
            unit: "m/s",
            time: 0.5,
            hints: SMOOTHING_HINTS,
        };
        let wrapped = Error::Stage {
            stage: "compensation",
            source: Box::new(e),
        };
        assert!(wrapped
            .to_string()
            .ends_with("allow smoothing (smooth = auto, max_smoothing) or raise the limit"));
        assert!(wrapped
            .message(Syntax::Cli)
            .ends_with("allow smoothing (--smooth auto, --max-smoothing) or raise the limit"));
        assert!(wrapped
            .message(Syntax::Python)
            .ends_with("allow smoothing (smooth=\"auto\", max_smoothing) or raise the limit"));
        assert_eq!(wrapped.hints(), SMOOTHING_HINTS);
        let e = Error::LimitUnreachable {
            quantity: "velocity",
            achievable: 2.0,
            time: 0.5,
            limit: 1.0,
            plain: 1.5,
            unit: "m/s",
            smoothing_ms: 20.0,
        };
        assert!(e.to_string().contains("raise the limit or max_smoothing,"));
        assert!(e
            .message(Syntax::Cli)
            .contains("raise the limit or --max-smoothing,"));
        assert_eq!(e.to_string(), e.message(Syntax::Library));
        // no flag of the command line in the library's own text
        assert!(!e.to_string().contains("--"));
    }
}

/// The kind of an input refused as too large ([`Error::InputTooLarge`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A recording from a pipe, FIFO or device (read whole).
    Stream,
    /// A small text file: rig parameters, effects, a model, a learning history.
    TextFile,
}

fn input_too_large(path: &std::path::Path, limit: u64, kind: InputKind) -> String {
    match kind {
        InputKind::Stream => format!(
            "{}: more than {limit} bytes from a pipe or device; feedid reads a recording whole: \
             save it to a file first, or use `feedid stream` for live data",
            path.display()
        ),
        InputKind::TextFile => format!(
            "{}: larger than {limit} bytes, the most feedid reads from a parameter, effects, \
             model or history file; is it the right file?",
            path.display()
        ),
    }
}
