//! Drive structures described in a parameter file: the linear closed loop
//! against closed forms, the simulation against the linear closed loop, and
//! the EMPS reference model against the measured EMPS run.

use std::path::Path;

use feedid::drive::{DriveStructure, LoopKind};

fn emps() -> DriveStructure {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/emps.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    DriveStructure::from_toml_str(&text, Some(&path)).unwrap()
}

/// Largest distance between the simulation of `s` on a ramp of `slope`
/// m/s (n samples at `rate`, from 0) and its transfer function's exact ramp
/// response.
fn ramp_gap(s: &DriveStructure, slope: f64, rate: f64, n: usize) -> f64 {
    let cmd: Vec<f64> = (0..n).map(|k| slope * (k as f64 / rate)).collect();
    let run = s.simulate(&cmd, rate, 0.0).unwrap();
    let exact = s
        .transfer_function()
        .unwrap()
        .ramp_response(slope, 1.0 / rate, n)
        .unwrap();
    run.position
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_emps_file_reads_with_its_published_values() {
    let s = emps();
    assert_eq!(s.position.kind, LoopKind::P);
    assert_eq!((s.position.kp, s.velocity.kp), (160.18, 243.45));
    assert_eq!((s.drive.gain, s.drive.limit), (35.1507, Some(10.0)));
    assert_eq!(s.mechanics.mass, 95.1089);
    assert_eq!(
        (s.friction.viscous, s.friction.coulomb, s.friction.offset),
        (203.5034, 20.3935, -3.1648)
    );
    assert_eq!(s.controller.sample_time, Some(0.001));
    assert!(s.source.as_deref().unwrap_or("").contains("Janot"));
    // what it writes it reads back
    let again = DriveStructure::from_toml_str(&s.to_toml_string(), None).unwrap();
    assert_eq!(again, s);
}

#[test]
fn a_p_p_loop_on_a_rigid_mass_is_the_closed_form_second_order_system() {
    // X/Xs = g·kv·kp / (M s² + (Fv + g·kv) s + g·kv·kp)
    let s = emps();
    let (g, kv, kp, m, fv) = (35.1507, 243.45, 160.18, 95.1089, 203.5034);
    let summary = s.closed_loop().unwrap();
    let den = &summary.denominator;
    let num = &summary.numerator;
    assert_eq!(den.len(), 3);
    let expect_den = [m, fv + g * kv, g * kv * kp];
    for (a, b) in den.iter().zip(expect_den) {
        assert!((a - b).abs() <= 1e-12 * b.abs(), "{den:?}");
    }
    assert_eq!(num.len(), 1);
    assert!((num[0] - g * kv * kp).abs() <= 1e-12 * num[0]);
    let wn = (g * kv * kp / m).sqrt();
    let zeta = (fv + g * kv) / (2.0 * (m * g * kv * kp).sqrt());
    assert!(summary.stable);
    for p in &summary.poles {
        assert!((p.freq_hz - wn / (2.0 * std::f64::consts::PI)).abs() < 1e-9 * wn);
        assert!((p.damping - zeta).abs() < 1e-9);
    }
    let e = summary.following_error_per_velocity.unwrap();
    assert!((e - (fv + g * kv) / (g * kv * kp)).abs() < 1e-12);
}

#[test]
fn integral_action_removes_the_following_error_and_feed_forward_halves_it() {
    let base = "[position]\nkp = 50.0\n[velocity]\nkp = 100.0\n[drive]\ngain = 10.0\n\
                [mechanics]\nmass = 5.0\n[friction]\nviscous = 20.0\n";
    let p = DriveStructure::from_toml_str(base, None).unwrap();
    let e0 = p
        .closed_loop()
        .unwrap()
        .following_error_per_velocity
        .unwrap();
    // v·(1/kp + Fv/(g·kv·kp))
    assert!((e0 - (1.0 / 50.0 + 20.0 / (10.0 * 100.0 * 50.0))).abs() < 1e-12);
    // a PI velocity loop makes the loop type 2 as far as the velocity is concerned:
    // the ramp error is v·(1 − kvff)/kp
    let pi = base.replace(
        "[velocity]\nkp = 100.0",
        "[velocity]\nkind = \"PI\"\nkp = 100.0\nki = 10.0",
    );
    let e1 = DriveStructure::from_toml_str(&pi, None)
        .unwrap()
        .closed_loop()
        .unwrap()
        .following_error_per_velocity
        .unwrap();
    assert!((e1 - 1.0 / 50.0).abs() < 1e-12, "{e1}");
    let ff = format!("{pi}[feed_forward]\nvelocity = 0.5\n");
    let e2 = DriveStructure::from_toml_str(&ff, None)
        .unwrap()
        .closed_loop()
        .unwrap()
        .following_error_per_velocity
        .unwrap();
    assert!((e2 - 0.5 / 50.0).abs() < 1e-12, "{e2}");
    // a PI position loop commanding the force directly: no ramp error
    let pid =
        "[position]\nkind = \"PID\"\nkp = 2000.0\nki = 20.0\nkd = 0.02\n[drive]\ngain = 1.0\n\
               [mechanics]\nmass = 1.0\n[friction]\nviscous = 5.0\n";
    let s = DriveStructure::from_toml_str(pid, None).unwrap();
    let summary = s.closed_loop().unwrap();
    assert!(summary.stable, "{summary}");
    assert_eq!(summary.following_error_per_velocity, Some(0.0));
}

#[test]
fn the_linear_continuous_simulation_follows_the_transfer_function() {
    // no friction but viscous, no saturation, continuous: the simulated ramp
    // response is the transfer function's (to the integration's accuracy)
    let text = "[position]\nkind = \"PI\"\nkp = 50.0\nki = 5.0\n[velocity]\nkind = \"PI\"\nkp = 100.0\nki = 20.0\n\
                [drive]\ngain = 10.0\n[mechanics]\nmass = 5.0\n[friction]\nviscous = 20.0\n\
                [feed_forward]\nvelocity = 0.8\n";
    let s = DriveStructure::from_toml_str(text, None).unwrap();
    let worst = ramp_gap(&s, 0.05, 2000.0, 2000);
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn bad_structures_are_refused_with_the_key_named() {
    for (text, key) in [
        ("[position]\nkp = -1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 1.0\n", "position.kp"),
        ("[position]\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 0.0\n", "mechanics.mass"),
        (
            "[position]\nkp = 1.0\n[velocity]\nkind = \"PID\"\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 1.0\n",
            "velocity.kind",
        ),
        (
            "[position]\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 1.0\n[feed_forward]\nvelocity = 1.0\n",
            "feed_forward.velocity",
        ),
        ("[position]\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 1.0\nweight = 3\n", "weight"),
    ] {
        let e = DriveStructure::from_toml_str(text, Some(Path::new("axis.toml"))).unwrap_err();
        let m = e.to_string();
        assert!(m.contains(key) && m.contains("axis.toml"), "{m}");
    }
    assert!(DriveStructure::describes("[drive]\ngain = 1.0\n"));
    assert!(!DriveStructure::describes("[control]\nkv = 30.0\n"));
}

#[test]
fn the_emps_reference_model_reproduces_the_measured_run() {
    let Some((qg, qm, rate)) = emps_recording() else {
        return;
    };
    let run = emps().simulate(&qg, rate, qm[0]).unwrap();
    let rms = |f: &dyn Fn(usize) -> f64| {
        ((0..qm.len()).map(|k| f(k).powi(2)).sum::<f64>() / qm.len() as f64).sqrt()
    };
    let tracking = rms(&|k| qg[k] - qm[k]);
    let error = rms(&|k| run.position[k] - qm[k]);
    eprintln!("EMPS: tracking error rms {tracking:.3e} m, reference model error rms {error:.3e} m");
    // the reference model inside the known controller explains the run:
    // its error is a small part of the tracking error it reproduces
    assert!(error < 0.01 * tracking, "{error} vs {tracking}");
}

#[test]
fn a_pid_position_loop_commanding_force_follows_its_transfer_function() {
    let text =
        "[position]\nkind = \"PID\"\nkp = 2000.0\nki = 20.0\nkd = 0.02\n[drive]\ngain = 1.0\n\
                [mechanics]\nmass = 1.0\n[friction]\nviscous = 5.0\n";
    let s = DriveStructure::from_toml_str(text, None).unwrap();
    let worst = ramp_gap(&s, 0.02, 5000.0, 2500);
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn a_sampled_controller_approaches_the_continuous_one_as_its_rate_rises() {
    let base = "[position]\nkp = 50.0\n[velocity]\nkp = 100.0\n[drive]\ngain = 10.0\n\
                [mechanics]\nmass = 5.0\n[friction]\nviscous = 20.0\ncoulomb = 2.0\n";
    let continuous = DriveStructure::from_toml_str(base, None).unwrap();
    let gap = |rate: f64| {
        let sampled = DriveStructure::from_toml_str(
            &format!(
                "{base}[controller]\nsample_time = {}\nvelocity_estimate = \"backward\"\n",
                1.0 / rate
            ),
            None,
        )
        .unwrap();
        let n = (0.5 * rate) as usize;
        let cmd: Vec<f64> = (0..n).map(|k| 0.01 * (k as f64 / rate)).collect();
        let a = continuous.simulate(&cmd, rate, 0.0).unwrap();
        let b = sampled.simulate(&cmd, rate, 0.0).unwrap();
        a.position
            .iter()
            .zip(&b.position)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    let (slow, fast) = (gap(1000.0), gap(10_000.0));
    assert!(fast < 0.2 * slow, "{slow} {fast}");
    assert!(fast < 1e-5, "{fast}");
}

#[test]
fn full_feed_forward_on_a_frictionless_mass_tracks_exactly() {
    // kvff = kaff = 1, no friction: N = D, X/Xs = 1 and no following error
    let text = "[position]\nkp = 30.0\n[velocity]\nkind = \"PI\"\nkp = 80.0\nki = 15.0\n[drive]\ngain = 2.0\n\
                [mechanics]\nmass = 7.0\n[feed_forward]\nvelocity = 1.0\nacceleration = 1.0\n";
    let s = DriveStructure::from_toml_str(text, None).unwrap();
    let summary = s.closed_loop().unwrap();
    assert_eq!(summary.numerator.len(), summary.denominator.len());
    for (a, b) in summary.numerator.iter().zip(&summary.denominator) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{summary}");
    }
    assert_eq!(summary.following_error_per_velocity, Some(0.0));
}

/// DATA_EMPS.mat with `qg` as the command and the variable `position`
/// (`qm`, or `vir` read the same way), or `None` when the file is absent.
fn emps_read(position: &str) -> Option<feedid::Recording> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/emps/DATA_EMPS.mat");
    if !path.exists() {
        eprintln!(
            "skipped: {} is absent (the EMPS data set, see its README)",
            path.display()
        );
        return None;
    }
    let opts = feedid::io::ReadOptions {
        time: Some(feedid::io::ChannelRef::parse("t").unwrap()),
        command: Some(feedid::io::ChannelRef::parse("qg").unwrap()),
        position: Some(feedid::io::ChannelRef::parse(position).unwrap()),
        ..Default::default()
    };
    Some(feedid::io::read_recording(&path, &opts).unwrap())
}

/// EMPS command, measured position and rate.
fn emps_recording() -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let rec = emps_read("qm")?;
    Some((
        rec.command().to_vec(),
        rec.position().to_vec(),
        rec.rate_hz(),
    ))
}

#[test]
fn the_emps_mass_and_friction_are_recovered_from_command_and_position() {
    use feedid::drive::StructureParam as P;
    let Some((qg, qm, rate)) = emps_recording() else {
        return;
    };
    // start 30 % off every reference value, the offset at 0
    let mut start = emps();
    start.mechanics.mass *= 1.3;
    start.friction.viscous *= 0.7;
    start.friction.coulomb *= 1.3;
    start.friction.offset = 0.0;
    let fit = start
        .fit(
            &qg,
            &qm,
            rate,
            &[P::Mass, P::Viscous, P::Coulomb, P::Offset],
        )
        .unwrap();
    eprintln!("{fit}");
    let reference = emps();
    let rel = |p: P| {
        let e = fit.estimates.iter().find(|e| e.param == p).unwrap();
        let r = match p {
            P::Mass => reference.mechanics.mass,
            P::Viscous => reference.friction.viscous,
            P::Coulomb => reference.friction.coulomb,
            _ => unreachable!(),
        };
        (e.value - r) / r
    };
    for p in [P::Mass, P::Viscous, P::Coulomb] {
        assert!(
            rel(p).abs() < 0.05,
            "{}: {:+.2} %",
            p.name(),
            100.0 * rel(p)
        );
    }
    let offset = fit
        .estimates
        .iter()
        .find(|e| e.param == P::Offset)
        .unwrap()
        .value;
    assert!(
        (offset - reference.friction.offset).abs() < 1.0,
        "offset {offset}"
    );
    // the estimates explain the run at least as well as the reference does
    let reference_rms = {
        let run = reference.simulate(&qg, rate, qm[0]).unwrap();
        (run.position
            .iter()
            .zip(&qm)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / qm.len() as f64)
            .sqrt()
    };
    assert!(
        fit.rms <= reference_rms * (1.0 + 1e-9),
        "{} vs {reference_rms}",
        fit.rms
    );
}

#[test]
fn inverse_dynamics_recovers_a_simulated_axis_and_the_emps_reference() {
    use feedid::drive::{inverse_dynamics, IdimConfig};
    // a simulated axis with known parameters: force = gain · output
    let mut s = emps();
    s.controller.sample_time = None;
    let rate = 1000.0;
    let cmd: Vec<f64> = (0..20_000)
        .map(|k| {
            let t = k as f64 / rate;
            0.05 * (0.7 * t).sin() + 0.02 * (2.3 * t).sin()
        })
        .collect();
    let run = s.simulate(&cmd, rate, 0.0).unwrap();
    let force: Vec<f64> = run.output.iter().map(|u| s.drive.gain * u).collect();
    let fit = inverse_dynamics(&run.position, &force, rate, &IdimConfig::default()).unwrap();
    let rel = |x: f64, truth: f64| ((x - truth) / truth).abs();
    assert!(rel(fit.mass.0, 95.1089) < 0.01, "{fit:?}");
    assert!(rel(fit.viscous.0, 203.5034) < 0.01, "{fit:?}");
    assert!(rel(fit.coulomb.0, 20.3935) < 0.02, "{fit:?}");
    assert!((fit.offset.0 + 3.1648).abs() < 0.2, "{fit:?}");
    // EMPS: force = gtau · vir, beside the measured position
    let (Some(qm), Some(vir)) = (emps_read("qm"), emps_read("vir")) else {
        return;
    };
    let force: Vec<f64> = vir.position().iter().map(|u| 35.1507 * u).collect();
    let fit =
        inverse_dynamics(qm.position(), &force, qm.rate_hz(), &IdimConfig::default()).unwrap();
    eprintln!("EMPS IDIM-LS: {fit:?}");
    assert!(rel(fit.mass.0, 95.1089) < 0.02, "{fit:?}");
    assert!(rel(fit.viscous.0, 203.5034) < 0.02, "{fit:?}");
    assert!(rel(fit.coulomb.0, 20.3935) < 0.02, "{fit:?}");
    assert!((fit.offset.0 + 3.1648).abs() < 1.0, "{fit:?}");
}

#[test]
fn the_friction_law_has_its_levels_dip_and_asymmetry() {
    use feedid::drive::FrictionLaw;
    let f = FrictionLaw {
        viscous: 10.0,
        coulomb: 5.0,
        coulomb_negative: Some(7.0),
        r#static: Some(8.0),
        stribeck_velocity: Some(1e-3),
        offset: -1.0,
        smoothing_velocity: Some(1e-6),
    };
    // far above the Stribeck velocity: viscous + Coulomb + offset
    assert!((f.force(0.1) - (1.0 + 5.0 - 1.0)).abs() < 1e-9);
    assert!((f.force(-0.1) - (-1.0 - 7.0 - 1.0)).abs() < 1e-9);
    // just moving: the static level
    assert!((f.force(1e-5) - (8.0 - 1.0)).abs() < 1e-2);
    // at rest: the offset alone
    assert_eq!(f.force(0.0), -1.0);
}

#[test]
fn a_fit_refuses_what_it_cannot_do_with_a_reason() {
    use feedid::drive::StructureParam as P;
    let s = emps();
    let cmd = vec![0.0; 100];
    assert!(s.fit(&cmd, &cmd[..99], 1000.0, &[P::Mass]).is_err());
    assert!(s.fit(&cmd, &cmd, 1000.0, &[]).is_err());
    let mut bad = cmd.clone();
    bad[5] = f64::NAN;
    let e = s.fit(&cmd, &bad, 1000.0, &[P::Mass]).unwrap_err();
    assert!(e.to_string().contains("position"), "{e}");
    // a parameter estimated as positive needs a positive start
    let mut zero = s.clone();
    zero.friction.coulomb = 0.0;
    assert!(zero.fit(&cmd, &cmd, 1000.0, &[P::Coulomb]).is_err());
    let e = "Kv".parse::<P>().unwrap_err();
    assert!(e.to_string().contains("M, Fv, Fc, offset"), "{e}");
}

#[test]
fn tuning_a_p_p_loop_hits_the_bandwidth_and_damping_asked() {
    use feedid::drive::TuneTarget;
    let s = emps();
    for (bw, z) in [
        (10.0, 0.5),
        (40.0, std::f64::consts::FRAC_1_SQRT_2),
        (60.0, 1.0),
    ] {
        let t = s
            .tune(&TuneTarget {
                bandwidth_hz: bw,
                damping: z,
            })
            .unwrap();
        assert!(
            (t.after.bandwidth_hz.unwrap() - bw).abs() < 1e-6 * bw,
            "{bw}"
        );
        for p in &t.after.poles {
            assert!((p.damping - z).abs() < 1e-6, "{bw} {z}: {}", p.damping);
        }
        // the second-order overshoot exp(−πζ/√(1−ζ²))
        let expected = if z < 1.0 {
            100.0 * (-std::f64::consts::PI * z / (1.0 - z * z).sqrt()).exp()
        } else {
            0.0
        };
        assert!(
            (t.overshoot_percent.1 - expected).abs() < 0.05,
            "{} {expected}",
            t.overshoot_percent.1
        );
        // the mass, friction and drive are kept
        assert_eq!(t.structure.mechanics, s.mechanics);
        assert_eq!(t.structure.friction, s.friction);
        assert_eq!(t.position_kp.0, 160.18);
    }
    // a bandwidth the viscous friction alone exceeds cannot be asked for
    assert!(s
        .tune(&TuneTarget {
            bandwidth_hz: 0.1,
            damping: 0.7
        })
        .is_err());
    // another loop structure is refused with the reason
    let mut pi = s.clone();
    pi.position.kind = feedid::drive::LoopKind::PI;
    pi.position.ki = 10.0;
    let e = pi
        .tune(&TuneTarget {
            bandwidth_hz: 40.0,
            damping: 0.7,
        })
        .unwrap_err();
    assert!(e.to_string().contains("P position loop"), "{e}");
    // the tuned gains run through the nonlinear simulation: a smaller
    // following error on a move within the drive's limit
    let t = s
        .tune(&TuneTarget {
            bandwidth_hz: 40.0,
            damping: std::f64::consts::FRAC_1_SQRT_2,
        })
        .unwrap();
    let cmd = feedid::signal::Scenario::Scurve
        .command(1000.0, 1.0, 0)
        .unwrap();
    let (before, after) = (
        s.run_figures(&cmd, 1000.0).unwrap(),
        t.structure.run_figures(&cmd, 1000.0).unwrap(),
    );
    eprintln!("{before:?}\n{after:?}");
    assert!(after.rms_error < before.rms_error, "{before:?} {after:?}");
}

#[test]
fn a_structure_whose_simulation_would_not_end_is_refused() {
    // a Coulomb level of 1e9 N on a 1 kg mass with a 1 nm/s knee: a stiffness
    // no explicit integration resolves in bounded time
    let text = "[position]\nkp = 10.0\n[velocity]\nkp = 10.0\n[drive]\ngain = 1.0\n\
                [mechanics]\nmass = 1.0\n[friction]\ncoulomb = 1e9\nsmoothing_velocity = 1e-9\n";
    let s = DriveStructure::from_toml_str(text, None).unwrap();
    let e = s.simulate(&vec![0.0; 100_000], 1000.0, 0.0).unwrap_err();
    assert!(e.to_string().contains("1e8"), "{e}");
    // NaN and infinities in the file are refused with the key
    for bad in ["mass = nan", "mass = inf"] {
        let text = format!("[position]\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\n{bad}\n");
        let e = DriveStructure::from_toml_str(&text, None).unwrap_err();
        assert!(e.to_string().contains("mechanics.mass"), "{e}");
    }
}

/// The EMPS loops on a two-mass axis: 80 kg load, 15 kg motor side, a
/// transmission of `k` N/m damped by 2000 N·s/m, measured on `side`.
fn two_mass(k: f64, side: &str) -> DriveStructure {
    let text = format!(
        "[position]\nkp = 160.18\n[velocity]\nkp = 243.45\n[drive]\ngain = 35.1507\n\
         [mechanics]\nmass = 80.0\nmotor_mass = 15.0\nstiffness = {k}\ndamping = 2000.0\nmeasured = \"{side}\"\n\
         [friction]\nviscous = 203.5034\n"
    );
    DriveStructure::from_toml_str(&text, None).unwrap()
}

#[test]
fn a_stiff_two_mass_axis_is_the_rigid_one_and_its_mode_is_the_closed_form() {
    // the free mechanics (c = Fv = 0): Δ = s²·(M_m·M_l·s² + k·(M_m + M_l))
    let mut free = two_mass(2e7, "load");
    free.mechanics.damping = 0.0;
    free.friction.viscous = 0.0;
    let (_, delta) = free.plant();
    let roots = feedid::lti::poly_roots(&delta).unwrap();
    let w = (2e7f64 * (15.0 + 80.0) / (15.0 * 80.0)).sqrt();
    let mode = roots.iter().map(|r| r.im.abs()).fold(0.0, f64::max);
    assert!((mode - w).abs() < 1e-9 * w, "{mode} {w}");
    // a very stiff transmission: the rigid closed loop of the total mass
    let rigid = DriveStructure {
        mechanics: feedid::drive::Mechanics {
            stiffness: None,
            ..two_mass(1.0, "load").mechanics
        },
        ..two_mass(1.0, "load")
    };
    assert_eq!(rigid.mechanics.total_mass(), 95.0);
    let b_rigid = rigid.closed_loop().unwrap().bandwidth_hz.unwrap();
    for side in ["load", "motor"] {
        let b = two_mass(1e12, side)
            .closed_loop()
            .unwrap()
            .bandwidth_hz
            .unwrap();
        assert!(
            (b - b_rigid).abs() < 1e-4 * b_rigid,
            "{side}: {b} {b_rigid}"
        );
    }
}

#[test]
fn the_two_mass_simulation_follows_its_transfer_function_on_either_side() {
    for side in ["load", "motor"] {
        let s = two_mass(3e6, side);
        assert!(s.closed_loop().unwrap().stable, "{side}");
        let worst = ramp_gap(&s, 0.03, 2000.0, 2000);
        assert!(worst < 1e-9, "{side}: {worst}");
    }
    // the two sides differ by the transmission's deflection
    let load = two_mass(3e6, "load")
        .simulate(&vec![1e-3; 500], 2000.0, 0.0)
        .unwrap();
    let motor = two_mass(3e6, "motor")
        .simulate(&vec![1e-3; 500], 2000.0, 0.0)
        .unwrap();
    assert!(load
        .position
        .iter()
        .zip(&motor.position)
        .any(|(a, b)| (a - b).abs() > 1e-7));
}

#[test]
fn velocity_feedback_from_the_load_destabilises_a_lightly_damped_transmission() {
    // non-collocated: measured on the load, the lightly damped mode goes
    // unstable under the EMPS velocity gain; measured on the motor it does not
    for k in [1e6, 1e8, 1e10] {
        let mut load = two_mass(k, "load");
        load.mechanics.damping = 50.0;
        let mut motor = two_mass(k, "motor");
        motor.mechanics.damping = 50.0;
        assert!(!load.closed_loop().unwrap().stable, "{k}");
        assert!(motor.closed_loop().unwrap().stable, "{k}");
    }
}

#[test]
fn two_mass_mechanics_need_the_motor_mass_and_are_tuned_as_their_rigid_equivalent() {
    let text =
        "[position]\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 1.0\nstiffness = 1e6\n";
    let e = DriveStructure::from_toml_str(text, None).unwrap_err();
    assert!(e.to_string().contains("mechanics.motor_mass"), "{e}");
    // measured on the motor, the transmission's mode (≈ 190 Hz) far above
    // the bandwidth asked: the rigid equivalent's gains, the whole loop's
    // bandwidth the one asked, stable
    let s = two_mass(3e6, "motor");
    let t = s
        .tune(&feedid::drive::TuneTarget {
            bandwidth_hz: 20.0,
            damping: 0.7,
        })
        .unwrap();
    assert!(t.after.stable);
    let bw = t.after.bandwidth_hz.unwrap();
    assert!((bw - 20.0).abs() < 1e-6 * 20.0, "{bw}");
    // its gains are those of the rigid axis of the same total mass within
    // 15 % (the mode ten times above the bandwidth, the compliance seen on
    // the motor)
    let mut rigid = s.clone();
    rigid.mechanics.stiffness = None;
    let r = rigid
        .tune(&feedid::drive::TuneTarget {
            bandwidth_hz: 20.0,
            damping: 0.7,
        })
        .unwrap();
    assert!(
        ((t.position_kp.1 - r.position_kp.1) / r.position_kp.1).abs() < 0.15,
        "{} {}",
        t.position_kp.1,
        r.position_kp.1
    );
}

#[test]
fn a_two_mass_axis_stiffness_and_masses_are_recovered_from_its_run() {
    use feedid::drive::StructureParam as P;
    // measured on the motor (collocated), a command rich enough to show the mode
    let truth = two_mass(3e6, "motor");
    let rate = 2000.0;
    let cmd: Vec<f64> = (0..8000)
        .map(|k| {
            let t = k as f64 / rate;
            1e-3 * ((3.0 * t).sin() + 0.3 * (37.0 * t).sin() + 0.1 * (190.0 * t).sin())
        })
        .collect();
    let run = truth.simulate(&cmd, rate, 0.0).unwrap();
    let mut start = truth.clone();
    start.mechanics.mass *= 1.3;
    start.mechanics.motor_mass = Some(15.0 * 0.75);
    start.mechanics.stiffness = Some(3e6 * 1.4);
    let fit = start
        .fit(
            &cmd,
            &run.position,
            rate,
            &[P::Mass, P::MotorMass, P::Stiffness],
        )
        .unwrap();
    for (p, t) in [(P::Mass, 80.0), (P::MotorMass, 15.0), (P::Stiffness, 3e6)] {
        let e = fit.estimates.iter().find(|e| e.param == p).unwrap();
        assert!(
            ((e.value - t) / t).abs() < 1e-4,
            "{}: {} vs {t}",
            p.name(),
            e.value
        );
    }
    // a rigid structure has no stiffness to estimate
    let e = emps()
        .fit(&cmd, &run.position, rate, &[P::Stiffness])
        .unwrap_err();
    assert!(e.to_string().contains("two-mass"), "{e}");
}

#[test]
fn restarts_flag_what_only_enters_as_a_product() {
    use feedid::drive::StructureParam as P;
    // without the output limit, a P/P loop sees the drive gain and the
    // velocity gain only as their product g·kv: restarts end apart
    let mut s = emps();
    s.drive.limit = None;
    s.controller.sample_time = None;
    let rate = 1000.0;
    let cmd: Vec<f64> = (0..6000)
        .map(|k| 0.01 * (2.0 * (k as f64 / rate)).sin())
        .collect();
    let run = s.simulate(&cmd, rate, 0.0).unwrap();
    let fit = s
        .fit_with_restarts(&cmd, &run.position, rate, &[P::DriveGain, P::VelocityKp], 2)
        .unwrap();
    assert!(
        fit.estimates
            .iter()
            .any(|e| e.verdict == feedid::drive::StructureVerdict::NotIdentifiable),
        "{fit}"
    );
    // the mass and the viscous friction are pinned
    let fit = s
        .fit_with_restarts(&cmd, &run.position, rate, &[P::Mass, P::Viscous], 2)
        .unwrap();
    assert!(fit.estimates.iter().all(|e| e.identifiable()), "{fit}");
    assert!(
        fit.estimates
            .iter()
            .all(|e| e.restart_spread.unwrap() < 1e-3),
        "{fit}"
    );
}

/// Fits axis `i` of the generated structure family from its truth moved
/// 30 % (15 % where the loop cannot run from there), two restarts.
fn fit_family_axis(i: usize) -> (feedid::zoo::StructureAxis, feedid::drive::StructureFit) {
    let a = feedid::zoo::StructureAxis::new(i).unwrap();
    let measured = a.measured();
    let fit = [0.3, 0.15]
        .into_iter()
        .find_map(|share| {
            a.start(share)
                .fit_with_restarts(&a.command, &measured, a.rate_hz, &a.estimate, 2)
                .ok()
        })
        .unwrap();
    (a, fit)
}

#[test]
fn identifiable_estimates_of_generated_axes_are_within_five_percent_of_the_truth() {
    use feedid::drive::StructureParam as P;
    // P/PI with feed-forward, PID commanding force, P/P with a constant
    // force, P/P with Stribeck friction and a constant force, the PID
    // commanding force at 120 Hz
    let mut identifiable = 0;
    for i in [1, 2, 4, 12, 22] {
        let (a, fit) = fit_family_axis(i);
        for e in &fit.estimates {
            let truth = e.param.get(&a.truth);
            let scale = if e.param == P::Offset {
                a.truth.friction.coulomb
            } else {
                truth.abs()
            };
            let error = (e.value - truth).abs() / scale;
            if e.identifiable() {
                identifiable += 1;
                assert!(
                    error <= 0.05,
                    "#{i} {}: {} {} against {truth}",
                    a.label,
                    e.param.name(),
                    e.value
                );
            }
        }
    }
    assert!(identifiable >= 15, "{identifiable}");
}

#[test]
fn a_parameter_the_run_does_not_see_is_not_identifiable_and_leaves_the_others_known() {
    use feedid::drive::StructureParam as P;
    // a PID loop commanding force with a Stribeck dip: the fit drives the
    // static level below the Coulomb level, where it acts no more
    let (a, fit) = fit_family_axis(6);
    let fs = fit.estimates.iter().find(|e| e.param == P::Static).unwrap();
    // equally good restarts end far apart: the data do not decide it
    assert_eq!(
        fs.verdict,
        feedid::drive::StructureVerdict::NotIdentifiable,
        "{fit}"
    );
    assert!(fs.restart_spread.unwrap() > feedid::drive::PINNED, "{fit}");
    assert!(fs.std_error.is_infinite(), "{fit}");
    for p in [P::Mass, P::Viscous, P::Coulomb] {
        let e = fit.estimates.iter().find(|e| e.param == p).unwrap();
        assert!(e.std_error.is_finite(), "{}: {fit}", p.name());
        assert!(e.identifiable(), "{}: {fit}", p.name());
        let truth = p.get(&a.truth);
        assert!(
            ((e.value - truth) / truth).abs() < 0.05,
            "{}: {fit}",
            p.name()
        );
    }
}

#[test]
fn an_imprecise_estimate_is_not_called_identifiable_even_when_restarts_agree() {
    use feedid::drive::StructureParam as P;
    // a two-mass axis at 526 Hz: the motor mass is known to ±17 % (one
    // standard error); its restarts end together, but it is 14 % off
    let (a, fit) = fit_family_axis(7);
    let mm = fit
        .estimates
        .iter()
        .find(|e| e.param == P::MotorMass)
        .unwrap();
    assert!(
        3.0 * mm.std_error > feedid::drive::PINNED * mm.value,
        "{fit}"
    );
    assert!(mm.restart_spread.unwrap() < 1e-3, "{fit}");
    assert_eq!(
        mm.verdict,
        feedid::drive::StructureVerdict::Imprecise,
        "{fit}"
    );
    // and the truth is within its three standard errors
    let truth = P::MotorMass.get(&a.truth);
    assert!(
        (mm.value - truth).abs() <= 3.0 * mm.std_error,
        "{truth}: {fit}"
    );
}

/// The coefficients of `M·(s + p)(s² + 2ζω·s + ω²)`, highest power first.
fn placed_cubic(m: f64, p: f64, z: f64, w: f64) -> [f64; 4] {
    [
        m,
        m * (p + 2.0 * z * w),
        m * (w * w + 2.0 * z * w * p),
        m * p * w * w,
    ]
}

#[test]
fn tuning_an_integral_loop_places_its_poles_and_hits_the_bandwidth() {
    use feedid::drive::{LoopKind, TuneTarget};
    let z = std::f64::consts::FRAC_1_SQRT_2;
    // P around PI with feed-forward (family axis 1), and a PID loop
    // commanding the force (family axis 2)
    for (i, bw) in [(1, 8.0), (1, 15.0), (2, 10.0), (2, 25.0)] {
        let s = feedid::zoo::StructureAxis::new(i).unwrap().truth;
        let t = s
            .tune(&TuneTarget {
                bandwidth_hz: bw,
                damping: z,
            })
            .unwrap();
        let after = &t.after;
        assert!(after.stable, "#{i} {bw}");
        assert!(
            (after.bandwidth_hz.unwrap() - bw).abs() < 1e-6 * bw,
            "#{i} {bw}: {:?}",
            after.bandwidth_hz
        );
        // the complex pair at the damping asked, the real pole at ω/4
        let pair: Vec<_> = after.poles.iter().filter(|p| p.im.abs() > 0.0).collect();
        assert_eq!(pair.len(), 2, "#{i} {bw}: {:?}", after.poles);
        let w = (pair[0].re * pair[0].re + pair[0].im * pair[0].im).sqrt();
        assert!((-pair[0].re / w - z).abs() < 1e-6, "#{i} {bw}");
        let real = after.poles.iter().find(|p| p.im == 0.0).unwrap();
        assert!((-real.re - 0.25 * w).abs() < 1e-6 * w, "#{i} {bw}");
        // the closed loop's denominator is M·(s + ω/4)(s² + 2ζω·s + ω²)
        let m = s.mechanics.total_mass();
        let expected = placed_cubic(m, 0.25 * w, z, w);
        let scale = after.denominator[0] / m;
        for (a, e) in after.denominator.iter().zip(expected) {
            assert!((a / scale - e).abs() < 1e-6 * e.abs(), "#{i} {bw}: {a} {e}");
        }
        // gains of the loop's own kind; mass, friction, feed-forward kept
        match s.velocity.kind {
            LoopKind::PI => assert!(t.velocity_ki.1 > 0.0 && t.velocity_ki.1 < t.position_kp.1),
            _ => assert!(t.position_ki.1 > 0.0 && t.position_kd.1 > 0.0),
        }
        assert_eq!(t.structure.friction, s.friction);
        assert_eq!(t.structure.feed_forward, s.feed_forward);
    }
    // a two-mass axis (family axis 3, its mode at 227 Hz) gets its rigid
    // equivalent's gains, the whole loop's bandwidth the one asked
    let t = feedid::zoo::StructureAxis::new(3)
        .unwrap()
        .truth
        .tune(&TuneTarget {
            bandwidth_hz: 10.0,
            damping: z,
        })
        .unwrap();
    assert!(t.after.stable);
    assert!((t.after.bandwidth_hz.unwrap() - 10.0).abs() < 1e-6 * 10.0);
}

#[test]
fn the_papers_cascade_as_a_structure_is_its_seventh_order_closed_loop() {
    use feedid::drive::{closed_loop_coefficients, D1Variant, RigParams};
    let mut ff = RigParams::default();
    ff.control.kvff = 0.8;
    ff.control.kaff = 0.5;
    for p in [RigParams::default(), ff] {
        let s = DriveStructure::paper(&p).unwrap();
        let ours = s.transfer_function().unwrap();
        let paper = closed_loop_coefficients(&p, D1Variant::Corrected)
            .transfer_function()
            .unwrap();
        // the same polynomials up to a common factor
        let k = ours.den()[0] / paper.den()[0];
        for (a, b) in [(ours.den(), paper.den()), (ours.num(), paper.num())] {
            let top = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let (a, b) = (trimmed(a), trimmed(b));
            assert_eq!(a.len(), b.len(), "{a:?} {b:?}");
            for (x, y) in a.iter().zip(b) {
                assert!((x / k - y).abs() <= 1e-9 * top, "{x} {y}");
            }
        }
        // through a structure file and back
        let again = DriveStructure::from_toml_str(&s.to_toml_string(), None).unwrap();
        assert_eq!(again, s);
    }
}

/// `p` without leading coefficients below 1e-300 of its largest.
fn trimmed(p: &[f64]) -> Vec<f64> {
    let top = p.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let first = p.iter().position(|v| v.abs() > 1e-300 * top).unwrap_or(0);
    p[first..].to_vec()
}

#[test]
fn a_current_loop_simulation_follows_its_transfer_function() {
    // the paper's cascade (current loop, back-EMF, screw stiffness, velocity
    // from the motor) without friction or limits: the simulated ramp
    // response is the transfer function's
    let p = feedid::drive::RigParams::default();
    let s = DriveStructure::paper(&p).unwrap();
    let worst = ramp_gap(&s, 0.05, 5000.0, 2500);
    assert!(worst < 1e-9, "{worst}");
    // and a current loop far faster than the mechanics is a force source
    let mut fast = emps();
    fast.controller.sample_time = None;
    fast.drive.limit = None;
    let ideal = fast.closed_loop().unwrap();
    fast.current = Some(feedid::drive::CurrentLoop {
        kp: 1e4,
        ki: 0.0,
        inductance: 1e-4,
        resistance: 0.0,
        back_emf: 0.0,
    });
    let with = fast.closed_loop().unwrap();
    let (a, b) = (ideal.bandwidth_hz.unwrap(), with.bandwidth_hz.unwrap());
    assert!((a - b).abs() < 1e-3 * a, "{a} {b}");
    // and `tune` places the whole loop's bandwidth with it
    let t = fast
        .tune(&feedid::drive::TuneTarget {
            bandwidth_hz: 40.0,
            damping: 0.7,
        })
        .unwrap();
    assert!(t.after.stable);
    assert!((t.after.bandwidth_hz.unwrap() - 40.0).abs() < 1e-6 * 40.0);
    // a current loop's values are checked by name
    let text = "[position]\nkp = 1.0\n[drive]\ngain = 1.0\n[mechanics]\nmass = 1.0\n\
                [current]\nkp = 1.0\ninductance = 0.0\nresistance = 1.0\n";
    let e = DriveStructure::from_toml_str(text, None).unwrap_err();
    assert!(e.to_string().contains("current.inductance"), "{e}");
}

#[test]
fn the_paper_cascade_s_mass_and_table_friction_are_recovered_and_the_start_reported() {
    use feedid::drive::StructureParam as P;
    // a PRBS-like program through the paper's cascade (current loop,
    // screw, velocity from the motor); the fit starts from 4 kg and 70 N·s/m
    let p = feedid::drive::RigParams::default();
    let truth = DriveStructure::paper(&p).unwrap();
    let rate = 5000.0;
    let cmd = feedid::signal::Scenario::Prbs
        .command(rate, 1.1, 0)
        .unwrap();
    let run = truth.simulate(&cmd, rate, 0.0).unwrap();
    let mut start = truth.clone();
    start.mechanics.mass = 4.0;
    start.friction.viscous = 70.0;
    let fit = start
        .fit_with_restarts(&cmd, &run.position, rate, &[P::Mass, P::Viscous], 2)
        .unwrap();
    for (e, (file, t)) in fit.estimates.iter().zip([(4.0, 3.0), (70.0, 100.0)]) {
        assert_eq!(e.start, file, "{fit}");
        assert!(((e.value - t) / t).abs() < 1e-6, "{fit}");
        assert!(e.identifiable(), "{fit}");
    }
}

#[test]
fn tuning_the_papers_cascade_places_its_bandwidth_or_says_why_not() {
    use feedid::drive::TuneTarget;
    let s = DriveStructure::paper(&feedid::drive::RigParams::default()).unwrap();
    let z = std::f64::consts::FRAC_1_SQRT_2;
    // 360 Hz: the whole loop (current loop, screw mode) placed there
    let t = s
        .tune(&TuneTarget {
            bandwidth_hz: 360.0,
            damping: z,
        })
        .unwrap();
    assert!(t.after.stable);
    assert!((t.after.bandwidth_hz.unwrap() - 360.0).abs() < 1e-6 * 360.0);
    // 450 Hz: the lightly damped screw mode lifts the response above −3 dB
    // and the bandwidth jumps across it: refused, not answered with another
    let e = s
        .tune(&TuneTarget {
            bandwidth_hz: 450.0,
            damping: z,
        })
        .unwrap_err();
    assert!(e.to_string().contains("jumps across"), "{e}");
}
