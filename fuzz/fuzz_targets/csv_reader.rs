//! The text reader on arbitrary bytes: never panics; an accepted recording
//! is finite with strictly increasing time and a finite, positive interval.
//! The same bytes as a live stream (`StreamReader`, what `feedid stream`
//! reads) never panic either, and end.
#![no_main]

use std::path::Path;

use feedid::io::{read_csv_from_bytes, ChannelRef, ReadOptions, StreamLine, StreamReader};
use feedid::Recording;
use libfuzzer_sys::fuzz_target;

fn check(rec: &Recording) {
    assert!(rec.len() >= 2);
    assert!(rec.dt().is_finite() && rec.dt() > 0.0, "dt {}", rec.dt());
    assert!(rec.rate_hz().is_finite() && rec.rate_hz() > 0.0);
    assert!(rec.time().windows(2).all(|w| w[1] > w[0]));
    for s in [rec.time(), rec.command(), rec.position()] {
        assert!(s.iter().all(|v| v.is_finite()));
    }
    for (_, v) in rec.extra() {
        assert!(v.iter().all(|v| v.is_finite()));
    }
}

fuzz_target!(|data: &[u8]| {
    // The first byte picks the options, the rest is the file.
    let Some((&sel, body)) = data.split_first() else {
        return;
    };
    let mut opts = ReadOptions {
        delimiter: match sel & 7 {
            1 => Some(b','),
            2 => Some(b';'),
            3 => Some(b'\t'),
            4 => Some(b' '),
            _ => None,
        },
        header: match (sel >> 3) & 3 {
            1 => Some(true),
            2 => Some(false),
            _ => None,
        },
        ..ReadOptions::default()
    };
    if sel & 0x20 != 0 {
        opts.time = Some(ChannelRef::Index(1));
        opts.command = Some(ChannelRef::Index(2));
        opts.position = Some(ChannelRef::Index(3));
    }
    if sel & 0x40 != 0 {
        opts.time = None;
        opts.rate_hz = Some(1000.0);
        opts.command = Some(ChannelRef::Index(1));
        opts.position = Some(ChannelRef::Index(2));
    }
    if sel & 0x80 != 0 {
        opts.jitter_tolerance = 1e9;
    }
    if let Ok(rec) = read_csv_from_bytes(body, Path::new("fuzz.csv"), &opts) {
        check(&rec);
        let _ = feedid::io::recording_info(&rec);
    }
    if let Ok(mut r) = StreamReader::new(body, Path::new("stdin"), &opts) {
        // every call consumes at least one line: at most one event per byte, then the end
        let mut events = 0usize;
        while let Ok(Some(l)) = r.next_line() {
            events += 1;
            assert!(events <= body.len() + 1, "the stream reader does not end");
            if let StreamLine::Sample { time, .. } = l {
                assert!(!time.is_nan() || opts.rate_hz.is_none());
            }
        }
    }
});
