//! Shared helpers of the library's integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use feedid::io::{read_recording, ChannelRef, ReadOptions};
use feedid::Recording;

/// The EMPS file (`FEEDID_EMPS_MAT` overrides the workplace location, e.g.
/// from a git worktree); `None`, after saying so, when it is absent.
pub fn emps_path() -> Option<PathBuf> {
    let path = std::env::var_os("FEEDID_EMPS_MAT").map_or_else(
        || {
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../../shared/data/emps/DATA_EMPS.mat")
        },
        PathBuf::from,
    );
    if path.exists() {
        Some(path)
    } else {
        eprintln!(
            "skipped: EMPS data not found at {} (set FEEDID_EMPS_MAT)",
            path.display()
        );
        None
    }
}

/// The EMPS recording, `qg` → `qm` over `t` (`None` when the file is absent).
pub fn emps_recording() -> Option<Recording> {
    let path = emps_path()?;
    Some(
        read_recording(
            &path,
            &ReadOptions {
                time: Some(ChannelRef::Name("t".into())),
                command: Some(ChannelRef::Name("qg".into())),
                position: Some(ChannelRef::Name("qm".into())),
                ..Default::default()
            },
        )
        .unwrap(),
    )
}
