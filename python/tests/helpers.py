"""Reading the CLI's outputs and comparing numbers with a tolerance."""

import csv
import json

import numpy as np


def read_csv(path):
    """A CSV of the CLI as a dict of float arrays (empty cells → NaN)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head, body = rows[0], rows[1:]
    out = {}
    for j, name in enumerate(head):
        col = []
        for r in body:
            cell = r[j]
            try:
                col.append(float(cell) if cell != "" else np.nan)
            except ValueError:
                col.append(cell)
        out[name] = np.array(col) if all(isinstance(c, float) for c in col) else col
    return out


def read_json(path):
    with open(path) as f:
        return json.load(f)


def assert_same_predictions(py, cli, scale, rel=1e-12):
    """Same samples predicted, values within rel × scale."""
    py = np.asarray(py)
    cli = np.asarray(cli)
    assert py.shape == cli.shape
    np.testing.assert_array_equal(np.isnan(py), np.isnan(cli))
    ok = ~np.isnan(cli)
    assert ok.sum() > 0, "nothing predicted: the comparison would be empty"
    err = np.max(np.abs(py[ok] - cli[ok]))
    assert err <= rel * scale, f"max difference {err:e} > {rel:e} × {scale:e}"


# timings differ from run to run; everything else must be equal
TIMING_KEYS = {"identification_seconds", "per_window_us"}


def assert_same_summary(py, cli, rel=1e-12):
    assert set(py) == set(cli), f"keys differ: {set(py) ^ set(cli)}"
    for k in py:
        if k in TIMING_KEYS:
            continue
        _assert_close(py[k], cli[k], rel, k)


def _assert_close(a, b, rel, where):
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), where
        for k in a:
            _assert_close(a[k], b[k], rel, f"{where}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _assert_close(x, y, rel, f"{where}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert abs(a - b) <= rel * max(abs(a), abs(b), 1e-300), f"{where}: {a!r} vs {b!r}"
    else:
        assert a == b, f"{where}: {a!r} vs {b!r}"
