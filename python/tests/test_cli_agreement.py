"""feedid.identify gives the CLI's numbers (`feedid identify`) on the rig
scenarios and on EMPS: predictions within 1e-12 of the position range, the
same samples predicted, the same coefficients, the same summary."""

import numpy as np
import pytest

import feedid
from helpers import assert_same_predictions, assert_same_summary, read_csv, read_json

SCENARIOS = ["ramp", "step", "scurve", "chirp", "prbs", "multisine"]


def cli_identify(cli, tmp_path, recording, *args):
    pred, coef, summ = tmp_path / "p.csv", tmp_path / "c.csv", tmp_path / "s.json"
    cli("identify", recording, *args, "-o", pred, "--coefficients", coef, "--summary", summ)
    return read_csv(pred), read_csv(coef), read_json(summ)


def check(run, pred, coef, summ):
    scale = float(np.ptp(run.position))
    assert_same_predictions(run.predicted, pred["predicted_m"], scale)
    assert_same_predictions(run.lower, pred["lower_m"], scale)
    assert_same_predictions(run.upper, pred["upper_m"], scale)
    np.testing.assert_array_equal(run.time, pred["time_s"])
    np.testing.assert_array_equal(run.position, pred["measured_m"])
    sim = pred["simulated_m"]
    assert run.simulated is not None
    assert np.max(np.abs(run.simulated - sim)) <= 1e-12 * max(scale, np.max(np.abs(sim)))
    # coefficients: each column within 1e-12 of its own magnitude
    assert run.coefficients.shape == (len(coef["start_s"]), len(run.coefficient_names))
    for j, name in enumerate(run.coefficient_names):
        a, b = run.coefficients[:, j], coef[name]
        tol = 1e-12 * max(np.max(np.abs(b)), 1e-300)
        assert np.max(np.abs(a - b)) <= tol, name
    assert_same_summary(run.summary, summ)


@pytest.mark.parametrize("scenario", SCENARIOS)
@pytest.mark.parametrize("method", ["auto", "arx"])
def test_identify_equals_the_cli_on_the_rig_scenarios(cli, tmp_path, scenario, method):
    rec_path = tmp_path / f"{scenario}.csv"
    cli("simulate", "--scenario", scenario, "--seed", 1, "-o", rec_path)
    pred, coef, summ = cli_identify(cli, tmp_path, rec_path, "--method", method)
    run = feedid.identify(feedid.read(rec_path), method=method)
    check(run, pred, coef, summ)
    # the same run from arrays (the CLI reads the same numbers)
    rec = feedid.read(rec_path)
    run2 = feedid.identify(np.array(rec.time), np.array(rec.command), np.array(rec.position), method=method)
    np.testing.assert_array_equal(run2.predicted, run.predicted)


def test_simulate_equals_the_cli(cli, tmp_path):
    for scenario in ["ramp", "prbs"]:
        p = tmp_path / "r.csv"
        cli("simulate", "--scenario", scenario, "--seed", 3, "-o", p)
        c = read_csv(p)
        r = feedid.simulate(scenario, seed=3)
        np.testing.assert_array_equal(r.time, c["time_s"])
        np.testing.assert_array_equal(r.command, c["command_m"])
        np.testing.assert_array_equal(r.position, c["position_m"])
        np.testing.assert_array_equal(r.true_position, c["true_position_m"])
        np.testing.assert_array_equal(r.current, c["current_a"])
        np.testing.assert_array_equal(r.velocity, c["velocity_m_per_s"])


def test_options_reach_the_method_as_on_the_command_line(cli, tmp_path):
    rec_path = tmp_path / "chirp.csv"
    cli("simulate", "--scenario", "chirp", "--seed", 2, "-o", rec_path)
    rec = feedid.read(rec_path)
    cases = [
        (["--method", "arx", "--order", "2,3,1", "--window", "60", "--horizon", "5"],
         dict(method="arx", order=(2, 3, 1), window=60, horizon=5)),
        (["--method", "rls", "--lambda", "0.99", "--hop", "3"],
         {"method": "rls", "lambda": 0.99, "hop": 3}),
        (["--method", "arx", "--order", "auto"], dict(method="arx", order="auto")),
        (["--method", "paper", "--solver", "simplex"], dict(method="paper", solver="simplex")),
        (["--method", "arx", "--ridge", "1e-6", "--interval", "80"],
         dict(method="arx", ridge=1e-6, interval=80)),
    ]
    for args, kw in cases:
        pred, coef, summ = cli_identify(cli, tmp_path, rec_path, *args)
        check(feedid.identify(rec, **kw), pred, coef, summ)


def test_model_equals_feedid_model_json(cli):
    import json

    assert feedid.model() == json.loads(cli("model", "--json").stdout)
    assert feedid.model(d1="paper") == json.loads(cli("model", "--json", "--d1", "paper").stdout)


def test_identify_equals_the_cli_on_emps(cli, tmp_path, emps):
    args = ["--time", "t", "--command", "qg", "--position", "qm"]
    for method in ["auto", "arx"]:
        pred, coef, summ = cli_identify(cli, tmp_path, emps, *args, "--method", method)
        rec = feedid.read(emps, time="t", command="qg", position="qm")
        check(feedid.identify(rec, method=method), pred, coef, summ)
