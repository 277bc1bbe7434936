//! Benchmark: `feedid stream`'s path for one line of text — read and parse
//! it ([`StreamReader`]), push it ([`Streamer::push`]), process the window it
//! completes ([`Streamer::poll`]), write the prediction's rows and flush them
//! ([`PredictionRows`], to `/dev/null` through a `BufWriter`, as the CLI
//! writes to standard output) — on 10 s of the virtual rig's chirp at 5 kHz
//! (`time_s,command_m,position_m` text).
//!
//! - `latency/*`: the time from reading a line that completes a window to
//!   flushing its prediction (only such lines are timed; criterion's time is
//!   per completing line). A histogram of single lines is printed too
//!   (median, 90th and 99th percentile, max).
//! - `throughput/*`: every line of one second, all the way; criterion's
//!   "elements" are lines, so real time is 5000 lines/s.
//!
//! ```text
//! cargo bench -p feedid --bench stream_line
//! ```

use std::fs::File;
use std::io::{BufWriter, Cursor, Write};
use std::time::{Duration, Instant};

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::stream::{StreamOptions, Streamer};
use feedid::ident::{EngineConfig, Estimator, Method};
use feedid::io::{PredictionRows, ReadOptions, StreamLine, StreamReader};
use feedid::signal::Scenario;

const RATE: f64 = 5000.0;

/// The recording as text lines with the command `lead` lines ahead.
fn text(seconds: f64, lead: usize) -> Vec<u8> {
    let command = Scenario::Chirp
        .command(RATE, seconds, 1)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&command, RATE)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut s = String::from("time_s,command_m,position_m\n");
    for k in 0..out.len() - lead {
        s += &format!(
            "{},{},{}\n",
            out.time[k],
            out.command[k + lead],
            out.position[k]
        );
    }
    s.into_bytes()
}

/// One stream: reader, streamer, writer.
struct Pipe {
    reader: StreamReader<Cursor<Vec<u8>>>,
    streamer: Streamer<Box<dyn Estimator + Send>>,
    rows: PredictionRows<BufWriter<File>>,
}

fn pipe(method: &str, lead: usize, text: &[u8]) -> Pipe {
    let m: Method = method.parse().unwrap_or_else(|e| panic!("{e}"));
    let cfg = EngineConfig {
        window: m.default_window(),
        ..EngineConfig::default()
    };
    let opts = StreamOptions {
        command_lead: lead,
        ..StreamOptions::default()
    };
    let streamer = Streamer::with_options(m.build().unwrap_or_else(|e| panic!("{e}")), cfg, opts)
        .unwrap_or_else(|e| panic!("{e}"));
    let reader = StreamReader::new(
        Cursor::new(text.to_vec()),
        "bench".as_ref(),
        &ReadOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let null = File::create("/dev/null").unwrap_or_else(|e| panic!("{e}"));
    let mut rows = PredictionRows::new(BufWriter::new(null));
    rows.header().unwrap_or_else(|e| panic!("{e}"));
    Pipe {
        reader,
        streamer,
        rows,
    }
}

impl Pipe {
    /// Process the next line; `None` at the end, else whether it completed a window.
    fn line(&mut self) -> Option<bool> {
        let l = self.reader.next_line().unwrap_or_else(|e| panic!("{e}"))?;
        let StreamLine::Sample {
            time,
            command,
            position,
            ..
        } = l
        else {
            return Some(false);
        };
        self.streamer
            .push(time, command, position)
            .unwrap_or_else(|e| panic!("{e}"));
        let mut completed = false;
        while let Some(p) = self.streamer.poll().unwrap_or_else(|e| panic!("{e}")) {
            completed = true;
            if p.is_ok() {
                self.rows
                    .write(p.time, p.position, p.lower, p.upper)
                    .unwrap_or_else(|e| panic!("{e}"));
            }
        }
        Some(completed)
    }
}

/// The CLI's settings benchmarked: (name, method, command lead).
const CASES: [(&str, &str, usize); 3] = [
    ("auto", "auto", 0),
    ("auto_lead10", "auto", 10),
    ("paper", "paper", 0),
];

fn latency(c: &mut Criterion) {
    let mut g = c.benchmark_group("latency");
    for (name, method, lead) in CASES {
        let text = text(10.0, lead);
        let mut p = pipe(method, lead, &text);
        // a histogram of single completing lines over the whole recording
        let mut single = Vec::new();
        loop {
            let t0 = Instant::now();
            match p.line() {
                None => break,
                Some(true) => single.push(t0.elapsed()),
                Some(false) => {}
            }
        }
        single.sort();
        let q = |f: f64| single[((single.len() - 1) as f64 * f) as usize];
        eprintln!(
            "latency/{name}: {} completing lines: median {:?}, p90 {:?}, p99 {:?}, max {:?}",
            single.len(),
            q(0.5),
            q(0.9),
            q(0.99),
            single[single.len() - 1]
        );
        let mut p = pipe(method, lead, &text);
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut done = 0;
                while done < iters {
                    let t0 = Instant::now();
                    match p.line() {
                        Some(true) => {
                            total += t0.elapsed();
                            done += 1;
                        }
                        Some(false) => {}
                        // the end of the text: start again (the warm-up is not timed)
                        None => p = pipe(method, lead, &text),
                    }
                }
                total
            })
        });
    }
    g.finish();
}

fn throughput(c: &mut Criterion) {
    let mut g = c.benchmark_group("throughput");
    for (name, method, lead) in CASES {
        let text = text(1.0, lead);
        let lines = text.iter().filter(|&&b| b == b'\n').count();
        g.throughput(Throughput::Elements(lines as u64));
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut p = pipe(method, lead, &text);
                let mut n = 0;
                while let Some(done) = p.line() {
                    n += usize::from(done);
                }
                let _ = p.rows.rows();
                black_box(n)
            })
        });
    }
    g.finish();
    let _ = std::io::stderr().flush();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    targets = latency, throughput
}
criterion_main!(benches);
