"""Shared fixtures: the command-line tool to compare with, the EMPS data."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EMPS = REPO / ".." / "shared" / "data" / "emps" / "DATA_EMPS.mat"


def _find_cli():
    given = os.environ.get("FEEDID_CLI")
    if given:
        if not Path(given).is_file():
            raise RuntimeError(f"FEEDID_CLI={given}: no such file")
        return given
    for profile in ("debug", "release"):
        p = REPO / "target" / profile / "feedid"
        if p.is_file():
            return str(p)
    return shutil.which("feedid")


@pytest.fixture(scope="session")
def cli():
    """A function running the feedid CLI (exit code checked)."""
    exe = _find_cli()
    if exe is None:
        pytest.skip("skipped: the feedid CLI is not built (cargo build -p feedid-cli, or set FEEDID_CLI)")

    def run(*args, check=True):
        r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        if check and r.returncode != 0:
            raise AssertionError(f"feedid {' '.join(map(str, args))}: exit {r.returncode}\n{r.stderr}")
        return r

    run.exe = exe
    return run


@pytest.fixture(scope="session")
def emps():
    if not EMPS.is_file():
        pytest.skip(f"skipped: {EMPS} absent (the EMPS benchmark data, see README)")
    return EMPS
