"""python/examples/fleet_dask.py on a dask.distributed LocalCluster with 2
workers: one row per recording, equal to the CLI's summary of it; a broken
recording gets an error row and the others finish."""

import csv
import subprocess
import sys
from pathlib import Path

import pytest

from helpers import read_json

pytest.importorskip("distributed", reason="skipped: dask.distributed absent (pip install './python[dask]')")

SCRIPT = Path(__file__).resolve().parents[1] / "examples" / "fleet_dask.py"
SCENARIOS = ["ramp", "step", "scurve", "chirp", "prbs", "multisine"]


def test_fleet_rows_equal_the_cli_summaries(cli, tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    paths = []
    for i in range(21):
        p = data / f"axis{i:02d}.csv"
        scenario = SCENARIOS[i % len(SCENARIOS)]
        cli("simulate", "--scenario", scenario, "--seed", 10 + i, "--duration", 0.5, "-o", p)
        paths.append(p)
    broken = data / "broken.csv"
    broken.write_text("time_s,command_m\n0,0\n0.001,0\n")
    out_dir = tmp_path / "cli"
    cli("identify", *paths, "--method", "auto", "--out-dir", out_dir)

    table = tmp_path / "fleet.csv"
    r = subprocess.run(
        [sys.executable, str(SCRIPT), *map(str, paths[:10]), str(broken), *map(str, paths[10:]),
         "--out", str(table), "--workers", "2", "--method", "auto"],
        capture_output=True, text=True, timeout=600,
    )
    assert r.returncode == 2, r.stderr  # one recording failed, the table is written
    assert "broken.csv" in r.stderr
    with open(table, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 22
    by_name = {Path(row["recording"]).name: row for row in rows}
    bad = by_name.pop("broken.csv")
    assert "broken.csv" in bad["error"] and "position_m" in bad["error"], bad["error"]
    assert bad["rms_m"] == "" and bad["samples"] == ""
    for p in paths:
        row = by_name[p.name]
        s = read_json(out_dir / f"{p.stem}.summary.json")
        assert row["error"] == ""
        assert row["method"] == s["method"] == "auto"
        assert int(row["samples"]) == s["samples"]
        for col, key in [("rms_m", "rms_error_m"), ("max_m", "max_abs_error_m"),
                         ("coverage_percent", "coverage_percent"),
                         ("global_fit_percent", "sim_fit_percent")]:
            b = s.get(key)
            if b is None:  # not in the summary (no global model fitted)
                assert row[col] == "", (p.name, col)
                continue
            a = float(row[col])
            assert abs(a - b) <= 1e-12 * max(abs(b), 1e-300), (p.name, col, a, b)
        assert row["global_model"] == (s.get("global_model") or "")
        assert float(row["identification_seconds"]) > 0
    # the fleet is not trivial: most recordings have a global model and a score
    assert sum(1 for r in by_name.values() if r["global_model"]) >= 10
    assert sum(1 for r in by_name.values() if r["global_fit_percent"]) >= 10


def test_demo_fleet_writes_into_a_fresh_directory_not_the_current_one(tmp_path):
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    r = subprocess.run(
        [sys.executable, str(SCRIPT), "--workers", "2"],
        capture_output=True, text=True, timeout=600, cwd=cwd,
    )
    assert r.returncode == 0, r.stderr
    assert list(cwd.iterdir()) == []  # nothing in the current directory
    first = r.stdout.splitlines()[0]
    assert first.startswith("writing into "), r.stdout
    out = Path(first[len("writing into "):])
    assert sorted(p.name for p in out.iterdir()) == [
        "axis1.csv", "axis2.csv", "axis3.csv", "axis4.csv", "fleet.csv"]
    with open(out / "fleet.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [Path(row["recording"]).name for row in rows] == [f"axis{i}.csv" for i in range(1, 5)]
    assert all(row["error"] == "" and float(row["rms_m"]) > 0 for row in rows)
    # a given directory gets the table as fleet.csv
    given = tmp_path / "results"
    r = subprocess.run(
        [sys.executable, str(SCRIPT), str(out / "axis1.csv"), "--out", str(given), "--workers", "1"],
        capture_output=True, text=True, timeout=600, cwd=cwd,
    )
    assert r.returncode == 0, r.stderr
    assert (given / "fleet.csv").is_file() and list(cwd.iterdir()) == []
