//! # feedid-report
//!
//! Figures and reports people can read, built on the numerical core
//! [`feedid`]: SVG charts and heat maps ([`plot`], plotters), one
//! self-contained HTML file per recording ([`recording_report`]) or for the
//! paper's experiments ([`paper_report`]) with inline figures, a table of
//! contents, captions saying what to look at, and the summary numbers; the
//! figures of the paper's experiments ([`experiment`]) and the heat map of a
//! window sweep ([`sweep_heat_map`]).
//!
//! The numerical core builds without this crate (and without plotters).
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]
#![warn(missing_docs)]

mod error;
pub mod experiment;
mod html;
mod paper;
pub mod plot;
mod recording;
mod sweep;

pub use error::{Error, Result};
pub use html::{escape_html, Block, Figure, HtmlReport, Section, Table};
pub use paper::paper_report;
pub use recording::{recording_report, GlobalModel, MethodRun, RecordingAnalysis, ReportOptions};
pub use sweep::sweep_heat_map;
