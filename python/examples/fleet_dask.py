#!/usr/bin/env python3
"""Identify a fleet of recordings on a Dask cluster, one recording per task.

    python python/examples/fleet_dask.py --workers 2          # a demo fleet
    python python/examples/fleet_dask.py rec1.csv rec2.mat ... --out results/
    python python/examples/fleet_dask.py data/*.csv --out fleet.csv --workers 8
    python python/examples/fleet_dask.py data/*.csv --out results/ --scheduler tcp://head:8786

Everything is written under --out: a directory (created if needed) that
gets the table as fleet.csv, or a path ending in .csv that is the table
itself. Without --out a fresh temporary directory is used and printed;
nothing is written into the current directory. Without recordings the
script first simulates a demo fleet there (axis1.csv … axis4.csv: PRBS on
the virtual rig, seeds 1 to 4) and identifies it.

Without --scheduler a LocalCluster with N worker processes (one thread
each) runs on this machine; with it the same tasks go to an existing
dask.distributed scheduler (a multi-node cluster: every worker needs the
feedid package installed and the recordings at the same paths).

Each task reads and identifies one recording with feedid.identify (the
library pipeline, the defaults of `feedid identify`) and returns one row:

    recording, method, samples, rms_m, max_m, coverage_percent,
    global_model, global_fit_percent, identification_seconds, error

The numbers are those of the recording's summary.json (`feedid identify
--summary`); a recording that fails gets a row with its message in `error`
and empty numbers, and the others still finish (the exit code is then 2,
as for `feedid identify --out-dir`, after the table is written). MAT-files are read with
--time/--command/--position (variable names), as on the command line.

Needs: pip install "./python[dask]".
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile
import time
from typing import Any, Dict, List, Optional, Tuple

COLUMNS = [
    "recording",
    "method",
    "samples",
    "rms_m",
    "max_m",
    "coverage_percent",
    "global_model",
    "global_fit_percent",
    "identification_seconds",
    "error",
]


def identify_one(path: str, method: str, read_options: Dict[str, Any]) -> Dict[str, Any]:
    """One task: read and identify one recording; never raises (a failure
    is the row's error)."""
    import feedid

    row: Dict[str, Any] = {c: "" for c in COLUMNS}
    row["recording"] = path
    row["method"] = method
    try:
        rec = feedid.read(path, **read_options)
        run = feedid.identify(rec, method=method)
    except Exception as e:  # one bad recording must not stop the fleet
        row["error"] = str(e) if isinstance(e, feedid.Error) else f"{type(e).__name__}: {e}"
        return row
    s = run.summary
    row.update(
        samples=s["samples"],
        rms_m=s["rms_error_m"],
        max_m=s["max_abs_error_m"],
        coverage_percent=s["coverage_percent"],
        global_model=s.get("global_model") or "",
        # summary.json's key for the global model's free-run fit
        global_fit_percent=s.get("sim_fit_percent", ""),
        identification_seconds=s["identification_seconds"],
    )
    return row


def cell(v: Any) -> str:
    """A CSV cell: floats with repr (round-trip exact), None empty."""
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return str(v)


def run_fleet(
    recordings: List[str],
    method: str = "auto",
    workers: int = 2,
    scheduler: Optional[str] = None,
    read_options: Optional[Dict[str, Any]] = None,
) -> List[Dict[str, Any]]:
    """Identify every recording as one task; rows in the order given."""
    from dask.distributed import Client, LocalCluster

    read_options = read_options or {}
    if scheduler:
        client = Client(scheduler)
        cluster = None
    else:
        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        )
        client = Client(cluster)
    try:
        futures = client.map(
            identify_one,
            recordings,
            method=method,
            read_options=read_options,
            pure=False,
        )
        return client.gather(futures)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def output_paths(out: Optional[str]) -> Tuple[str, str]:
    """The directory the outputs go to and the table's path: `out` as a
    directory (created), a path ending in .csv as the table, or a fresh
    temporary directory."""
    if out is None:
        directory = tempfile.mkdtemp(prefix="feedid-fleet-")
        return directory, os.path.join(directory, "fleet.csv")
    if out.lower().endswith(".csv") and not os.path.isdir(out):
        directory = os.path.dirname(os.path.abspath(out))
        os.makedirs(directory, exist_ok=True)
        return directory, out
    os.makedirs(out, exist_ok=True)
    return out, os.path.join(out, "fleet.csv")


def demo_fleet(directory: str, axes: int = 4) -> List[str]:
    """Simulate `axes` PRBS recordings on the virtual rig into `directory`
    (axis1.csv …, seeds 1 …) and return their paths."""
    import numpy as np

    import feedid

    paths = []
    for seed in range(1, axes + 1):
        rec = feedid.simulate("prbs", seed=seed)
        path = os.path.join(directory, f"axis{seed}.csv")
        np.savetxt(
            path,
            np.column_stack([rec.time, rec.command, rec.position]),
            delimiter=",",
            header="time_s,command_m,position_m",
            comments="",
            fmt="%.17g",
        )
        paths.append(path)
    return paths


def main(argv: Optional[List[str]] = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("recordings", nargs="*", metavar="RECORDING",
                   help="CSV or MAT recordings (none: simulate a demo fleet of 4 under --out)")
    p.add_argument("--out", metavar="DIR|TABLE.csv",
                   help="output directory (the table is DIR/fleet.csv) or the table's path; "
                        "default: a fresh temporary directory, printed")
    p.add_argument("--workers", type=int, default=2, metavar="N",
                   help="worker processes of the LocalCluster (default 2)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="an existing dask.distributed scheduler (tcp://host:8786) instead")
    p.add_argument("--method", default="auto", metavar="M",
                   help="identification method (default auto)")
    p.add_argument("--time", help="time column or MAT variable")
    p.add_argument("--command", help="command column or MAT variable")
    p.add_argument("--position", help="position column or MAT variable")
    a = p.parse_args(argv)
    if a.workers < 1:
        p.error("--workers must be at least 1")
    read_options = {k: v for k, v in
                    (("time", a.time), ("command", a.command), ("position", a.position)) if v}
    directory, table = output_paths(a.out)
    if a.out is None:
        print(f"writing into {directory}")
    recordings = a.recordings or demo_fleet(directory)
    start = time.perf_counter()
    rows = run_fleet(recordings, a.method, a.workers, a.scheduler, read_options)
    with open(table, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([cell(r[c]) for c in COLUMNS])
    failed = sum(1 for r in rows if r["error"])
    print(
        f"{table}: {len(rows)} recordings, {failed} failed, "
        f"{time.perf_counter() - start:.1f} s wall "
        f"({'scheduler ' + a.scheduler if a.scheduler else f'{a.workers} local workers'})"
    )
    for r in rows:
        if r["error"]:
            print(f"error: {r['error']}", file=sys.stderr)
    return 2 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
