//! Reading recordings from CSV/text and MATLAB v5 files, and writing results.

mod output;

pub use output::{
    cell, write_atomic, write_coefficients_csv, write_predictions_csv, write_string_atomic,
};
