//! The drive zoo: determinism, stability, coverage of the ranges the zoo
//! asks for, defects.

use std::collections::BTreeSet;

use feedid::zoo::{AxisClass, MemberSpec, PlantKind, Zoo, MAX_ROWS};

fn all_specs(zoo: &Zoo) -> Vec<MemberSpec> {
    let idx: Vec<usize> = (0..zoo.len()).collect();
    zoo.specs(&idx).into_iter().map(|s| s.unwrap()).collect()
}

fn min_max<I: Iterator<Item = f64>>(it: I) -> (f64, f64) {
    it.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

#[test]
fn the_same_seed_gives_the_same_bits_alone_or_in_parallel() {
    let zoo = Zoo::standard();
    let idx: Vec<usize> = zoo.small().chain([57, 133, 209, 215]).collect();
    let parallel = zoo.members(&idx);
    for (&i, p) in idx.iter().zip(&parallel) {
        let alone = zoo.member(i).unwrap();
        let p = p.as_ref().unwrap();
        assert_eq!(&alone, p, "member {i}");
        // bit for bit, including signed zeros
        for (a, b) in alone.position.iter().zip(&p.position) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        assert_eq!(zoo.spec(i).unwrap(), alone.spec);
    }
    // another seed is another zoo
    let other = Zoo::new(14, 20, 0, 0).unwrap();
    assert_ne!(
        other.member(0).unwrap().position,
        parallel[0].as_ref().unwrap().position
    );
    // the standard zoo through `new` is the same zoo
    assert_eq!(
        Zoo::new(13, 210, 10, 30).unwrap().member(5).unwrap(),
        zoo.member(5).unwrap()
    );
}

#[test]
fn every_member_is_stable_finite_and_within_its_caps() {
    let zoo = Zoo::standard();
    assert!(
        zoo.regular().len() >= 200,
        "the zoo: at least 200 recordings"
    );
    let idx: Vec<usize> = (0..zoo.len()).collect();
    for (i, m) in zoo.members(&idx).into_iter().enumerate() {
        let m = m.unwrap_or_else(|e| panic!("member {i}: {e}"));
        let s = &m.spec;
        assert_eq!(s.index, i);
        let st = s.stability;
        assert!(st.max_real_part < 0.0, "member {i}: {st:?}");
        assert!(st.spectral_radius < 1.0, "member {i}: {st:?}");
        assert!(st.min_damping > 0.0, "member {i}: {st:?}");
        assert_eq!(m.len(), s.samples);
        assert!(
            m.len() <= MAX_ROWS && m.len() >= 900,
            "member {i}: {}",
            m.len()
        );
        assert_eq!(m.command.len(), m.len());
        assert_eq!(m.truth.len(), m.len());
        for v in [&m.time, &m.command, &m.position, &m.truth] {
            assert!(v.iter().all(|x| x.is_finite()), "member {i}");
        }
        assert!(m.time.windows(2).all(|w| w[1] > w[0]));
        // the axis follows its command: no run-away
        let peak = m.truth.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(
            peak <= 3.0 * s.amplitude_m + 1e-4,
            "member {i}: peak {peak} amplitude {}",
            s.amplitude_m
        );
        assert!(
            (m.command.iter().fold(0.0f64, |a, v| a.max(v.abs())) - s.amplitude_m).abs() <= 1e-12
                || s.has_gaps()
        );
        if s.has_gaps() {
            assert!(
                m.recording().is_err(),
                "member {i}: the reader refuses gaps"
            );
        } else {
            let r = m.recording().unwrap();
            assert!((r.rate_hz() / s.rate_hz - 1.0).abs() < 1e-9);
        }
    }
}

#[test]
fn the_family_spans_the_ranges_its_module_doc_promises() {
    let zoo = Zoo::standard();
    let specs = all_specs(&zoo);
    let (lo, hi) = min_max(specs.iter().map(|s| s.rate_hz));
    assert!(lo <= 101.0 && hi >= 19_900.0, "rate {lo} … {hi}");
    let (lo, hi) = min_max(specs.iter().map(|s| s.kv));
    assert!(lo <= 10.5 && hi >= 2_900.0, "Kv {lo} … {hi}");
    let (_, rig_hi) = min_max(specs.iter().filter(|s| s.rig.is_some()).map(|s| s.kv));
    assert!(rig_hi >= 700.0, "rig Kv up to {rig_hi}");
    let (lo, hi) = min_max(specs.iter().filter_map(|s| s.mass_kg));
    assert!(lo <= 0.51 && hi >= 490.0, "mass {lo} … {hi}");
    let (lo, hi) = min_max(
        specs
            .iter()
            .filter(|s| s.rig.is_some())
            .map(|s| s.friction_share),
    );
    assert!(lo <= 0.005 && hi >= 0.095, "friction {lo} … {hi}");
    let backlash: Vec<f64> = specs
        .iter()
        .map(|s| s.backlash_m)
        .filter(|&b| b > 0.0)
        .collect();
    let (lo, hi) = min_max(backlash.iter().copied());
    assert!(
        backlash.len() >= 30 && lo <= 2e-6 && hi >= 18e-6,
        "backlash {} {lo} … {hi}",
        backlash.len()
    );
    let placed: Vec<f64> = specs
        .iter()
        .filter(|s| s.resonance_placed)
        .filter_map(|s| s.axial_mode_hz)
        .collect();
    let (lo, hi) = min_max(placed.iter().copied());
    assert!(
        placed.len() >= 20 && lo <= 30.0 && hi >= 250.0,
        "modes {} {lo} … {hi}",
        placed.len()
    );
    let dead: BTreeSet<usize> = specs.iter().map(|s| s.dead_time_samples).collect();
    assert_eq!(dead, BTreeSet::from([0, 1, 2, 3]));
    let (lo, hi) = min_max(specs.iter().map(|s| s.resolution_m));
    assert!(lo <= 1.01e-9 && hi >= 1.99e-5, "resolution {lo} … {hi}");
    assert!(specs.iter().any(|s| s.noise_std_m == 0.0));
    let (_, hi) = min_max(specs.iter().map(|s| s.noise_std_m / s.resolution_m));
    assert!(hi >= 2.5, "noise up to {hi} counts");
    let (lo, hi) = min_max(specs.iter().map(|s| s.amplitude_m));
    assert!(lo <= 1.05e-4 && hi >= 0.95, "amplitude {lo} … {hi}");
    let commands: BTreeSet<&str> = specs.iter().map(|s| s.command.name()).collect();
    assert_eq!(
        commands,
        BTreeSet::from(["contour", "p2p", "ramp", "scurve", "square", "step", "sweep"])
    );
    let plants: BTreeSet<&str> = specs.iter().map(|s| s.plant.name()).collect();
    assert_eq!(plants.len(), 5, "{plants:?}");
    for ff in ["none", "vff", "vff+aff"] {
        let n = specs.iter().filter(|s| s.feed_forward() == ff).count();
        assert!(n >= 50, "{ff}: {n}");
    }
    let (lo, hi) = min_max(specs.iter().filter(|s| s.kvff > 0.0).map(|s| s.kvff));
    assert!(lo <= 0.81 && hi >= 0.99, "kvff {lo} … {hi}");
    let (lo, hi) = min_max(specs.iter().filter(|s| s.kaff > 0.0).map(|s| s.kaff));
    assert!(lo <= 0.52 && hi >= 0.98, "kaff {lo} … {hi}");
    assert!(specs.iter().filter(|s| !s.glitches.is_empty()).count() >= 15);
    assert_eq!(specs.iter().filter(|s| s.has_gaps()).count(), 10);
    // every axis class reaches across its mass range
    for class in [AxisClass::Heavy, AxisClass::Conventional, AxisClass::Stiff] {
        let n = specs
            .iter()
            .filter(|s| s.plant == PlantKind::Rig(class))
            .count();
        assert!(n >= 50, "{class:?}: {n}");
    }
}

#[test]
fn the_small_subset_has_every_kind() {
    let zoo = Zoo::standard();
    let specs: Vec<MemberSpec> = zoo.small().map(|i| zoo.spec(i).unwrap()).collect();
    assert_eq!(specs.len(), 20);
    let commands: BTreeSet<&str> = specs.iter().map(|s| s.command.name()).collect();
    assert_eq!(commands.len(), 7);
    let plants: BTreeSet<&str> = specs.iter().map(|s| s.plant.name()).collect();
    assert_eq!(plants.len(), 5);
    let ff: BTreeSet<&str> = specs.iter().map(|s| s.feed_forward()).collect();
    assert_eq!(ff.len(), 3);
    assert!(specs.iter().any(|s| !s.glitches.is_empty()));
    assert!(specs.iter().all(|s| !s.has_gaps()));
}

#[test]
fn glitches_are_isolated_wild_samples_and_the_truth_is_clean() {
    let zoo = Zoo::standard();
    for i in [5, 17, 29] {
        let m = zoo.member(i).unwrap();
        let s = &m.spec;
        assert!(!s.glitches.is_empty(), "member {i}");
        let floor = 0.5 * s.resolution_m + 6.0 * s.noise_std_m + 1e-15;
        for (k, (&y, &x)) in m.position.iter().zip(&m.truth).enumerate() {
            match s.glitches.iter().find(|g| g.index == k) {
                Some(g) => assert!(
                    ((y - x) - g.offset).abs() <= floor * (1.0 + 1e-9) + 1e-9 * g.offset.abs()
                ),
                None => assert!((y - x).abs() <= floor, "member {i} row {k}: {}", y - x),
            }
        }
    }
}

#[test]
fn gapped_members_are_their_source_without_the_dropped_rows() {
    let zoo = Zoo::standard();
    for i in zoo.gapped() {
        let m = zoo.member(i).unwrap();
        let src = zoo.member(m.spec.gap_source.unwrap()).unwrap();
        let rows = &m.spec.dropped_rows;
        assert!(!rows.is_empty());
        assert_eq!(m.len() + rows.len(), src.len());
        let kept: Vec<usize> = (0..src.len()).filter(|k| !rows.contains(k)).collect();
        for (j, &k) in kept.iter().enumerate() {
            assert_eq!(m.time[j], src.time[k]);
            assert_eq!(m.position[j], src.position[k]);
            assert_eq!(m.command[j], src.command[k]);
            assert_eq!(m.truth[j], src.truth[k]);
        }
        let dt = 1.0 / m.spec.rate_hz;
        let jumps = m.time.windows(2).filter(|w| w[1] - w[0] > 1.5 * dt).count();
        assert!(jumps >= 1);
    }
}

#[test]
fn unknown_members_are_an_error_not_a_panic() {
    let zoo = Zoo::standard();
    assert!(zoo.member(zoo.len()).is_err());
    assert!(zoo.spec(usize::MAX).is_err());
    assert!(Zoo::new(1, 0, 3, 0).is_err());
}

#[test]
fn run_plant_on_the_members_own_command_gives_its_recording() {
    let zoo = Zoo::standard();
    let mut exact = 0;
    for i in zoo.small() {
        let m = zoo.member(i).unwrap();
        let s = &m.spec;
        let run = s.run_plant(&m.command, s.noise_seed).unwrap();
        assert_eq!(run.time, m.time);
        if s.decimation() == 1 {
            // the same loop samples: bit for bit
            exact += 1;
            assert_eq!(run.truth, m.truth, "member {i}");
            for (k, (a, b)) in run.position.iter().zip(&m.position).enumerate() {
                if s.glitches.iter().all(|g| g.index != k) {
                    assert_eq!(a, b, "member {i} row {k}");
                }
            }
        } else {
            // the loop sees the interpolated command instead of the
            // generator's: close, except right after steps
            let scale = s.amplitude_m;
            let d = (run
                .truth
                .iter()
                .zip(&m.truth)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / m.len() as f64)
                .sqrt();
            assert!(d < 0.05 * scale, "member {i}: rms {d} of {scale}");
        }
    }
    assert!(exact >= 5, "{exact}");
    assert!(zoo.spec(0).unwrap().run_plant(&[0.0], 1).is_err());
    assert!(zoo.spec(0).unwrap().run_plant(&[0.0, f64::NAN], 1).is_err());
}

#[test]
fn disturbed_members_are_their_source_with_one_disturbance() {
    use feedid::zoo::Disturbance;
    let zoo = Zoo::standard();
    let idx: Vec<usize> = zoo.disturbed().collect();
    assert_eq!(idx.len(), 30);
    let mut kinds = [0usize; 3];
    for m in zoo.members(&idx) {
        let m = m.unwrap();
        let s = &m.spec;
        let d = s.disturbed.expect("a disturbed member says what it adds");
        let src = zoo.member(d.source).unwrap();
        assert!(zoo.regular().contains(&d.source));
        // every disturbed member is a recording the reader accepts
        assert!(m.recording().is_ok(), "member {}", s.index);
        // the source's command (re-planned at the lower rate of a coarse encoder)
        assert_eq!(s.command.name(), src.spec.command.name());
        if !matches!(d.disturbance, Disturbance::Encoder { .. }) {
            assert_eq!(s.command, src.spec.command, "member {}", s.index);
        }
        match d.disturbance {
            Disturbance::Pulses { pulses, share } => {
                kinds[0] += 1;
                assert!(matches!(s.plant, PlantKind::Rig(_)));
                assert!((0.1..=0.5).contains(&share));
                assert!(pulses.width >= 1e-3 * 0.999 && pulses.width <= 0.05);
                assert_eq!(s.rig.unwrap().effects.pulses, pulses);
                // the same axis and noise: identical until the first pulse,
                // pushed off the source's path after it
                let first = (pulses.first * s.rate_hz).floor() as usize;
                assert_eq!(m.truth[..first], src.truth[..first], "member {}", s.index);
                let moved = m
                    .truth
                    .iter()
                    .zip(&src.truth)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(moved > 0.0, "member {}", s.index);
            }
            Disturbance::Friction { share } => {
                kinds[1] += 1;
                assert!((0.1..=0.25).contains(&share));
                assert_eq!(s.friction_share, share);
                assert!(src.spec.friction_share <= 0.1);
                assert!(
                    ["sweep", "square", "p2p", "contour"].contains(&s.command.name()),
                    "member {}: friction members reverse",
                    s.index
                );
                let rig = s.rig.unwrap();
                assert!(rig.effects.friction && rig.effects.table_friction.coulomb > 0.0);
            }
            Disturbance::Encoder { counts } => {
                kinds[2] += 1;
                assert!((30.0..=1000.0).contains(&counts));
                assert!(s.rate_hz <= 1000.0 * (1.0 + 1e-9), "member {}", s.index);
                let q = s.resolution_m;
                assert!((q * counts / s.amplitude_m - 1.0).abs() < 1e-9);
                assert_eq!(s.noise_std_m, 0.0);
                // every measured sample (but glitches) is a whole count
                for (k, y) in m.position.iter().enumerate() {
                    if s.glitches.iter().all(|g| g.index != k) {
                        let c = y / q;
                        assert!((c - c.round()).abs() < 1e-6, "member {} row {k}", s.index);
                    }
                }
            }
        }
    }
    assert_eq!(kinds, [10, 10, 10]);
}
