#!/usr/bin/env python3
"""Side-by-side: the paper method as a user would write it in Python vs feedid.

    python3 bench/compare_python.py [--scenarios ramp,step] [--simplex-windows 100] [--arx chirp]

What it does, in one run (so the ratio holds on a noisy machine):

1. Creates its own virtual environment (bench/.venv) and installs NumPy and
   SciPy into it, then re-runs itself inside it.
2. Builds feedid (release) and writes the recordings with
   `feedid simulate --scenario S -o S.csv`; where that command is absent,
   with `cargo run --release -p feedid --example make_recording -- S S.csv`
   (same virtual rig, CSV columns time_s,command_m,position_m).
3. Python, per window of W = 20 samples, hop = horizon H = 10 (the batch
   engine's windows): time from the motion start (the last sample before the
   command first moves by more than 1 nm), basis scaled by T = max|tau| over
   the window; `numpy.linalg.lstsq` on (tau/T)^5..(tau/T)^7 for the position
   and (tau/T)^0..(tau/T)^7 for the command; the prediction continues the
   position polynomial over the next H samples. Windows that end at or
   before the motion start hold the last position and positions are taken
   from the rest position at the motion start (as feedid does). The
   paper's simplex: `scipy.optimize.fmin` on the same two sums of squares
   (data normalised to unit norm, start at 0, tolerances like feedid's).
4. feedid: `feedid identify --method paper --solver qr|simplex --window 20
   --horizon 10 -o pred.csv --summary s.json REC` (per-window time from
   summary.json `per_window_us`). Without `identify`, `feedid stream` is used
   for the predictions and timed from outside (process start and CSV I/O
   included: an upper bound).
5. Checks the QR predictions agree within 1e-6 of the position range and
   prints per-window times and ratios; feedid's simplex both from the
   paper's zeros (default) and with `--simplex-start previous`.
6. ARX 8,8,1, W = 200, H = 10, hop 10, on the chirp: a NumPy
   refit per window (`numpy.linalg.lstsq` on [-y lags, u lags, 1], then
   the 10-step prediction driven by the measured command) against
   `feedid identify --method arx --window 200 --horizon 10` (its own ridge,
   scaling, offset and checks, so the predictions are compared by their
   rms error against the measured position over the same samples, not to
   each other).

Not part of CI. Exit code 1 if a QR comparison fails.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENV = ROOT / "bench" / ".venv"
W, H = 20, 10
MOTION_THRESHOLD = 1e-9


def ensure_venv():
    """Re-run inside bench/.venv with numpy and scipy installed."""
    if os.environ.get("FEEDID_COMPARE_IN_VENV") == "1":
        return
    py = VENV / "bin" / "python"
    if not py.exists():
        print(f"creating {VENV} ...", file=sys.stderr)
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    check = subprocess.run([str(py), "-c", "import numpy, scipy"], capture_output=True)
    if check.returncode != 0:
        print("installing numpy and scipy ...", file=sys.stderr)
        subprocess.run([str(py), "-m", "pip", "install", "-q", "numpy", "scipy"], check=True)
    env = dict(os.environ, FEEDID_COMPARE_IN_VENV="1")
    os.execve(str(py), [str(py), __file__] + sys.argv[1:], env)


def target_dir():
    return Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))


def build_feedid(feedid, profile):
    if feedid:
        return Path(feedid)
    subprocess.run(["cargo", "build", "--profile", profile, "-q", "-p", "feedid-cli"], cwd=ROOT,
                   check=True)
    return target_dir() / ("debug" if profile == "dev" else profile) / "feedid"


def make_recording(feedid, scenario, path, profile):
    r = subprocess.run([str(feedid), "simulate", "--scenario", scenario, "-o", str(path)],
                       capture_output=True, text=True)
    if r.returncode == 0 and path.exists():
        return "feedid simulate"
    subprocess.run(["cargo", "run", "--profile", profile, "-q", "-p", "feedid", "--example", "make_recording",
                    "--", scenario, str(path)], cwd=ROOT, check=True, capture_output=True)
    return "example make_recording"


def read_recording(np, path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    col = {name: i for i, name in enumerate(header)}
    t = data[:, col.get("time_s", 0)]
    u = data[:, col.get("command_m", 1)]
    y = data[:, col.get("position_m", 2)]
    return t, u, y


def motion_start(np, t, u):
    moving = np.nonzero(np.abs(u - u[0]) > MOTION_THRESHOLD)[0]
    return t[0] if len(moving) == 0 else t[max(moving[0] - 1, 0)]


def rest_position(np, t, y, ms):
    """Measured position at the motion start (the output model has no constant term)."""
    k = np.nonzero(t <= ms)[0]
    return 0.0 if len(k) == 0 else y[k[-1]]


def windows(n):
    s = 0
    while s + W < n:
        yield s, s + W, min(s + W + H, n)
        s += H


def python_lstsq(np, t, u, y):
    """The paper method with numpy.linalg.lstsq; (predictions, seconds, windows)."""
    ms = motion_start(np, t, u)
    y0 = rest_position(np, t, y, ms)
    pred = np.full(len(t), np.nan)
    count = 0
    t0 = time.perf_counter()
    for s, we, he in windows(len(t)):
        count += 1
        if t[we - 1] <= ms:
            pred[we:he] = y[we - 1]
            continue
        tau = t[s:we] - ms
        scale = np.max(np.abs(tau))
        x = tau / scale
        a_out = np.column_stack([x ** 5, x ** 6, x ** 7])
        p, *_ = np.linalg.lstsq(a_out, y[s:we] - y0, rcond=None)
        a_in = np.vander(x, 8, increasing=True)
        q, *_ = np.linalg.lstsq(a_in, u[s:we], rcond=None)
        xh = (t[we:he] - ms) / scale
        pred[we:he] = y0 + np.column_stack([xh ** 5, xh ** 6, xh ** 7]) @ p
    return pred, time.perf_counter() - t0, count


def python_fmin(np, fmin, t, u, y, max_windows):
    """The paper's simplex with scipy.optimize.fmin on the first `max_windows` moving windows."""
    ms = motion_start(np, t, u)
    y0 = rest_position(np, t, y, ms)
    pred = np.full(len(t), np.nan)
    count = 0
    elapsed = 0.0

    def fit(a, b):
        norm = np.linalg.norm(b)
        if norm == 0.0:
            return np.zeros(a.shape[1])
        bn = b / norm
        n = a.shape[1]
        simplex = np.vstack([np.zeros(n), 0.5 * np.eye(n)])
        z = fmin(lambda c: float(np.sum((a @ c - bn) ** 2)), np.zeros(n), xtol=1e-10, ftol=1e-26,
                 maxiter=4000, maxfun=8000, disp=False, initial_simplex=simplex)
        return z * norm

    for s, we, he in windows(len(t)):
        if t[we - 1] <= ms:
            continue
        if count >= max_windows:
            break
        count += 1
        t0 = time.perf_counter()
        tau = t[s:we] - ms
        scale = np.max(np.abs(tau))
        x = tau / scale
        a_out = np.column_stack([x ** 5, x ** 6, x ** 7])
        p = fit(a_out, y[s:we] - y0)
        fit(np.vander(x, 8, increasing=True), u[s:we])
        xh = (t[we:he] - ms) / scale
        pred[we:he] = y0 + np.column_stack([xh ** 5, xh ** 6, xh ** 7]) @ p
        elapsed += time.perf_counter() - t0
    return pred, elapsed, count


ARX_NA, ARX_NB, ARX_NK, ARX_W = 8, 8, 1, 200


def python_arx(np, u, y):
    """ARX refit per window with numpy.linalg.lstsq; (predictions, seconds, windows)."""
    na, nb, nk, w = ARX_NA, ARX_NB, ARX_NK, ARX_W
    lag = max(na, nb + nk - 1)
    n = len(y)
    pred = np.full(n, np.nan)
    count = 0
    t0 = time.perf_counter()
    s = lag
    while s + w + H <= n:
        e = s + w
        k = np.arange(s, e)
        cols = [-y[k - i] for i in range(1, na + 1)]
        cols += [u[k - nk - j] for j in range(nb)]
        cols.append(np.ones(w))
        theta, *_ = np.linalg.lstsq(np.column_stack(cols), y[s:e], rcond=None)
        a, b, c = theta[:na], theta[na:na + nb], theta[-1]
        yy = list(y[e - na:e])  # the past outputs, the predictions appended
        for j in range(H):
            kk = e + j
            v = c - sum(a[i] * yy[-1 - i] for i in range(na))
            v += sum(b[i] * u[kk - nk - i] for i in range(nb))
            yy.append(v)
            pred[kk] = v
        count += 1
        s += H
    return pred, time.perf_counter() - t0, count


def rms_error(np, pred, y, mask):
    d = pred[mask] - y[mask]
    return float(np.sqrt(np.mean(d * d))) if d.size else float("nan")


def read_predictions(np, path):
    """predicted_m per sample (NaN where empty) from feedid identify's predictions.csv."""
    with open(path) as f:
        header = f.readline().strip().split(",")
        i = header.index("predicted_m")
        out = []
        for line in f:
            cells = line.rstrip("\n").split(",")
            out.append(float(cells[i]) if i < len(cells) and cells[i] != "" else np.nan)
    return np.array(out)


def feedid_identify(np, feedid, rec, label, workdir, options):
    """(predictions, µs per window) from `feedid identify REC OPTIONS`."""
    pred_csv = workdir / f"pred_{rec.stem}_{label}.csv"
    summary = workdir / f"summary_{rec.stem}_{label}.json"
    r = subprocess.run([str(feedid), "identify", str(rec)] + options + ["-o", str(pred_csv), "--summary",
                       str(summary)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"feedid identify {' '.join(options)} failed: {r.stderr.strip()}")
    with open(summary) as f:
        us = float(json.load(f)["per_window_us"])
    return read_predictions(np, pred_csv), us


def feedid_predictions(np, feedid, rec, solver, workdir, n, start="zeros"):
    """(predictions, µs per window, how) from `feedid identify`, else from `feedid stream`."""
    label = f"{solver}_{start}"
    pred_csv = workdir / f"pred_{rec.stem}_{label}.csv"
    summary = workdir / f"summary_{rec.stem}_{label}.json"
    extra = ["--simplex-start", start] if solver == "simplex" else []
    r = subprocess.run([str(feedid), "identify", str(rec), "--method", "paper", "--solver", solver,
                        "--window", str(W), "--horizon", str(H), "-o", str(pred_csv),
                        "--summary", str(summary)] + extra, capture_output=True, text=True)
    if r.returncode == 0 and pred_csv.exists() and summary.exists():
        with open(summary) as f:
            us = float(json.load(f)["per_window_us"])
        return read_predictions(np, pred_csv), us, "identify"
    # fallback: the streaming command (same predictions), timed from outside
    with open(rec) as f:
        text = f.read()
    t0 = time.perf_counter()
    s = subprocess.run([str(feedid), "stream", "--method", "paper", "--solver", solver, "--window", str(W),
                        "--horizon", str(H)], input=text, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    t_rec = np.loadtxt(rec, delimiter=",", skiprows=1, usecols=0, ndmin=1)
    dt = (t_rec[-1] - t_rec[0]) / (len(t_rec) - 1)
    pred = np.full(n, np.nan)
    for line in s.stdout.splitlines()[1:]:
        tt, yy = line.split(",")
        k = int(round((float(tt) - t_rec[0]) / dt))
        if 0 <= k < n:
            pred[k] = float(yy)
    windows_count = sum(1 for _ in windows(n))
    return pred, 1e6 * wall / windows_count, "stream (wall time incl. I/O)"


def compare(np, a, b, y):
    both = ~np.isnan(a) & ~np.isnan(b)
    if np.any(np.isnan(a) != np.isnan(b)):
        return float("inf"), int(both.sum())
    rng = float(np.max(y) - np.min(y)) or 1.0
    return float(np.max(np.abs(a[both] - b[both])) / rng), int(both.sum())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenarios", default="ramp,step")
    ap.add_argument("--simplex-windows", type=int, default=100,
                    help="moving windows timed with scipy's fmin (it is slow)")
    ap.add_argument("--arx", default="chirp",
                    help="recordings for the ARX comparison (scenarios; empty: none)")
    ap.add_argument("--feedid", help="feedid binary (default: cargo build --release)")
    ap.add_argument("--profile", default="release", help="cargo profile to build with")
    ap.add_argument("--keep", help="directory for recordings and outputs (default: temporary)")
    args = ap.parse_args()
    ensure_venv()
    import numpy as np
    from scipy.optimize import fmin

    feedid = build_feedid(args.feedid, args.profile)
    workdir = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="feedid_cmp_"))
    workdir.mkdir(parents=True, exist_ok=True)
    rows = []
    ok = True
    for scenario in args.scenarios.split(","):
        rec = workdir / f"{scenario}.csv"
        source = make_recording(feedid, scenario, rec, args.profile)
        t, u, y = read_recording(np, rec)
        n = len(t)
        py_qr, py_qr_s, nwin = python_lstsq(np, t, u, y)
        py_nm, py_nm_s, nwin_nm = python_fmin(np, fmin, t, u, y, args.simplex_windows)
        fq, fq_us, how_q = feedid_predictions(np, feedid, rec, "qr", workdir, n)
        fs, fs_us, how_s = feedid_predictions(np, feedid, rec, "simplex", workdir, n)
        fp, fp_us, _ = feedid_predictions(np, feedid, rec, "simplex", workdir, n, "previous")
        err_qr, m_qr = compare(np, py_qr, fq, y)
        # the simplex subset: compare where Python's fmin predicted
        sub = ~np.isnan(py_nm)
        err_nm, _ = compare(np, np.where(sub, py_nm, np.nan), np.where(sub, fs, np.nan), y)
        err_prev, _ = compare(np, np.where(sub, py_nm, np.nan), np.where(sub, fp, np.nan), y)
        ok &= err_qr <= 1e-6
        rows.append({
            "recording": f"{scenario} ({n} samples, {source})",
            "windows": nwin,
            "py_lstsq_us": 1e6 * py_qr_s / nwin,
            "feedid_qr_us": fq_us,
            "py_fmin_us": 1e6 * py_nm_s / max(nwin_nm, 1),
            "feedid_simplex_us": fs_us,
            "feedid_previous_us": fp_us,
            "err_prev": err_prev,
            "err_qr": err_qr,
            "err_nm": err_nm,
            "how": how_q if how_q == how_s else f"{how_q}/{how_s}",
            "compared": m_qr,
        })
    arx_rows = []
    for scenario in [a for a in args.arx.split(",") if a]:
        rec = workdir / f"{scenario}.csv"
        source = make_recording(feedid, scenario, rec, args.profile)
        t, u, y = read_recording(np, rec)
        py, py_s, nwin = python_arx(np, u, y)
        fa, fa_us = feedid_identify(np, feedid, rec, "arx", workdir,
                                    ["--method", "arx", "--window", str(ARX_W), "--horizon", str(H)])
        both = ~np.isnan(py) & ~np.isnan(fa)
        arx_rows.append({
            "recording": f"{scenario} ({len(t)} samples, {source})",
            "windows": nwin,
            "py_us": 1e6 * py_s / nwin,
            "feedid_us": fa_us,
            "rms_py": rms_error(np, py, y, both),
            "rms_feedid": rms_error(np, fa, y, both),
            "compared": int(both.sum()),
        })
    print()
    print("Paper method, W = 20, H = hop = 10:")
    print()
    print("| recording | windows | NumPy lstsq µs/window | feedid QR µs/window | ratio "
          "| SciPy fmin µs/window | feedid simplex µs/window | ratio | feedid simplex (previous) µs/window "
          "| ratio | max QR diff / range | max simplex diff / range (zeros, previous) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['recording']} | {r['windows']} | {r['py_lstsq_us']:.1f} | {r['feedid_qr_us']:.2f} "
              f"| {r['py_lstsq_us'] / r['feedid_qr_us']:.0f}× | {r['py_fmin_us']:.0f} "
              f"| {r['feedid_simplex_us']:.1f} | {r['py_fmin_us'] / r['feedid_simplex_us']:.0f}× "
              f"| {r['feedid_previous_us']:.1f} | {r['py_fmin_us'] / r['feedid_previous_us']:.0f}× "
              f"| {r['err_qr']:.1e} | {r['err_nm']:.1e}, {r['err_prev']:.1e} |")
    if arx_rows:
        print()
        print(f"ARX {ARX_NA},{ARX_NB},{ARX_NK}, W = {ARX_W}, H = hop = {H}:")
        print()
        print("| recording | windows | NumPy lstsq refit µs/window | feedid arx µs/window | ratio "
              "| rms error NumPy [µm] | rms error feedid [µm] | samples compared |")
        print("|---|---|---|---|---|---|---|---|")
        for r in arx_rows:
            print(f"| {r['recording']} | {r['windows']} | {r['py_us']:.1f} | {r['feedid_us']:.2f} "
                  f"| {r['py_us'] / r['feedid_us']:.0f}× | {1e6 * r['rms_py']:.4f} "
                  f"| {1e6 * r['rms_feedid']:.4f} | {r['compared']} |")
    print()
    print(f"feedid timing from: {rows[0]['how'] if rows else '-'}; "
          f"fmin timed on the first {args.simplex_windows} moving windows; outputs in {workdir}")
    print(f"QR predictions agree within 1e-6 of the range: {'yes' if ok else 'NO'}")
    if not args.keep:
        shutil.rmtree(workdir, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
