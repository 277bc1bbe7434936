//! A recording and what is known of it before identifying: the checked
//! recording (time, command, measured position; gaps, motion segments), the
//! plausibility checks of a well-formed recording that would mislead, and
//! the summary a user checks (`feedid info`).

mod checked;
mod info;
pub mod plausibility;

pub use checked::{
    is_usable, segments, Gap, MotionSegment, Recording, RecordingRef, DEFAULT_JITTER_TOLERANCE,
    MAX_GAPS_ANY_LENGTH, MAX_GAP_SHARE, MAX_MAGNITUDE, MIN_INTERVAL, MOTION_THRESHOLD,
};
pub use info::{
    recording_info, recording_info_in, ChannelStats, RecordingInfo, SEGMENT_MIN_STANDSTILL_S,
    SEGMENT_STEP_RELATIVE,
};
