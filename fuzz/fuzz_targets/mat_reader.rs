//! The MAT-file reader on arbitrary bytes: never panics, never allocates
//! beyond what the bytes can hold; an accepted recording is finite with
//! strictly increasing time.
#![no_main]

use std::path::Path;

use feedid::io::{list_mat_variables_from_bytes, read_mat_from_bytes, ChannelRef, ReadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.mat");
    let _ = list_mat_variables_from_bytes(data, path);
    for (time, rate) in [(Some("t"), None), (None, Some(5000.0))] {
        let opts = ReadOptions {
            time: time.map(|t| ChannelRef::Name(t.into())),
            command: Some(ChannelRef::Name("qg".into())),
            position: Some(ChannelRef::Name("qm".into())),
            rate_hz: rate,
            jitter_tolerance: 1e9,
            ..ReadOptions::default()
        };
        if let Ok(rec) = read_mat_from_bytes(data, path, &opts) {
            assert!(rec.dt().is_finite() && rec.dt() > 0.0, "dt {}", rec.dt());
            assert!(rec.time().windows(2).all(|w| w[1] > w[0]));
            for s in [rec.time(), rec.command(), rec.position()] {
                assert!(s.iter().all(|v| v.is_finite()));
            }
            let _ = feedid::io::recording_info(&rec);
        }
    }
});
