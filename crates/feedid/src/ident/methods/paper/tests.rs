//! Tests of the paper method.

use std::ops::Range;

use super::basis::*;
use super::config::*;
use super::estimator::*;
use super::polynomials::*;
use crate::error::Error;
use crate::ident::{Estimator, FitStatus, Signals, WindowFit, WindowOutcome};
use crate::solve::Termination;

const DT: f64 = 2e-4;
const W: usize = 20;
const H: usize = 10;

struct Data {
    t: Vec<f64>,
    u: Vec<f64>,
    y: Vec<f64>,
}

impl Data {
    fn signals(&self, motion_start: f64) -> Signals<'_> {
        Signals::new(&self.t, &self.u, &self.y, DT, motion_start)
    }
}

fn eval_p(p: &[f64; 3], tau: f64) -> f64 {
    p[0] * tau.powi(5) + p[1] * tau.powi(6) + p[2] * tau.powi(7)
}

fn eval_q(q: &[f64; 8], tau: f64) -> f64 {
    q.iter().rev().fold(0.0, |acc, c| acc * tau + c)
}

/// Samples `0..n` at `t = t0 + k·dt` of the model polynomials in `τ = t − origin`.
fn model_data(p: &[f64; 3], q: &[f64; 8], t0: f64, origin: f64, n: usize) -> Data {
    let t: Vec<f64> = (0..n).map(|k| t0 + k as f64 * DT).collect();
    let y = t.iter().map(|&t| eval_p(p, t - origin)).collect();
    let u = t.iter().map(|&t| eval_q(q, t - origin)).collect();
    Data { t, u, y }
}

/// Polynomials whose terms are all O(1e-3) over `τ ∈ [0, span]`.
fn balanced(span: f64) -> ([f64; 3], [f64; 8]) {
    let ph = [1.0e-3, -0.6e-3, 0.8e-3];
    let qh = [
        0.2e-3, 1.1e-3, -0.7e-3, 0.5e-3, 0.9e-3, -0.4e-3, 0.3e-3, 0.6e-3,
    ];
    let p = [
        ph[0] / span.powi(5),
        ph[1] / span.powi(6),
        ph[2] / span.powi(7),
    ];
    let mut q = [0.0; 8];
    for i in 0..8 {
        q[i] = qh[i] / span.powi(i as i32);
    }
    (p, q)
}

fn method(solver: Solver, origin: TimeOrigin) -> PaperMethod {
    PaperConfig {
        solver,
        time_origin: origin,
        ..PaperConfig::default()
    }
    .build()
    .unwrap()
}

fn fit(m: &mut PaperMethod, s: &Signals<'_>, window: Range<usize>) -> ([f64; 11], WindowFit) {
    let mut c = [0.0; 11];
    let f = m.fit(s, window, &mut c).unwrap();
    (c, f)
}

fn max_rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) / y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn coefficient_mapping_uses_the_factorials_of_eq_6() {
    let c = coefficients_from_polynomials([1.0; 3], [1.0; 8]);
    assert_eq!(
        c,
        [120.0, 720.0, 5040.0, 1.0, 1.0, 2.0, 6.0, 24.0, 120.0, 720.0, 5040.0]
    );
    let (p, q) = polynomials_from_coefficients(&[
        120.0, 720.0, 5040.0, 1.0, 1.0, 2.0, 6.0, 24.0, 120.0, 720.0, 5040.0,
    ]);
    assert_eq!(p, [1.0; 3]);
    assert_eq!(q, [1.0; 8]);
    // P5 = N2/120, Q7 = D0/5040, Q2 = D5/2
    let c = [
        4.10814e9, 1.60209e13, 6.63693e15, 1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7,
        2.71640e10, 2.55023e13, 6.63693e15,
    ];
    let (p, q) = polynomials_from_coefficients(&c);
    assert!((p[0] - 4.10814e9 / 120.0).abs() < 1e-6 * p[0]);
    assert!((q[7] - 6.63693e15 / 5040.0).abs() < 1e-6 * q[7]);
    assert!((q[2] - 1.57906 / 2.0).abs() < 1e-12);
    assert_eq!(q[0], 1.68e-8);
    let back = coefficients_from_polynomials(p, q);
    assert!(max_rel(&back, &c) < 1e-15);
}

#[test]
fn coefficient_mapping_round_trips_from_polynomials() {
    let p = [3.3, -2.2e5, 7.1e-3];
    let q = [1.0, -2.0, 3.5, 4.25e3, -5.0e-4, 6.0, 7.0e9, -8.0];
    let (p2, q2) = polynomials_from_coefficients(&coefficients_from_polynomials(p, q));
    assert!(max_rel(&p2, &p) < 1e-15);
    assert!(max_rel(&q2, &q) < 1e-15);
}

#[test]
fn legendre_table_matches_closed_forms() {
    let t = legendre_monomials();
    // L3 = (5s³ − 3s)/2, L7 = (429s⁷ − 693s⁵ + 315s³ − 35s)/16
    assert_eq!(t[3][..4], [0.0, -1.5, 0.0, 2.5]);
    let l7 = [
        0.0,
        -35.0 / 16.0,
        0.0,
        315.0 / 16.0,
        0.0,
        -693.0 / 16.0,
        0.0,
        429.0 / 16.0,
    ];
    assert!(
        max_rel(
            &t[7][1..].iter().step_by(2).copied().collect::<Vec<_>>(),
            &l7[1..].iter().step_by(2).copied().collect::<Vec<_>>()
        ) < 1e-15
    );
}

#[test]
fn affine_change_of_variable_expands_binomially() {
    // 2 + 3·((τ − 1)/2) + 4·((τ − 1)/2)² = 2 − 1.5 + 1 + (1.5 − 2)τ + τ²
    let mut out = [0.0; 3];
    affine_to_monomial(&[2.0, 3.0, 4.0], 1.0, 2.0, &mut out);
    assert!(max_rel(&out, &[1.5, -0.5, 1.0]) < 1e-15);
}

#[test]
fn exact_model_polynomial_is_reproduced_by_qr_to_rounding() {
    let span = (W - 1) as f64 * DT;
    // first window after the motion start, and window-local time
    let (p, q) = balanced(span);
    let d = model_data(&p, &q, 0.0, 0.0, W + H);
    let expected = coefficients_from_polynomials(p, q);
    for origin in [TimeOrigin::Motion, TimeOrigin::Window] {
        let mut m = method(Solver::Qr, origin);
        let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
        assert!(
            max_rel(&c, &expected) < 1e-9,
            "{origin:?}: {}",
            max_rel(&c, &expected)
        );
        assert_eq!(f.status, FitStatus::Identified(Termination::Exact));
        assert!(f.residual_rms < 1e-16, "{}", f.residual_rms);
        let diag = m.diagnostics().unwrap();
        assert_eq!(diag.output_qr.unwrap().rank, 3);
        assert_eq!(diag.input_qr.unwrap().rank, 8);
    }
    // a later window (t0 = 10 ms): motion-origin polynomial balanced over [0, 14 ms]
    let t0 = 0.01;
    let (p, q) = balanced(t0 + span);
    let d = model_data(&p, &q, t0, 0.0, W);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
    let expected = coefficients_from_polynomials(p, q);
    // the fit itself is exact to rounding …
    assert!(f.residual_rms < 1e-17, "{}", f.residual_rms);
    // … the monomial coefficients lose the digits the change of basis
    // amplifies (~1e6 here): still 1e-6 relative
    assert!(m.diagnostics().unwrap().shift_amplification > 1e5);
    assert!(max_rel(&c, &expected) < 1e-6, "{}", max_rel(&c, &expected));
}

#[test]
fn rig_coefficients_are_identified_from_noise_free_model_polynomials() {
    // N, D of the default rig (docs/METHODS.md §2), first window after the motion start
    let c_true = [
        4.10814e9, 1.60209e13, 6.63693e15, 1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7,
        2.71640e10, 2.55023e13, 6.63693e15,
    ];
    let (p, q) = polynomials_from_coefficients(&c_true);
    let d = model_data(&p, &q, 0.0, 0.0, W);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    let (c, _) = fit(&mut m, &d.signals(0.0), 0..W);
    // output coefficients and the dominant input terms to rounding level
    assert!(max_rel(&c[..3], &c_true[..3]) < 1e-9, "{:?}", &c[..3]);
    assert!(max_rel(&c[5..], &c_true[5..]) < 1e-7, "{:?}", &c[5..]);
    // D7 = Q0 contributes 3e-5 of the command over the window: relative
    // accuracy degrades accordingly but stays well below 1e-3
    assert!(max_rel(&c[3..5], &c_true[3..5]) < 1e-4, "{:?}", &c[3..5]);
}

#[test]
fn simplex_and_qr_agree_to_1e_6_relative_on_exact_model_polynomials() {
    let span = (W - 1) as f64 * DT;
    let mut cases = Vec::new();
    let (p, q) = balanced(span);
    cases.push((TimeOrigin::Motion, model_data(&p, &q, 0.0, 0.0, W)));
    cases.push((TimeOrigin::Window, model_data(&p, &q, 0.0, 0.0, W)));
    // window-local polynomial 50 ms into the motion
    cases.push((TimeOrigin::Window, model_data(&p, &q, 0.05, 0.05, W)));
    let (p, q) = balanced(0.004 + span);
    cases.push((TimeOrigin::Motion, model_data(&p, &q, 0.004, 0.0, W)));
    let c_rig = [
        4.10814e9, 1.60209e13, 6.63693e15, 1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7,
        2.71640e10, 2.55023e13, 6.63693e15,
    ];
    let (p, q) = polynomials_from_coefficients(&c_rig);
    cases.push((TimeOrigin::Motion, model_data(&p, &q, 0.0, 0.0, W)));
    for (k, (origin, d)) in cases.iter().enumerate() {
        let s = d.signals(0.0);
        let (c_qr, _) = fit(&mut method(Solver::Qr, *origin), &s, 0..W);
        let (c_nm, f) = fit(&mut method(Solver::Simplex, *origin), &s, 0..W);
        assert_eq!(
            f.status,
            FitStatus::Identified(Termination::Converged),
            "case {k}"
        );
        assert!(f.iterations > 0);
        let e = max_rel(&c_nm, &c_qr);
        assert!(
            e < 1e-6,
            "case {k}: max relative difference {e:e}\n{c_nm:?}\n{c_qr:?}"
        );
    }
}

#[test]
fn simplex_and_qr_predictions_agree_on_non_polynomial_data() {
    // a smooth non-polynomial motion: the fits are not exact, both solvers
    // must still find the same least-squares optimum
    let n = 200;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 1e-3 * (1.0 - (-40.0 * t).exp() * (1.0 + 40.0 * t)))
        .collect();
    let u: Vec<f64> = t
        .iter()
        .map(|&t| 1e-3 * (1.0 - (-60.0 * t).exp()))
        .collect();
    let d = Data { t, u, y };
    let s = d.signals(0.0);
    let mut qr = method(Solver::Qr, TimeOrigin::Motion);
    let mut nm = method(Solver::Simplex, TimeOrigin::Motion);
    for start in (0..n - W - H).step_by(H) {
        let win = start..start + W;
        let hor = start + W..start + W + H;
        let (_, fq) = fit(&mut qr, &s, win.clone());
        let (_, fs) = fit(&mut nm, &s, win.clone());
        assert!((fs.residual_rms - fq.residual_rms).abs() <= 1e-6 * fq.residual_rms + 1e-15);
        let mut pq = [0.0; H];
        let mut ps = [0.0; H];
        qr.predict(&s, win.clone(), hor.clone(), &mut pq).unwrap();
        nm.predict(&s, win, hor, &mut ps).unwrap();
        // the simplex resolves the optimum to the rounding level of the
        // sum of squares: agreement to 1e-6 of the data scale
        let scale = d.y[start..start + W]
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        for (a, b) in pq.iter().zip(&ps) {
            assert!((a - b).abs() < 1e-6 * scale, "window {start}: {a} vs {b}");
        }
    }
}

#[test]
fn polynomial_prediction_is_the_fitted_output_polynomial_continued() {
    let n = W + H;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    // not of the model form: the fit is approximate
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 2e-3 * (1.0 - (300.0 * t).cos()))
        .collect();
    let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
    let d = Data { t, u, y };
    let s = d.signals(0.0);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    let (c, f) = fit(&mut m, &s, 0..W);
    assert!(f.residual_rms > 0.0);
    let (p, _) = polynomials_from_coefficients(&c);
    let mut pred = [0.0; H];
    m.predict(&s, 0..W, W..n, &mut pred).unwrap();
    for (k, v) in pred.iter().enumerate() {
        let expected = eval_p(&p, d.t[W + k]);
        assert!(
            (v - expected).abs() < 1e-10 * expected.abs(),
            "{v} vs {expected}"
        );
    }
    // and on exact model data the continuation is the true continuation
    let (p, q) = balanced((W - 1) as f64 * DT);
    let d = model_data(&p, &q, 0.0, 0.0, n);
    let s = d.signals(0.0);
    fit(&mut m, &s, 0..W);
    m.predict(&s, 0..W, W..n, &mut pred).unwrap();
    for (k, v) in pred.iter().enumerate() {
        assert!((v - d.y[W + k]).abs() < 1e-12 * d.y[W + k].abs().max(1e-3));
    }
}

#[test]
fn fitted_polynomials_match_the_identified_coefficients() {
    let n = W + H;
    let t: Vec<f64> = (0..n).map(|k| 0.003 + k as f64 * DT).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 2e-3 * (1.0 - (300.0 * t).cos()))
        .collect();
    let u: Vec<f64> = t.iter().map(|&t| 1e-3 * (200.0 * t).sin()).collect();
    let d = Data { t, u, y };
    let s = d.signals(0.001);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    assert!(m.fitted_command(0.0).is_none());
    let (c, _) = fit(&mut m, &s, 0..W);
    let (p, q) = polynomials_from_coefficients(&c);
    for &t in &d.t {
        let tau = t - 0.001;
        let (fy, fu) = (m.fitted_position(t).unwrap(), m.fitted_command(t).unwrap());
        assert!(
            (fy - eval_p(&p, tau)).abs() < 1e-9 * 2e-3,
            "{fy} vs {}",
            eval_p(&p, tau)
        );
        assert!(
            (fu - eval_q(&q, tau)).abs() < 1e-9 * 1e-3,
            "{fu} vs {}",
            eval_q(&q, tau)
        );
    }
    // and the fits are least-squares fits: residual orthogonal to a constant
    let mean_res: f64 = (0..W)
        .map(|k| d.u[k] - m.fitted_command(d.t[k]).unwrap())
        .sum::<f64>();
    assert!(mean_res.abs() < 1e-15, "{mean_res}");
}

#[test]
fn window_local_time_origin_fits_polynomials_in_window_time() {
    let span = (W - 1) as f64 * DT;
    let (p, q) = balanced(span);
    let t0 = 0.0372;
    // data is a model polynomial in t − t0 (window-local time)
    let d = model_data(&p, &q, t0, t0, W + H);
    let s = d.signals(0.0);
    let mut local = method(Solver::Qr, TimeOrigin::Window);
    let (c, f) = fit(&mut local, &s, 0..W);
    let expected = coefficients_from_polynomials(p, q);
    assert!(max_rel(&c, &expected) < 1e-9, "{}", max_rel(&c, &expected));
    assert!(f.residual_rms < 1e-15);
    let mut pred = [0.0; H];
    local.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
    for (k, v) in pred.iter().enumerate() {
        assert!((v - d.y[W + k]).abs() < 1e-12 * d.y[W + k].abs());
    }
    // the motion-origin model cannot represent it (non-zero value at the window start)
    let mut motion = method(Solver::Qr, TimeOrigin::Motion);
    let (_, f) = fit(&mut motion, &s, 0..W);
    assert!(f.residual_rms > 1e-6, "{}", f.residual_rms);
}

#[test]
fn windows_far_from_the_origin_give_finite_coefficients_and_predictions() {
    // a 50 mm/s ramp observed 25 s after the motion start
    let t0 = 25.0;
    let n = W + H;
    let t: Vec<f64> = (0..n).map(|k| t0 + k as f64 * DT).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 0.05 * (t - 0.0714) + 1e-6 * (50.0 * t).sin())
        .collect();
    let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
    let d = Data { t, u, y };
    let s = d.signals(0.0);
    for solver in [Solver::Qr, Solver::Simplex] {
        let mut m = method(solver, TimeOrigin::Motion);
        let (c, f) = fit(&mut m, &s, 0..W);
        assert!(c.iter().all(|v| v.is_finite()), "{solver:?}: {c:?}");
        assert!(f.residual_rms.is_finite());
        let diag = m.diagnostics().unwrap();
        // the monomial coefficients are ill-conditioned and the diagnostics say so
        assert!(
            diag.shift_amplification > 1e20,
            "{}",
            diag.shift_amplification
        );
        let mut pred = [0.0; H];
        m.predict(&s, 0..W, W..n, &mut pred).unwrap();
        for (k, v) in pred.iter().enumerate() {
            assert!(v.is_finite());
            // the fitted family is locally smooth: a ramp is continued well
            assert!(
                (v - d.y[W + k]).abs() < 1e-5,
                "{solver:?} {k}: {v} vs {}",
                d.y[W + k]
            );
        }
    }
}

#[test]
fn worst_shift_amplification_matches_the_fit_diagnostics() {
    // windows 25 s after the motion start (the EMPS file's span)
    let n = 100;
    let t: Vec<f64> = (0..n).map(|k| 25.0 + k as f64 * DT).collect();
    let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
    let s = Signals::new(&t, &u, &u, DT, 0.0);
    let cfg = crate::ident::EngineConfig {
        window: W,
        horizon: H,
        ..Default::default()
    };
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    let mut coef = [0.0; NAMES.len()];
    // the last window is the farthest from the origin
    let (last, _) = cfg.windows(n, 0).last().unwrap();
    m.fit(&s, last, &mut coef).unwrap();
    let fitted = m.diagnostics().unwrap().shift_amplification;
    let worst = m.config.worst_shift_amplification(&s, &cfg);
    assert!((worst / fitted - 1.0).abs() < 1e-12, "{worst} vs {fitted}");
    assert!(worst > SHIFT_AMPLIFICATION_WARNING);
    // each window's own origin: (1 + 1)⁷
    let w = PaperConfig {
        time_origin: TimeOrigin::Window,
        ..PaperConfig::default()
    };
    assert!((w.worst_shift_amplification(&s, &cfg) - 128.0).abs() < 1e-9);
}

#[test]
fn window_straddling_the_motion_start_is_handled() {
    // rest before motion_start = 1 ms, then a model polynomial
    let (p, q) = balanced(0.004);
    let ms = 1e-3;
    let t: Vec<f64> = (0..W + H).map(|k| k as f64 * DT).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| if t < ms { 0.0 } else { eval_p(&p, t - ms) })
        .collect();
    let u: Vec<f64> = t
        .iter()
        .map(|&t| if t < ms { 0.0 } else { eval_q(&q, t - ms) })
        .collect();
    let d = Data { t, u, y };
    let s = d.signals(ms);
    for solver in [Solver::Qr, Solver::Simplex] {
        let mut m = method(solver, TimeOrigin::Motion);
        let (c, f) = fit(&mut m, &s, 0..W);
        assert!(c.iter().all(|v| v.is_finite()) && f.residual_rms.is_finite());
        let mut pred = [0.0; H];
        m.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
        assert!(pred.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn zero_data_gives_zero_coefficients() {
    let d = Data {
        t: (0..W + H).map(|k| k as f64 * DT).collect(),
        u: vec![0.0; W + H],
        y: vec![0.0; W + H],
    };
    for solver in [Solver::Qr, Solver::Simplex] {
        let mut m = method(solver, TimeOrigin::Motion);
        let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
        assert!(c.iter().all(|v| *v == 0.0), "{c:?}");
        assert_eq!(f.residual_rms, 0.0);
    }
}

#[test]
fn windows_ending_at_or_before_the_motion_start_are_rest_windows() {
    let (p, q) = balanced(0.004);
    let mut d = model_data(&p, &q, 0.0, 0.0, W + H);
    d.y.iter_mut().for_each(|y| *y += 1e-3);
    let last = d.y[W - 1];
    for (ms, rest) in [
        (f64::INFINITY, true),
        (d.t[W - 1], true),
        (d.t[W - 1] + 1e-9, true),
        (d.t[W - 2], false),
    ] {
        for solver in [Solver::Qr, Solver::Simplex] {
            let mut m = method(solver, TimeOrigin::Motion);
            let mut c = [1.0; 11];
            let s = d.signals(ms);
            let f = m.fit(&s, 0..W, &mut c).unwrap();
            let mut pred = [0.0; H];
            m.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
            if rest {
                assert_eq!(f.status, FitStatus::Fallback);
                assert_eq!(c, [0.0; 11]);
                assert!(pred.iter().all(|&v| v == last), "{pred:?}");
                assert!(m.fitted_position(d.t[0]).is_none());
            } else {
                assert_ne!(f.status, FitStatus::Fallback);
                assert!(c.iter().any(|&v| v != 0.0));
                assert!(pred.iter().all(|&v| v != last));
            }
        }
    }
    // the window-local origin ignores the motion start
    let mut m = method(Solver::Qr, TimeOrigin::Window);
    let f = m
        .fit(&d.signals(f64::INFINITY), 0..W, &mut [0.0; 11])
        .unwrap();
    assert_eq!(f.status, FitStatus::Identified(Termination::Exact));
}

#[test]
fn only_the_polynomial_prediction_does_without_the_future_command() {
    assert!(!method(Solver::Qr, TimeOrigin::Motion).uses_future_command());
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    m.config.prediction = PredictionMode::TransferFunction;
    assert!(m.uses_future_command());
}

#[test]
fn buffers_are_not_regrown_for_windows_of_the_same_size() {
    let (p, q) = balanced(0.004);
    let d = model_data(&p, &q, 0.0, 0.0, 100);
    let s = d.signals(0.0);
    let mut m = method(Solver::Simplex, TimeOrigin::Motion);
    fit(&mut m, &s, 0..W);
    let ptrs = (m.tau.as_ptr(), m.data.as_ptr(), m.work.as_ptr(), m.cap);
    for start in (10..80).step_by(10) {
        fit(&mut m, &s, start..start + W);
        assert_eq!(
            ptrs,
            (m.tau.as_ptr(), m.data.as_ptr(), m.work.as_ptr(), m.cap)
        );
    }
    // a longer window grows once
    fit(&mut m, &s, 0..2 * W);
    assert_eq!(m.cap, 2 * W);
}

#[test]
fn simplex_cap_is_reported_as_max_iterations() {
    let (p, q) = balanced(0.004);
    let d = model_data(&p, &q, 0.0, 0.0, W);
    let mut m = PaperConfig {
        solver: Solver::Simplex,
        simplex: SimplexSettings {
            max_iterations: 5,
            ..SimplexSettings::default()
        },
        ..PaperConfig::default()
    }
    .build()
    .unwrap();
    let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
    assert_eq!(f.status, FitStatus::Identified(Termination::MaxIterations));
    assert_eq!(f.iterations, 10);
    assert!(c.iter().all(|v| v.is_finite()));
}

#[test]
fn estimator_metadata_and_errors() {
    let m = method(Solver::Qr, TimeOrigin::Motion);
    assert_eq!(m.name(), "paper");
    assert_eq!(
        m.coefficient_names(),
        ["N2", "N1", "N0", "D7", "D6", "D5", "D4", "D3", "D2", "D1", "D0"]
    );
    let (p, q) = balanced(0.004);
    let mut d = model_data(&p, &q, 0.0, 0.0, W + H);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    let mut c = [0.0; 11];
    let mut out = [0.0; H];
    assert!(matches!(
        m.predict(&d.signals(0.0), 0..W, W..W + H, &mut out),
        Err(Error::InvalidModel { .. })
    ));
    assert!(matches!(
        m.fit(&d.signals(0.0), 0..7, &mut c),
        Err(Error::TooFewSamples { .. })
    ));
    assert!(matches!(
        m.fit(&d.signals(0.0), 25..45, &mut c),
        Err(Error::TooFewSamples { .. })
    ));
    assert!(matches!(
        m.fit(&d.signals(0.0), 0..W, &mut c[..10]),
        Err(Error::LengthMismatch { .. })
    ));
    d.y[3] = f64::NAN;
    assert!(matches!(
        m.fit(&d.signals(0.0), 0..W, &mut c),
        Err(Error::NonFinite { index: 3, .. })
    ));
    assert_eq!(
        "tf".parse::<PredictionMode>().unwrap(),
        PredictionMode::TransferFunction
    );
    let bad = PaperConfig {
        simplex: SimplexSettings {
            step_rel: 0.0,
            ..SimplexSettings::default()
        },
        ..PaperConfig::default()
    };
    assert!(matches!(bad.build(), Err(Error::InvalidParameter { .. })));
    assert_eq!("simplex".parse::<Solver>().unwrap(), Solver::Simplex);
    assert_eq!("window".parse::<TimeOrigin>().unwrap(), TimeOrigin::Window);
    assert!("lsq".parse::<Solver>().is_err());
}

#[test]
fn rest_windows_hold_the_last_position_and_report_fallback() {
    let n = 60;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    let y = vec![0.25; n];
    let u = vec![0.25; n];
    let d = Data { t, u, y };
    // motion starts after the data: every window is a rest window
    let s = d.signals(f64::INFINITY);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    let (c, f) = fit(&mut m, &s, 0..W);
    assert_eq!(f.status, FitStatus::Fallback);
    assert!(c.iter().all(|&v| v == 0.0));
    let mut pred = vec![0.0; H];
    m.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
    assert!(pred.iter().all(|&v| v == 0.25));
}

#[test]
fn rest_position_offset_does_not_change_the_prediction() {
    // The same motion measured from 0 and from a rest position of 0.1 m.
    let span = (W - 1) as f64 * DT;
    let (p, q) = balanced(span + 0.004);
    let rest = 10;
    let n = rest + W + H;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    let t_m = t[rest - 1];
    let shape = |tt: f64| if tt <= t_m { 0.0 } else { eval_p(&p, tt - t_m) };
    let y0: Vec<f64> = t.iter().map(|&tt| shape(tt)).collect();
    let y1: Vec<f64> = y0.iter().map(|v| v + 0.1).collect();
    let u: Vec<f64> = t
        .iter()
        .map(|&tt| eval_q(&q, (tt - t_m).max(0.0)))
        .collect();
    let mut preds = Vec::new();
    for y in [y0, y1] {
        let d = Data {
            t: t.clone(),
            u: u.clone(),
            y,
        };
        let s = d.signals(t_m);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let w = rest..rest + W;
        fit(&mut m, &s, w.clone());
        let mut pred = vec![0.0; H];
        m.predict(&s, w, rest + W..n, &mut pred).unwrap();
        preds.push(pred);
    }
    for (a, b) in preds[0].iter().zip(&preds[1]) {
        assert!((b - a - 0.1).abs() < 1e-12, "{a} {b}");
    }
}

#[test]
fn reset_forgets_the_last_fit() {
    let (p, q) = balanced(0.004);
    let d = model_data(&p, &q, 0.0, 0.0, W + H);
    let mut m = method(Solver::Qr, TimeOrigin::Motion);
    fit(&mut m, &d.signals(0.0), 0..W);
    m.reset();
    let mut out = [0.0; H];
    assert!(m
        .predict(&d.signals(0.0), 0..W, W..W + H, &mut out)
        .is_err());
    assert!(m.diagnostics().is_none());
}

#[test]
fn signals_with_offset_are_indexed_absolutely() {
    let (p, q) = balanced(0.004);
    let d = model_data(&p, &q, 0.0, 0.0, 60);
    let full = d.signals(0.0);
    let view = Signals::with_offset(30, &d.t[30..], &d.u[30..], &d.y[30..], DT, 0.0);
    let mut a = method(Solver::Qr, TimeOrigin::Motion);
    let mut b = method(Solver::Qr, TimeOrigin::Motion);
    let (ca, _) = fit(&mut a, &full, 35..55);
    let (cb, _) = fit(&mut b, &view, 35..55);
    assert_eq!(ca, cb);
}

#[test]
fn sliding_engine_runs_the_paper_method_on_a_lagged_ramp_without_nan() {
    use crate::ident::engine::EngineConfig;
    // 50 mm/s ramp through a first-order lag 1/Kv (Kv = 700 1/s): the
    // following error settles at v/Kv = 71.4 µm
    let (v, tl) = (0.05, 1.0 / 700.0);
    let n = 600;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    let u: Vec<f64> = t.iter().map(|&t| v * t).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| v * (t - tl * (1.0 - (-t / tl).exp())))
        .collect();
    let s = Signals::new(&t, &u, &y, DT, 0.0);
    let mut qr = method(Solver::Qr, TimeOrigin::Motion);
    let rq = crate::ident::engine::run_as_made(&mut qr, &s, &EngineConfig::default()).unwrap();
    assert!(rq
        .windows
        .iter()
        .all(|w| w.outcome == WindowOutcome::Predicted(Termination::Exact)));
    assert!(rq.stats.samples > 500);
    assert!(rq.stats.rms.is_finite() && rq.stats.max_abs.is_finite());
    // independent reference (NumPy lstsq on t⁵, t⁶, t⁷ over samples 0..20,
    // extrapolated to 20..30): residual rms 7.71355e-6 m and a horizon
    // error of 9.56182e-3 m — the t⁵…t⁷ model cannot follow the start
    // of a lagged ramp, and its extrapolation blows up (docs/METHODS.md §4)
    let w0 = &rq.windows[0];
    let e0 = w0
        .horizon
        .clone()
        .map(|k| (rq.predicted[k] - y[k]).abs())
        .fold(0.0, f64::max);
    assert!(
        (w0.residual_rms / 7.713548e-6 - 1.0).abs() < 1e-5,
        "{}",
        w0.residual_rms
    );
    assert!((e0 / 9.5618237e-3 - 1.0).abs() < 1e-6, "{e0}");
    // once the motion is established the continuation improves steadily
    let last = rq.windows.last().unwrap();
    let el = last
        .horizon
        .clone()
        .map(|k| (rq.predicted[k] - y[k]).abs())
        .fold(0.0, f64::max);
    assert!(el < 5e-6, "{el}");
    let mut nm = method(Solver::Simplex, TimeOrigin::Motion);
    let rs = crate::ident::engine::run_as_made(&mut nm, &s, &EngineConfig::default()).unwrap();
    assert!(rs
        .windows
        .iter()
        .all(|w| w.outcome == WindowOutcome::Predicted(Termination::Converged)));
    for k in 0..n {
        assert_eq!(rq.has_prediction[k], rs.has_prediction[k]);
        if rq.has_prediction[k] {
            assert!(
                (rq.predicted[k] - rs.predicted[k]).abs() < 1e-6 * y[n - 1],
                "sample {k}"
            );
        }
    }
}

/// Rig data: exact model polynomials of the default rig's `N`, `D` over `n` samples.
fn rig_data(n: usize) -> ([f64; 11], Data) {
    use crate::drive::{closed_loop_coefficients, D1Variant, RigParams};
    let cl = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
    let mut c = [0.0; 11];
    c[..3].copy_from_slice(&cl.num);
    c[3..].copy_from_slice(&cl.den);
    let (p, q) = polynomials_from_coefficients(&c);
    (c, model_data(&p, &q, 0.0, 0.0, n))
}

fn tf_method() -> PaperMethod {
    PaperConfig {
        prediction: PredictionMode::TransferFunction,
        ..PaperConfig::default()
    }
    .build()
    .unwrap()
}

#[test]
fn transfer_function_prediction_equals_polynomial_when_the_command_follows_the_fit() {
    let (_, d) = rig_data(W + H);
    let s = d.signals(0.0);
    let mut poly = method(Solver::Qr, TimeOrigin::Motion);
    let mut tf = tf_method();
    fit(&mut poly, &s, 0..W);
    fit(&mut tf, &s, 0..W);
    let (mut a, mut b) = ([0.0; H], [0.0; H]);
    poly.predict(&s, 0..W, W..W + H, &mut a).unwrap();
    tf.predict(&s, 0..W, W..W + H, &mut b).unwrap();
    assert_eq!(tf.tf_fallbacks(), 0);
    assert!(!tf.diagnostics().unwrap().tf_fallback);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-9 * x.abs(), "{x} vs {y}");
    }
}

#[test]
fn transfer_function_prediction_adds_the_step_response_to_a_command_deviation() {
    use crate::drive::{closed_loop_state_space, RigParams};
    let (_, mut d) = rig_data(W + H);
    // the actual command leaves the fitted polynomial by a 1 µm step at the horizon start
    let delta = 1e-6;
    for k in W..W + H {
        d.u[k] += delta;
    }
    let s = d.signals(0.0);
    let mut poly = method(Solver::Qr, TimeOrigin::Motion);
    let mut tf = tf_method();
    fit(&mut poly, &s, 0..W);
    fit(&mut tf, &s, 0..W);
    let (mut a, mut b) = ([0.0; H], [0.0; H]);
    poly.predict(&s, 0..W, W..W + H, &mut a).unwrap();
    tf.predict(&s, 0..W, W..W + H, &mut b).unwrap();
    assert_eq!(tf.tf_fallbacks(), 0);
    // reference: step response of the physical 7-state model of the rig
    let step = closed_loop_state_space(&RigParams::default())
        .unwrap()
        .step_response(DT, H)
        .unwrap();
    assert!(
        step[H - 1] > 0.05,
        "the step response must be visible: {}",
        step[H - 1]
    );
    for k in 0..H {
        let added = b[k] - a[k];
        assert!(
            (added - delta * step[k]).abs() < 1e-4 * delta,
            "sample {k}: {added:e} vs {:e}",
            delta * step[k]
        );
    }
}

#[test]
fn unstable_identified_transfer_function_falls_back_to_the_polynomial() {
    // balanced polynomials with mixed-sign D coefficients: not Hurwitz
    let (p, q) = balanced((W - 1) as f64 * DT);
    let mut d = model_data(&p, &q, 0.0, 0.0, W + H);
    for k in W..W + H {
        d.u[k] += 1e-4;
    }
    let s = d.signals(0.0);
    let mut poly = method(Solver::Qr, TimeOrigin::Motion);
    let mut tf = tf_method();
    let (c, _) = fit(&mut tf, &s, 0..W);
    assert!(c[3..].iter().any(|v| *v < 0.0) && c[3..].iter().any(|v| *v > 0.0));
    fit(&mut poly, &s, 0..W);
    let (mut a, mut b) = ([0.0; H], [0.0; H]);
    poly.predict(&s, 0..W, W..W + H, &mut a).unwrap();
    tf.predict(&s, 0..W, W..W + H, &mut b).unwrap();
    assert_eq!(a, b);
    assert!(b.iter().all(|v| v.is_finite()));
    assert_eq!(tf.tf_fallbacks(), 1);
    assert!(tf.diagnostics().unwrap().tf_fallback);
    tf.reset();
    assert_eq!(tf.tf_fallbacks(), 0);
}

#[test]
fn transfer_function_mode_runs_in_the_engine_without_nan() {
    use crate::ident::engine::{run, EngineConfig};
    let (v, tl) = (0.05, 1.0 / 700.0);
    let n = 400;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
    let u: Vec<f64> = t.iter().map(|&t| v * t).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| v * (t - tl * (1.0 - (-t / tl).exp())))
        .collect();
    let s = Signals::new(&t, &u, &y, DT, 0.0);
    let mut tf = tf_method();
    let r = run(&mut tf, &s, &EngineConfig::default()).unwrap();
    assert!(r.stats.samples > 300);
    assert!(r.stats.rms.is_finite() && r.stats.max_abs.is_finite());
    assert!(r
        .predicted
        .iter()
        .zip(&r.has_prediction)
        .all(|(p, h)| !h || p.is_finite()));
}

/// The direct fit of one window as the method computed it before the
/// cached projection (the test oracle): bases on the window's own grid,
/// unit-norm columns, pivoted Householder QR of the `W×3` and `W×8`
/// problems. Returns the prediction of the horizon `[e, e+h)` (motion or
/// window origin, polynomial mode) and the output residual rms.
fn direct_fit(
    origin: TimeOrigin,
    s: &Signals<'_>,
    window: Range<usize>,
    h: usize,
) -> Option<(Vec<f64>, f64)> {
    use crate::solve::{lstsq_in_place, LstsqOptions, QrWorkspace};
    let w = window.len();
    let all = s.all();
    let time = &all.time[window.clone()];
    let pos = &all.position[window.clone()];
    let (o, y_ref) = match origin {
        TimeOrigin::Motion => {
            let ms = s.motion_start();
            if time[w - 1] <= ms {
                return None;
            }
            let y_ref = all
                .time
                .iter()
                .rposition(|&t| t <= ms)
                .map_or(0.0, |k| all.position[k]);
            (ms, y_ref)
        }
        TimeOrigin::Window => (time[0], 0.0),
    };
    let tau: Vec<f64> = time.iter().map(|t| t - o).collect();
    let (t_first, t_last) = (tau[0], tau[w - 1]);
    let centre = 0.5 * (t_first + t_last);
    let half = 0.5 * (t_last - t_first);
    let t_scale = tau.iter().fold(0.0f64, |a, t| a.max(t.abs()));
    let mut g = vec![0.0; NP * w];
    for i in 0..w {
        let sv = (tau[i] - centre) / half;
        let wt = (tau[i] / t_scale).powi(5);
        let (mut lm1, mut l) = (1.0, sv);
        let mut leg = [0.0; NQ];
        leg[0] = 1.0;
        leg[1] = sv;
        for k in 1..NQ - 1 {
            let next = LEGENDRE_A[k] * sv * l - LEGENDRE_B[k] * lm1;
            lm1 = l;
            l = next;
            leg[k + 1] = l;
        }
        for k in 0..NP {
            g[i + k * w] = wt * leg[k];
        }
    }
    let mut norms = [0.0; NP];
    for k in 0..NP {
        norms[k] = normalise(&mut g[k * w..(k + 1) * w]);
    }
    let mut b: Vec<f64> = pos.iter().map(|p| p - y_ref).collect();
    let mut z = [0.0; NP];
    let info = lstsq_in_place(
        w,
        NP,
        &mut g,
        &mut b,
        &mut z,
        &mut QrWorkspace::new(NQ),
        &LstsqOptions::default(),
    )
    .ok()?;
    let times = &all.time[window.end..window.end + h];
    let pred = times
        .iter()
        .map(|&t| {
            let tau = t - o;
            let sv = (tau - centre) / half;
            let l2 = 1.5 * sv * sv - 0.5;
            y_ref
                + (tau / t_scale).powi(5)
                    * (z[0] / norms[0] + z[1] / norms[1] * sv + z[2] / norms[2] * l2)
        })
        .collect();
    Some((pred, info.residual_norm / (w as f64).sqrt()))
}

/// A named recording: (name, time, command, position, motion start).
type Named = (&'static str, Vec<f64>, Vec<f64>, Vec<f64>, f64);

/// The rig's ramp and step (every effect on, seed 3) at 5 kHz, and a
/// seeded random smooth motion far from the motion start.
fn oracle_recordings() -> Vec<Named> {
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;
    use rand::{Rng, SeedableRng};
    let mut out = vec![];
    for (name, scenario, seconds) in [("ramp", Scenario::Ramp, 0.8), ("step", Scenario::Step, 0.1)]
    {
        let command = scenario.command(5000.0, seconds, 3).unwrap();
        let r = VirtualRig::new(RigParams::default())
            .with_seed(3)
            .simulate(&command, 5000.0)
            .unwrap();
        let ms = crate::Recording::new(r.time.clone(), r.command.clone(), r.position.clone())
            .unwrap()
            .motion_start_time();
        out.push((name, r.time, r.command, r.position, ms));
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let n = 3000;
    let (mut y, mut v) = (0.1, 0.0);
    let mut t = vec![0.0; n];
    let mut u = vec![0.0; n];
    let mut p = vec![0.0; n];
    for k in 0..n {
        t[k] = 7.0 + k as f64 * DT; // far from the motion start at 0
        v = 0.99 * v + 1e-3 * rng.random_range(-1.0..1.0);
        y += v * DT;
        u[k] = y + 1e-4 * v;
        p[k] = y + 1e-8 * rng.random_range(-1.0..1.0);
    }
    out.push(("random", t, u, p, 0.0));
    out
}

#[test]
fn cached_projection_predicts_like_the_direct_fit_on_rig_and_random_data() {
    for (name, t, u, y, ms) in oracle_recordings() {
        let s = Signals::new(&t, &u, &y, DT, ms);
        let range = y.iter().fold(f64::NEG_INFINITY, |a, &v| a.max(v))
            - y.iter().fold(f64::INFINITY, |a, &v| a.min(v));
        for origin in [TimeOrigin::Motion, TimeOrigin::Window] {
            let mut m = method(Solver::Qr, origin);
            let (mut worst, mut worst_rms, mut compared) = (0.0f64, 0.0f64, 0);
            let mut pred = [0.0; H];
            for start in (0..t.len() - W - H).step_by(H) {
                let win = start..start + W;
                let (_, f) = fit(&mut m, &s, win.clone());
                m.predict(&s, win.clone(), win.end..win.end + H, &mut pred)
                    .unwrap();
                let Some((want, rms)) = direct_fit(origin, &s, win, H) else {
                    continue;
                };
                // relative to the signal range, or to the prediction where the
                // model runs away from the data (the window origin cannot
                // represent positions that do not start at 0 in the window:
                // it extrapolates the random motion to metres)
                for (a, b) in pred.iter().zip(&want) {
                    worst = worst.max((a - b).abs() / range.max(b.abs()));
                }
                worst_rms = worst_rms.max((f.residual_rms - rms).abs() / range);
                compared += 1;
            }
            assert!(compared > 5, "{name} {origin:?}: {compared}");
            assert!(
                worst < 1e-9 && worst_rms < 1e-9,
                "{name} {origin:?}: predictions {worst:e}, residual rms {worst_rms:e} of the range"
            );
            // a uniform grid is projected once per window length
            assert!(
                m.projection.builds <= 2,
                "{name}: {} builds",
                m.projection.builds
            );
        }
    }
}

#[test]
fn jittered_time_grids_rebuild_the_projection_and_still_match_the_direct_fit() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    let n = 400;
    let t: Vec<f64> = (0..n)
        .map(|k| k as f64 * DT + 0.05 * DT * rng.random_range(-1.0..1.0))
        .collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 1e-3 * (30.0 * t).sin() + 1e-3 * t)
        .collect();
    let u: Vec<f64> = t.iter().map(|&t| 1e-3 * (30.0 * t).sin()).collect();
    let s = Signals::new(&t, &u, &y, DT, 0.0);
    let mut m = method(Solver::Qr, TimeOrigin::Window);
    let mut pred = [0.0; H];
    let mut windows = 0;
    for start in (0..n - W - H).step_by(H) {
        let win = start..start + W;
        fit(&mut m, &s, win.clone());
        m.predict(&s, win.clone(), win.end..win.end + H, &mut pred)
            .unwrap();
        let (want, _) = direct_fit(TimeOrigin::Window, &s, win, H).unwrap();
        for (a, b) in pred.iter().zip(&want) {
            assert!((a - b).abs() < 1e-12, "window {start}: {a} vs {b}");
        }
        windows += 1;
    }
    assert_eq!(m.projection.builds, windows);
}

#[test]
fn simplex_from_the_previous_window_agrees_with_qr_in_fewer_iterations() {
    for (name, t, u, y, ms) in oracle_recordings() {
        let s = Signals::new(&t, &u, &y, DT, ms);
        let mut qr = method(Solver::Qr, TimeOrigin::Motion);
        let mut zeros = method(Solver::Simplex, TimeOrigin::Motion);
        let mut prev = PaperConfig {
            solver: Solver::Simplex,
            simplex_start: SimplexStart::Previous,
            ..PaperConfig::default()
        }
        .build()
        .unwrap();
        let (mut it_zeros, mut it_prev, mut compared) = (0, 0, 0);
        let (mut pq, mut pz, mut pp) = ([0.0; H], [0.0; H], [0.0; H]);
        let last = (t.len() - W - H).min(1200);
        for start in (0..last).step_by(H) {
            let win = start..start + W;
            let hor = win.end..win.end + H;
            fit(&mut qr, &s, win.clone());
            let (_, fz) = fit(&mut zeros, &s, win.clone());
            let (_, fp) = fit(&mut prev, &s, win.clone());
            qr.predict(&s, win.clone(), hor.clone(), &mut pq).unwrap();
            zeros
                .predict(&s, win.clone(), hor.clone(), &mut pz)
                .unwrap();
            prev.predict(&s, win.clone(), hor, &mut pp).unwrap();
            if fz.iterations == 0 {
                continue; // rest window
            }
            assert_eq!(fp.status, FitStatus::Identified(Termination::Converged));
            let scale = y[win].iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for ((a, b), c) in pq.iter().zip(&pz).zip(&pp) {
                assert!((a - b).abs() < 1e-6 * scale, "{name} {start}: {a} vs {b}");
                assert!((a - c).abs() < 1e-6 * scale, "{name} {start}: {a} vs {c}");
            }
            it_zeros += fz.iterations;
            it_prev += fp.iterations;
            compared += 1;
        }
        assert!(compared > 5, "{name}");
        assert!(
            it_prev < it_zeros,
            "{name}: {it_prev} iterations from the previous window, {it_zeros} from zeros"
        );
    }
}
