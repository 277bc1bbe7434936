//! Reports people can read: one self-contained HTML file per recording (or
//! for the paper's experiments) with inline SVG figures, a table of
//! contents, captions saying what to look at, and the summary numbers.

mod html;
mod paper;
mod recording;

pub use html::{escape_html, Block, Figure, HtmlReport, Section, Table};
pub use paper::paper_report;
pub use recording::{
    method_label, recording_report, GlobalModel, MethodRun, RecordingAnalysis, ReportOptions,
    GLOBAL_FIT_MAX_SAMPLES,
};
