//! Reading recordings from CSV/text and MATLAB v5 files ([`read_recording`]
//! dispatches), the options that pick columns and units ([`ReadOptions`]), a
//! live text stream read line by line with the same options
//! ([`StreamReader`]), and writing results without destroying anything or
//! leaving partial files ([`OutputSet`], [`write_atomic`]), and the CSV
//! tables of results.

mod columns;
mod csv;
mod layout;
mod mat;
mod options;
mod output;
mod read;
mod source;
mod stream;
mod table;
mod text;

pub use self::csv::{read_csv, read_csv_from_bytes, read_csv_from_str};
pub use self::mat::{
    list_mat_variables, list_mat_variables_from_bytes, read_mat, read_mat_from_bytes,
    MatVariableInfo,
};
pub use self::options::{
    ChannelRef, ReadOptions, TimeUnit, Unit, DEFAULT_COMMAND_COLUMN, DEFAULT_POSITION_COLUMN,
    DEFAULT_TIME_COLUMN,
};
pub use self::output::{
    abandon_pending_outputs, destination, pending_output_count, write_atomic, write_string_atomic,
    Destination, OutputSet,
};
pub use self::read::{
    read_recording, read_recording_from_bytes, read_recording_with_progress, ReadProgress,
    READ_PROGRESS_BYTES,
};
pub use self::source::{
    read_small_text, read_text_up_to, MAX_LINE_BYTES, MAX_SMALL_FILE_BYTES, MAX_STREAM_BYTES,
};
pub use self::stream::{
    CommandRows, PredictionRows, StreamLine, StreamReader, COMMAND_COLUMNS, MAX_STREAM_LINE,
    PREDICTION_COLUMNS,
};
// the summary of a recording moved to `recording`; its old path stays
pub use self::table::{
    cell, write_coefficients_csv, write_predictions_csv, CoefficientRow, PredictionColumns,
};
pub use self::text::DECIMAL_COMMA_HINT;
pub use crate::recording::{recording_info, recording_info_in, ChannelStats, RecordingInfo};
