"""feedid.identify gives the CLI's numbers (`feedid identify`) on the rig
scenarios and on EMPS: predictions within 1e-12 of the position range, the
same samples predicted, the same coefficients, the same summary."""

import json

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
@pytest.mark.parametrize("method", ["auto", "arx", "nn"])
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


def test_simulate_defaults_equal_the_cli_defaults(cli, tmp_path):
    # no seed given on either side: the same default seed (0)
    p = tmp_path / "prbs.csv"
    cli("simulate", "--scenario", "prbs", "--duration", 0.2, "-o", p)
    c = read_csv(p)
    r = feedid.simulate("prbs", duration=0.2)
    np.testing.assert_array_equal(r.command, c["command_m"])
    np.testing.assert_array_equal(r.position, c["position_m"])
    assert not np.array_equal(feedid.simulate("prbs", seed=1, duration=0.2).position, r.position)


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
        (["--method", "paper", "--runaway", "off"], dict(method="paper", runaway=None)),
        (["--method", "oe", "--runaway", "3"], dict(method="oe", runaway=3.0)),
        (["--method", "nn", "--hidden", "8", "--nn-seed", "3", "--online-steps", "2",
          "--train-samples", "1000", "--epochs", "5", "--learning-rate", "0.002"],
         dict(method="nn", hidden=8, nn_seed=3, online_steps=2, train_samples=1000, epochs=5,
              learning_rate=0.002)),
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
    for method in ["auto", "arx", "nn"]:
        pred, coef, summ = cli_identify(cli, tmp_path, emps, *args, "--method", method)
        rec = feedid.read(emps, time="t", command="qg", position="qm")
        check(feedid.identify(rec, method=method), pred, coef, summ)


@pytest.mark.parametrize(
    "py_options, cli_options, fallback",
    [
        ({}, [], None),
        # from rest without smoothing the start of motion asks more than
        # 30 m/s² (with it the start is eased in and the limits are met):
        # the correction is held back there, compensated elsewhere
        ({"start": "rest", "max_smoothing": 0.0}, ["--start", "rest", "--max-smoothing", 0.0], "held"),
        ({"start": "rest"}, ["--start", "rest"], None),
        (
            {"start": "rest", "fallback": False, "max_acceleration": float("inf")},
            ["--start", "rest", "--no-fallback", "--max-acceleration", "inf"],
            None,
        ),
        ({"min_benefit": 1e12}, ["--min-benefit", 1e12], "small_benefit"),
        ({"min_fit": 99.999}, ["--min-fit", 99.999], "poor_fit"),
        ({"check": "CHECK"}, ["--check", "CHECK"], None),
        ({"check": "CHECK", "min_fit": 99.99}, ["--check", "CHECK", "--min-fit", 99.99], "poor_fit"),
        # two runs of one program: the noise out by cross-products
        ({"check": ["CHECK", "CHECK2"]}, ["--check", "CHECK", "--check", "CHECK2"], None),
        # and the encoder's resolution from its data sheet
        (
            {"check": ["CHECK", "CHECK2"], "encoder_resolution": 1e-7},
            ["--check", "CHECK", "--check", "CHECK2", "--encoder-resolution", 1e-7],
            None,
        ),
    ],
)
def test_compensate_equals_the_cli_with_its_options(cli, tmp_path, py_options, cli_options, fallback):
    rec_path, model_path = tmp_path / "prbs.csv", tmp_path / "model.json"
    cli("simulate", "--scenario", "prbs", "--seed", 2, "-o", rec_path)
    cli("identify", rec_path, "--method", "arx", "-o", tmp_path / "p.csv", "--model-out", model_path)
    check_path, check2_path = tmp_path / "check.csv", tmp_path / "check2.csv"
    cli("simulate", "--scenario", "chirp", "--seed", 3, "-o", check_path)
    cli("simulate", "--scenario", "chirp", "--seed", 4, "-o", check2_path)
    # a desired trajectory cut from a move: it starts at a small speed
    # (from rest, the compensated command would exceed 30 m/s²)
    t = np.arange(3000) * 2e-4
    desired = 0.5e-3 * (1 - np.cos(2 * np.pi * t)) + 1e-4 * t
    desired_path = tmp_path / "desired.csv"
    np.savetxt(desired_path, np.column_stack([t, desired]), delimiter=",",
               header="time_s,position_m", comments="", fmt="%.17g")
    py_options = {"start": "moving", **py_options}
    if "--start" not in cli_options:
        cli_options = ["--start", "moving", *cli_options]
    paths = {"CHECK": check_path, "CHECK2": check2_path}

    def as_py(v):
        if isinstance(v, list):
            return [as_py(x) for x in v]
        return feedid.read(paths[v]) if isinstance(v, str) and v in paths else v

    py_options = {k: as_py(v) for k, v in py_options.items()}
    cli_options = [paths.get(v, v) if isinstance(v, str) else v for v in cli_options]
    out_path, summary_path = tmp_path / "c.csv", tmp_path / "c.json"
    cli("compensate", "--desired", desired_path, "--model", model_path, "-o", out_path,
        "--summary", summary_path, *cli_options)
    c, summary = read_csv(out_path), read_json(summary_path)
    out = feedid.compensate(t, desired, model_path, **py_options)
    scale = float(np.ptp(desired))
    assert np.max(np.abs(out["command"] - c["command_m"])) <= 1e-12 * scale
    assert np.max(np.abs(out["predicted"] - c["predicted_m"])) <= 1e-12 * scale
    # the summary's keys (the CLI's also names its files and limits)
    keys = set(out) - {"command", "predicted"}
    assert keys and keys <= set(summary), keys - set(summary)
    for key in keys:
        assert json.dumps(out[key], sort_keys=True) == json.dumps(summary[key], sort_keys=True), key
    # the option did what it says: the plain command is sent on a fall-back only
    held = fallback == "held"
    fallback = None if held else fallback
    assert (out["fallback"] or {}).get("reason") == fallback, out["fallback"]
    assert np.array_equal(out["command"], desired) == (fallback is not None)
    assert (out["held_back_share"] > 0) == held, out["held_back_share"]


def test_learning_from_runs_equals_the_cli_step_by_step(cli, tmp_path):
    # a heavy axis with feed-forward and friction: the compensated command
    # leaves a few µm that learning takes away
    params, effects = tmp_path / "heavy.toml", tmp_path / "fx.toml"
    params.write_text("[table]\nmass = 60.0\n[control]\nkv = 60.0\nkvff = 0.9\n")
    effects.write_text("[table_friction]\ncoulomb = 25.0\nbreakaway = 30.0\n"
                       "stribeck_velocity = 1e-3\nsmoothing_velocity = 1e-4\n")
    prog, model = tmp_path / "prog.csv", tmp_path / "m.json"
    cli("simulate", "--scenario", "scurve", "--params", params, "--effects", effects, "-o", prog)
    cli("identify", prog, "-o", tmp_path / "p.csv", "--model-out", model)
    program = feedid.read(prog)
    t, desired = np.asarray(program.time), np.asarray(program.command)
    command_path = tmp_path / "cmd1.csv"
    cli("compensate", "--desired", prog, "--desired-column", "command_m", "--model", model,
        "-o", command_path)
    history_path = tmp_path / "history.json"
    history = None
    rms = []
    for run in (1, 2, 3):
        run_path = tmp_path / f"run{run}.csv"
        cli("simulate", "--command", command_path, "--params", params, "--effects", effects,
            "--seed", run, "-o", run_path)
        next_path, summary_path = tmp_path / f"cmd{run + 1}.csv", tmp_path / f"s{run}.json"
        cli("compensate", "--desired", prog, "--desired-column", "command_m", "--model", model,
            "--measured", run_path, "--history", history_path, "-o", next_path,
            "--summary", summary_path)
        c, summary = read_csv(next_path), read_json(summary_path)
        out = feedid.learn(t, desired, model, run_path, history=history)
        assert out["run"] == run == summary["run"]
        scale = float(np.ptp(desired))
        assert np.max(np.abs(out["command"] - c["command_m"])) <= 1e-12 * scale
        assert np.max(np.abs(out["predicted"] - c["predicted_m"])) <= 1e-12 * scale
        keys = set(out) - {"command", "predicted", "history"}
        assert keys and keys <= set(summary), keys - set(summary)
        for key in keys:
            assert json.dumps(out[key], sort_keys=True) == json.dumps(summary[key], sort_keys=True), key
        # the history the CLI keeps is the one Python returns
        assert out["history"] == read_json(history_path)
        history = out["history"]
        rms.append(out["measured"]["rms"])
        command_path = next_path
    assert rms[2] < rms[0], rms
    # a history from the file, and the arrays form
    run_path = tmp_path / "run3.csv"
    rec = feedid.read(run_path)
    a = feedid.learn(t, desired, model, np.asarray(rec.position), sent=np.asarray(rec.command),
                     history=tmp_path / "history.json")
    assert a["run"] == 4
    with pytest.raises(feedid.InputError, match="sent="):
        feedid.learn(t, desired, model, np.asarray(rec.position))
    with pytest.raises(feedid.InputError, match="learning gain"):
        feedid.learn(t, desired, model, rec, gain=3.0)


def test_online_compensation_equals_the_cli_stream_line_by_line(cli, tmp_path):
    rec_path = tmp_path / "sc.csv"
    cli("simulate", "--scenario", "scurve", "-o", rec_path)
    rec = feedid.read(rec_path)
    t, u, y = (np.asarray(rec.time), np.asarray(rec.command), np.asarray(rec.position))
    import subprocess

    # what `feedid simulate` writes streams with no reading options
    r = subprocess.run([cli.exe, "stream", "--compensate", "--replay", "--command-lead", "4"],
                       input=rec_path.read_text(), capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.strip().splitlines()
    assert lines[0] == "time_s,desired_m,command_m"
    cli_rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    comp = feedid.OnlineCompensator(rate=5000.0, command_lead=4, replay=True)
    rows = [row for k in range(len(t)) if (row := comp.push(t[k], u[k], y[k])) is not None]
    py_rows = np.array(rows)
    assert py_rows.shape == cli_rows.shape
    scale = float(np.ptp(u))
    assert np.max(np.abs(py_rows[:, 1:] - cli_rows[:, 1:])) <= 1e-12 * scale
    assert np.max(np.abs(py_rows[:, 0] - cli_rows[:, 0])) <= 1e-9
    stats = comp.stats
    assert stats["state"] == "active"
    assert stats["compensated"] > 0.5 * stats["commands"]
    assert 0.5e-3 < stats["time_constants"][0] < 5e-3
    # many lines at once: the same commands
    many = feedid.OnlineCompensator(5000.0, 4, replay=True).push_many(t, u, y)
    assert np.array_equal(np.array(many), py_rows)
    with pytest.raises(feedid.InputError, match="3 to 33 samples ahead"):
        feedid.OnlineCompensator(5000.0, 2)
    # starting from an identified model: compensated from the first commands
    model_path = tmp_path / "m.json"
    cli("identify", rec_path, "-o", tmp_path / "p.csv", "--model-out", model_path)
    warm = feedid.OnlineCompensator(5000.0, 4, replay=True, model=model_path)
    warm_rows = np.array(warm.push_many(t, u, y))
    assert warm.stats["compensated"] > stats["compensated"]
    r = subprocess.run([cli.exe, "stream", "--compensate", "--replay", "--command-lead", "4",
                        "--model", str(model_path)],
                       input=rec_path.read_text(), capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    cli_warm = np.array([[float(v) for v in line.split(",")]
                         for line in r.stdout.strip().splitlines()[1:]])
    assert np.max(np.abs(warm_rows[:, 1:] - cli_warm[:, 1:])) <= 1e-12 * scale
    with pytest.raises(feedid.InputError, match="different lengths"):
        comp.push_many(t, u[:-1], y)


def test_runaway_cuts_and_regime_intervals_are_in_the_summary_as_on_the_command_line(cli, tmp_path):
    rec_path = tmp_path / "ramp.csv"
    cli("simulate", "--scenario", "ramp", "--seed", 1, "-o", rec_path)
    on = feedid.identify(feedid.read(rec_path), method="paper")
    off = feedid.identify(feedid.read(rec_path), method="paper", runaway=None)
    assert on.summary["runaway_windows"] > 0
    assert off.summary["runaway_windows"] == 0
    assert on.summary["max_abs_error_m"] < off.summary["max_abs_error_m"]
    regimes = on.summary["interval_by_regime"]
    assert sum(r["samples"] for r in regimes) == on.summary["samples_predicted"]
    assert on.summary["interval_median_width_m"] > 0
    with pytest.raises(feedid.InputError, match="factor"):
        feedid.identify(feedid.read(rec_path), runaway=0.5)
    s = feedid.Streamer(rate=5000.0, extrapolate="wait", runaway=None)
    s.push_many(np.array(feedid.read(rec_path).time), np.array(feedid.read(rec_path).command),
                np.array(feedid.read(rec_path).position))
    s.finish()
    st = s.stats
    assert st["runaway_windows"] == 0
    assert sum(v["samples"] for v in st["interval_by_regime"].values()) == st["samples_scored"]
