#!/usr/bin/env python3
"""Time feedid.identify on one hour of 5 kHz NumPy data: the arrays written by
`cargo run --release -p feedid --example pipeline_hour -- PREFIX`, loaded
with NumPy and identified with the default method: once with everything
`feedid identify` computes, then repeatedly the sliding identification
alone, as the Rust example times them (python/README.md, "Speed from Python").

    python python/examples/bench_hour.py PREFIX [REPEATS]
"""

import os
import sys
import time

import numpy as np

import feedid


def main() -> int:
    prefix = sys.argv[1]
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    t, u, y = (np.fromfile(f"{prefix}.{n}.f64", dtype="<f8") for n in ("time", "command", "position"))
    print(f"{len(t)} samples loaded")
    full = None
    if os.environ.get("FEEDID_BENCH_BREAKDOWN", "1") != "0":
        t0 = time.perf_counter()
        full = feedid.identify(t, u, y)  # everything feedid identify computes
        print(f"feedid.identify(time, command, position), as feedid identify: "
              f"{time.perf_counter() - t0:.2f} s")
    bare, bare_cpu, rec_only = [], [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        # arrays in: checked and read in place (no copy), then the sliding identification
        run = feedid.identify(t, u, y, nominal=False, global_model=False, residuals=False)
        bare.append(time.perf_counter() - t0)
        bare_cpu.append(time.process_time() - c0)
        t0 = time.perf_counter()
        feedid.Recording(t, u, y)
        rec_only.append(time.perf_counter() - t0)
    if full is not None:
        assert np.array_equal(run.predicted, full.predicted, equal_nan=True)
    s = run.summary
    med = lambda v: sorted(v)[len(v) // 2]  # noqa: E731
    print(f"rms {s['rms_error_m']:.3e} m over {s['coverage_percent']:.2f} % of the samples")
    print(f"feedid.identify(..., nominal=False, global_model=False, residuals=False): "
          f"wall min {min(bare):.2f} s, median {med(bare):.2f} s; "
          f"CPU min {min(bare_cpu):.2f} s, median {med(bare_cpu):.2f} s over {repeats} runs")
    print(f"a checked copy of the arrays (feedid.Recording), for comparison; "
          f"identify does not make one: min {min(rec_only):.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
