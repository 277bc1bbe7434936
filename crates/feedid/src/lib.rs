//! # feedid
//!
//! Short-time identification and prediction of machine-tool feed drives: the
//! physical model of a ball-screw axis under P / PI / PI cascade control
//! ([`drive`]), linear-system tools ([`lti`]), a nonlinear virtual rig and
//! test commands ([`drive`], [`signal`]), the windowed identification methods
//! and the sliding prediction engine ([`ident`]), one identification run end
//! to end ([`pipeline`]), solvers ([`solve`]) and file input ([`io`]);
//! physical parameters from data ([`greybox`]) and model-based compensation
//! of the command ([`compensate`]); the drive zoo, a generated family of
//! recordings to benchmark on ([`zoo`]).
//!
//! Figures and HTML reports are in the separate crate `feedid-report`, so
//! this numerical core builds without a plotting library.
//!
//! Reference: M.G.A. Nassef, L. Li, C. Schenck, B. Kuhfuss, "Short Time
//! Identification of Feed Drive Systems using Nonlinear Least Squares Method".
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]
#![warn(missing_docs)]

pub mod compensate;
pub mod drive;
pub mod error;
pub mod experiment;
pub mod greybox;
pub mod ident;
pub mod io;
pub mod lti;
pub mod pipeline;
pub mod recording;
pub mod signal;
pub mod solve;
pub mod stats;
pub mod zoo;

pub use error::{Error, Result};
pub use pipeline::Pipeline;
pub use recording::plausibility;
pub use recording::{Recording, RecordingRef};
