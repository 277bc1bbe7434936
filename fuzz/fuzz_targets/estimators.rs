//! Every estimator on arbitrary `f64` sequences through the batch engine and
//! the streaming path: never panics; every prediction is finite.
//!
//! Layout of the input: byte 0 the method (and orders), byte 1 the window,
//! byte 2 the horizon, byte 3 the hop, byte 4 options; then pairs (command,
//! position) of little-endian `f64` or, with option bit 6, of `i16` µm.
//! Every value goes to the streaming path as it is (non-finite ones must be
//! refused per sample, huge ones must not give non-finite predictions); for
//! the batch path values a `Recording` refuses are replaced by 0.
#![no_main]

use feedid::ident::engine::{run, EngineConfig};
use feedid::ident::{
    ArxOrders, Method, PaperConfig, PredictionMode, Solver, Streamer, TimeOrigin,
};
use feedid::Recording;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if data.len() < 5 {
        return;
    }
    let (head, body) = data.split_at(5);
    let opt = head[4];
    let paper = PaperConfig {
        time_origin: if opt & 1 != 0 {
            TimeOrigin::Window
        } else {
            TimeOrigin::Motion
        },
        prediction: if opt & 2 != 0 {
            PredictionMode::TransferFunction
        } else {
            PredictionMode::Polynomial
        },
        solver: if opt & 4 != 0 {
            Solver::Simplex
        } else {
            Solver::Qr
        },
        ..PaperConfig::default()
    };
    let mut spec = match head[0] & 3 {
        0 => Method::Paper(paper),
        1 => Method::Arx(Default::default()),
        2 => Method::Rls(Default::default()),
        _ => Method::Oe(Default::default()),
    };
    if opt & 8 != 0 && spec.orders().is_some() {
        let orders = ArxOrders::new(
            usize::from(head[0] >> 4) % 5 + 1,
            usize::from(head[0] >> 2) % 5 + 1,
            usize::from(opt >> 6),
        );
        if spec.set_orders(orders).is_err() {
            return;
        }
    }
    let is_oe = matches!(spec, Method::Oe(_));
    let max_window = if is_oe { 32 } else { 256 };
    let cfg = EngineConfig {
        window: usize::from(head[1]) % max_window + 1,
        horizon: usize::from(head[2]) % 32 + 1,
        hop: Some(usize::from(head[3]) % 32 + 1),
        warm_up: 0,
    };
    // Samples: raw little-endian f64 pairs (any bit pattern), or with
    // option bit 6 pairs of i16 in µm (signals a rig could give).
    let (mut u, mut y) = (Vec::new(), Vec::new());
    if opt & 64 == 0 {
        for c in body.chunks_exact(16) {
            let mut a = [0u8; 8];
            a.copy_from_slice(&c[..8]);
            u.push(f64::from_le_bytes(a));
            a.copy_from_slice(&c[8..]);
            y.push(f64::from_le_bytes(a));
        }
    } else {
        for c in body.chunks_exact(4) {
            u.push(f64::from(i16::from_le_bytes([c[0], c[1]])) * 1e-6);
            y.push(f64::from(i16::from_le_bytes([c[2], c[3]])) * 1e-6);
        }
    }
    // Bound the work per input (the simplex and OE iterate per window):
    // a few hundred samples reach every code path.
    let cap = match &spec {
        Method::Oe(_) => 80,
        Method::Paper(p) if p.solver == Solver::Simplex => 120,
        _ => 200,
    };
    u.truncate(cap);
    y.truncate(cap);
    let n = u.len();
    // Some inputs as magnitudes users meet (metres): scale by 1e-3 when asked.
    if opt & 16 != 0 {
        u.iter_mut().chain(y.iter_mut()).for_each(|v| *v *= 1e-3);
    }
    let dt = 2e-4;
    // Absolute time far from zero (as in the EMPS file) when asked.
    let t0 = if opt & 32 != 0 { 25.0 } else { 0.0 };

    // Streaming: raw values, one sample at a time.
    if let Ok(est) = spec.build() {
        if let Ok(mut s) = Streamer::new(est, cfg) {
            for k in 0..n {
                if s.push(t0 + k as f64 * dt, u[k], y[k]).is_ok() {
                    while let Ok(Some(p)) = s.poll() {
                        assert!(
                            p.position.iter().all(|v| v.is_finite()),
                            "stream prediction"
                        );
                    }
                }
            }
            s.finish();
            while let Ok(Some(p)) = s.poll() {
                assert!(
                    p.position.iter().all(|v| v.is_finite()),
                    "stream prediction"
                );
            }
        }
    }

    // Batch: a checked recording (values it refuses replaced by 0).
    let clean = |v: &mut Vec<f64>| {
        v.iter_mut()
            .filter(|x| !feedid::recording::is_usable(**x))
            .for_each(|x| *x = 0.0)
    };
    clean(&mut u);
    clean(&mut y);
    let time: Vec<f64> = (0..n).map(|k| t0 + k as f64 * dt).collect();
    let Ok(rec) = Recording::new(time, u, y) else {
        return;
    };
    let Ok(mut est) = spec.build() else {
        return;
    };
    if let Ok(res) = run(est.as_mut(), &rec.signals(), &cfg) {
        for k in 0..rec.len() {
            if let Some(p) = res.prediction(k) {
                assert!(p.is_finite(), "batch prediction {k}: {p}");
            }
        }
    }
});
