//! `feedid zoo` and the rig extensions as `feedid simulate` reads them.

mod common;

use common::{assert_fails, csv_column as column, feedid, stderr, stdout};

#[test]
fn zoo_list_prints_one_row_per_member_and_the_ranges() {
    let o = feedid(&["zoo", "--list", "--members", "small"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    let rows = s
        .lines()
        .filter(|l| {
            l.trim_start()
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_digit())
        })
        .filter(|l| !l.contains("members span"))
        .count();
    assert_eq!(rows, 20, "{s}");
    assert!(s.contains("20 members span:"), "{s}");
    assert!(s.contains("rig-heavy") && s.contains("second-order"), "{s}");
    // the whole zoo
    let o = feedid(&["zoo", "--list"]);
    assert!(stdout(&o).contains("250 members span:"));
    // the disturbed members, one of each kind at least, with their source
    let o = feedid(&["zoo", "--list", "--members", "disturbed"]);
    let s = stdout(&o);
    assert!(s.contains("30 members span:"), "{s}");
    assert!(
        s.contains("force pulses on 10, strong friction on 10, coarse encoder on 10"),
        "{s}"
    );
    assert!(
        s.contains("force pulses") && s.contains("encoder") && s.contains(" of #"),
        "{s}"
    );
}

#[test]
fn zoo_members_are_files_identify_reads_with_no_options() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zoo");
    let o = feedid(&["zoo", "--out", out.to_str().unwrap(), "--members", "0..=2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for i in 0..3 {
        let f = out.join(format!("zoo-{i:03}.csv"));
        let p = dir.path().join(format!("p{i}.csv"));
        let o = feedid(&["identify", f.to_str().unwrap(), "-o", p.to_str().unwrap()]);
        assert!(o.status.success(), "member {i}: {}", stderr(&o));
    }
    // the CSV holds the library's member bit for bit
    let m = feedid::zoo::Zoo::standard().member(1).unwrap();
    let f = out.join("zoo-001.csv");
    assert_eq!(column(&f, "position_m"), m.position);
    assert_eq!(column(&f, "true_position_m"), m.truth);
    assert_eq!(column(&f, "time_s"), m.time);
    // the manifests describe the written members
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    let a = v.as_array().unwrap();
    assert_eq!(a.len(), 3);
    assert_eq!(a[1]["file"], "zoo-001.csv");
    assert_eq!(a[1]["readable"], true);
    assert_eq!(a[1]["samples"].as_u64().unwrap() as usize, m.len());
    let csv = std::fs::read_to_string(out.join("manifest.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4);
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .starts_with("index,file,readable,plant"));
}

#[test]
fn a_member_with_dropped_rows_is_identified_segment_by_segment() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gaps");
    let o = feedid(&["zoo", "--out", out.to_str().unwrap(), "--members", "215"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(v[0]["readable"], false);
    let dropped = v[0]["dropped_rows"].as_array().unwrap().len();
    assert!(dropped > 0);
    let f = out.join("zoo-215.csv");
    let (p, s) = (dir.path().join("p.csv"), dir.path().join("s.json"));
    let o = feedid(&[
        "identify",
        f.to_str().unwrap(),
        "-o",
        p.to_str().unwrap(),
        "--summary",
        s.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // the warning names the gaps and what they cost
    let err = stderr(&o);
    assert!(
        err.contains("missing in 2 gaps") && err.contains("restarted"),
        "{err}"
    );
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&s).unwrap()).unwrap();
    assert_eq!(j["gaps"].as_u64(), Some(2));
    assert_eq!(j["missing_samples"].as_u64(), Some(dropped as u64));
    let samples = j["samples"].as_u64().unwrap() as usize;
    // one row per measured sample; none predicted across a gap's first window
    let rows = std::fs::read_to_string(&p).unwrap().lines().count() - 1;
    assert_eq!(rows, samples);
    assert!(j["coverage_percent"].as_f64().unwrap() > 80.0, "{j}");
    // `info` names the gaps
    let o = feedid(&["info", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("gaps        2"), "{}", stdout(&o));
    // `greybox` simulates through the gaps and compares the measured samples
    let gs = dir.path().join("g.json");
    let o = feedid(&[
        "greybox",
        f.to_str().unwrap(),
        "--estimate",
        "kv",
        "--summary",
        gs.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("2 gap(s) of dropped samples (5 missing)"),
        "{}",
        stdout(&o)
    );
    let g: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&gs).unwrap()).unwrap();
    assert_eq!(g["gaps"].as_u64(), Some(2));
    assert_eq!(g["residuals"].as_u64(), Some(samples as u64));
    // and tracks over windows between the gaps
    let track = dir.path().join("t.csv");
    let o = feedid(&[
        "greybox",
        f.to_str().unwrap(),
        "--estimate",
        "kv",
        "--track-window",
        "0.05",
        "--track-out",
        track.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let windows = std::fs::read_to_string(&track).unwrap().lines().count() - 1;
    assert!(windows > 10, "{windows}");
    // `order` chooses on the stretch between the gaps where the command
    // moves most (member 215 moves before its first gap and then stands)
    // and says which
    let o = feedid(&["order", f.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(j["gaps"].as_u64(), Some(2));
    assert_eq!(j["samples"].as_u64(), Some(samples as u64));
    let used = j["samples_used"].as_u64().unwrap() as usize;
    assert!(used > 0 && used < samples, "{j}");
    let o = feedid(&["order", f.to_str().unwrap()]);
    assert!(
        stdout(&o).contains(
            "orders chosen on the stretch between dropped samples where the command moves most: samples 0..409"
        ),
        "{}",
        stdout(&o)
    );
    // `sweep` restarts every combination after each gap, as `identify`
    let sw = dir.path().join("sw.csv");
    let o = feedid(&[
        "sweep",
        f.to_str().unwrap(),
        "-o",
        sw.to_str().unwrap(),
        "--windows",
        "50,100",
        "--methods",
        "arx",
        "--plot",
        dir.path().join("sw.svg").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read_to_string(dir.path().join("sw.svg"))
        .unwrap()
        .contains("in each segment between dropped samples"));
    assert!(
        stdout(&o).contains("of each of the 3 segments between the 2 gap(s)"),
        "{}",
        stdout(&o)
    );
    // the report identifies it as `identify` does, and says so
    let html = dir.path().join("r.html");
    let o = feedid(&["report", f.to_str().unwrap(), "-o", html.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("5 sample(s) missing in 2 gap(s)"),
        "{}",
        stdout(&o)
    );
    assert!(std::fs::read_to_string(&html)
        .unwrap()
        .contains("dropped samples"));
}

#[test]
fn bad_member_sets_are_refused_with_the_choices() {
    for (set, needle) in [
        ("5..2", "empty"),
        ("0..999", "member 250 does not exist"),
        ("one", "expected all, regular"),
        ("1,x", "expected all, regular"),
    ] {
        let o = feedid(&["zoo", "--list", "--members", set]);
        assert_fails(&o, &[needle]);
    }
    assert_fails(&feedid(&["zoo"]), &["nothing to do"]);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("f");
    std::fs::write(&file, "x").unwrap();
    assert_fails(
        &feedid(&["zoo", "--out", file.to_str().unwrap(), "--members", "0"]),
        &["not a directory"],
    );
}

#[test]
fn simulate_reads_feed_forward_backlash_and_dead_time() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("ff.toml");
    std::fs::write(&params, "[control]\nkvff = 0.9\nkaff = 0.5\n").unwrap();
    let effects = dir.path().join("fx.toml");
    std::fs::write(
        &effects,
        "noise = false\nquantisation = false\nfriction = false\ndead_time = 2\n",
    )
    .unwrap();
    let plain = dir.path().join("plain.csv");
    let ff = dir.path().join("ff.csv");
    let simulate = |fx: &std::path::Path, out: &std::path::Path| {
        let o = feedid(&[
            "simulate",
            "--scenario",
            "ramp",
            "--params",
            params.to_str().unwrap(),
            "--effects",
            fx.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    };
    let o = feedid(&[
        "simulate",
        "--scenario",
        "ramp",
        "--linear",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    simulate(&effects, &ff);
    let cmd = column(&ff, "command_m");
    let x = column(&ff, "true_position_m");
    // steady ramp: (1 − kvff)·v/Kv = 7.14 µm plus two samples of dead time (2·v/rate = 20 µm)
    let k = 2500;
    let e = cmd[k] - x[k];
    let want = 0.1 * 0.05 / 700.0 + 2.0 * 0.05 / 5000.0;
    assert!((e - want).abs() < 1e-8, "following error {e} vs {want}");
    let x0 = column(&plain, "true_position_m");
    assert!(cmd[k] - x0[k] > 70e-6, "without feed-forward: v/Kv");
    // backlash changes the motion by about its width
    std::fs::write(
        &effects,
        "noise = false\nquantisation = false\nfriction = false\ndead_time = 2\nbacklash = true\nbacklash_width = 1e-5\n",
    )
    .unwrap();
    let with = dir.path().join("backlash.csv");
    simulate(&effects, &with);
    let xb = column(&with, "true_position_m");
    let d = x
        .iter()
        .zip(&xb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(d > 1e-6 && d < 1e-4, "{d}");
    // the model of these parameters says the same
    let o = feedid(&["model", "--params", params.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let fe = v["following_error_s"].as_f64().unwrap();
    assert!((fe - 0.1 / 700.0).abs() < 1e-12, "{fe}");
    assert_eq!(v["num"].as_array().unwrap().len(), 5);
    // bad values are refused by name
    std::fs::write(&params, "[control]\nkvff = -1\n").unwrap();
    let o = feedid(&[
        "simulate",
        "--scenario",
        "ramp",
        "--params",
        params.to_str().unwrap(),
        "-o",
        ff.to_str().unwrap(),
    ]);
    assert_fails(&o, &["control.kvff"]);
}
