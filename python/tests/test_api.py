"""The Python API itself: errors, zero-copy arrays, the GIL, docstrings."""

import inspect
import threading

import numpy as np
import pytest

import feedid


def test_errors_are_value_and_os_errors_with_the_cli_messages(tmp_path):
    with pytest.raises(feedid.FileError) as e:
        feedid.read(tmp_path / "missing.csv")
    assert isinstance(e.value, OSError) and isinstance(e.value, feedid.Error)
    assert "missing.csv" in str(e.value)
    bad = tmp_path / "bad.csv"
    bad.write_text("time_s,command_m,position_m\n0,0,0\n0.001,0,abc\n0.002,0,0\n")
    with pytest.raises(feedid.InputError) as e:
        feedid.read(bad)
    msg = str(e.value)
    assert isinstance(e.value, ValueError)
    assert "bad.csv" in msg and "line 3" in msg and "abc" in msg, msg
    with pytest.raises(feedid.InputError, match="no column `pos`"):
        feedid.read(bad, position="pos")
    t = np.arange(100) * 1e-3
    with pytest.raises(feedid.InputError, match="non-finite"):
        feedid.identify(t, np.where(t > 0.05, np.nan, 0.0), np.zeros(100))
    with pytest.raises(feedid.InputError, match="time"):
        feedid.identify(t[::-1], np.zeros(100), np.zeros(100))
    with pytest.raises(feedid.InputError, match="unknown|invalid"):
        feedid.identify(t, np.zeros(100), np.zeros(100), method="magic")
    with pytest.raises(feedid.InputError, match="lambda does not apply to method arx"):
        feedid.identify(t, np.zeros(100), np.zeros(100), method="arx", **{"lambda": 0.9})
    with pytest.raises(TypeError, match="unknown option"):
        feedid.identify(t, np.zeros(100), np.zeros(100), lamda=0.9)
    with pytest.raises(feedid.InputError, match="interval"):
        feedid.identify(t, np.zeros(100), np.zeros(100), interval=100)
    with pytest.raises(feedid.InputError, match="scenario"):
        feedid.simulate("sawtooth")


def test_recording_arrays_are_read_only_views_and_identify_reads_them_in_place():
    rec = feedid.simulate("ramp", seed=1)
    t1, t2 = rec.time, rec.time
    assert t1.dtype == np.float64 and not t1.flags.writeable
    assert np.shares_memory(t1, t2), "two views of the library's buffer, no copy"
    with pytest.raises(ValueError):
        t1[0] = 1.0
    run = feedid.identify(rec, method="arx")
    assert np.shares_memory(run.position, rec.position)
    # contiguous float64 input is passed on without a NumPy copy
    a = np.ascontiguousarray(rec.time)
    assert feedid._array(a, "time") is a
    # arrays are identified in place: the result holds the caller's arrays,
    # and equals the identification of a checked recording of them
    t, u, y = (np.array(rec.time), np.array(rec.command), np.array(rec.position))
    run_arrays = feedid.identify(t, u, y, method="arx")
    assert run_arrays.time is t and run_arrays.position is y
    np.testing.assert_array_equal(run_arrays.predicted, run.predicted)
    assert run_arrays.summary["rms_error_m"] == run.summary["rms_error_m"]
    assert np.array_equal(run_arrays.recording.command, u), "a checked copy on demand"
    with pytest.raises(TypeError, match="recording or time, command and position"):
        feedid._feedid.identify(rec, time=t, command=u, position=y)
    # a run that predicts nothing says so in its repr (no rms)
    still = feedid.identify(t, np.zeros_like(t), np.zeros_like(t), method="arx")
    assert still.summary.get("rms_error_m") is None and "rms_error_m=none" in repr(still)
    # strided or integer input is converted, not refused
    t = np.arange(0, 2000, dtype=np.int64)
    run = feedid.identify(t[::2] * 1e-4, np.zeros(1000), np.zeros(1000), method="arx")
    assert run.summary["samples"] == 1000


def test_dropped_samples_are_gaps_as_in_the_cli(tmp_path):
    rec = feedid.simulate("ramp", seed=1)
    keep = np.ones(len(rec), dtype=bool)
    keep[300:303] = False
    t, u, y = (np.array(v)[keep] for v in (rec.time, rec.command, rec.position))
    run = feedid.identify(t, u, y, method="arx")
    assert (run.summary["gaps"], run.summary["missing_samples"]) == (1, 3)
    assert any("missing in 1 gap" in w for w in run.summary["warnings"])
    # no prediction reaches across the gap: the windows restart after it
    assert np.all(np.isnan(run.predicted[300:310]))
    assert run.recording.gaps == [(300, 3)]
    with pytest.raises(ValueError, match="3 samples look missing"):
        feedid.Recording(t, u, y)
    # a file read with gaps allowed identifies the same
    path = tmp_path / "gapped.csv"
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="time_s,command_m,position_m", comments="")
    with pytest.raises(ValueError, match="missing"):
        feedid.read(path)
    rec = feedid.read(path, allow_gaps=True)
    assert rec.gaps == [(300, 3)]
    again = feedid.identify(rec, method="arx")
    np.testing.assert_array_equal(again.predicted, run.predicted)


def test_identification_has_its_arrays_and_frames():
    pd = pytest.importorskip("pandas")
    rec = feedid.simulate("multisine", seed=2)
    run = feedid.identify(rec)
    n = len(rec)
    assert run.predicted.shape == run.lower.shape == run.upper.shape == (n,)
    assert run.coefficients.ndim == 2
    assert run.coefficients.shape == (run.summary["windows"], len(run.coefficient_names))
    predicted = ~np.isnan(run.predicted)
    assert predicted.sum() == run.summary["samples_predicted"]
    # where nothing was predicted the bounds are NaN too
    assert np.all(np.isnan(run.lower[~predicted])) and np.all(np.isnan(run.upper[~predicted]))
    # every predicted sample has its interval around the prediction
    assert not np.any(np.isnan(run.lower[predicted])) and not np.any(np.isnan(run.upper[predicted]))
    assert np.all(run.lower[predicted] <= run.predicted[predicted])
    assert np.all(run.predicted[predicted] <= run.upper[predicted])
    y = rec.position[predicted]
    inside = (run.lower[predicted] <= y) & (y <= run.upper[predicted])
    assert 100 * inside.mean() == pytest.approx(run.summary["interval_coverage_percent"], rel=1e-9)
    narrow = feedid.identify(rec, interval=50)
    w95 = run.upper[predicted] - run.lower[predicted]
    w50 = narrow.upper[predicted] - narrow.lower[predicted]
    assert np.median(w50) < np.median(w95)
    err = run.predicted[predicted] - rec.position[predicted]
    assert np.sqrt(np.mean(err**2)) == pytest.approx(run.summary["rms_error_m"], rel=1e-9)
    df = run.to_pandas()
    assert list(df.columns[:4]) == ["time_s", "command_m", "measured_m", "predicted_m"]
    assert len(df) == n and df["predicted_m"].isna().sum() == n - predicted.sum()
    cf = run.coefficients_to_pandas()
    assert len(cf) == run.summary["windows"] and list(cf.columns[3:]) == run.coefficient_names
    assert run.model is not None and "model" in run.model


def test_the_summary_says_whose_parameters_the_simulation_model_has(tmp_path):
    rec = feedid.simulate("ramp", seed=1)
    built_in = feedid.identify(rec, method="arx").summary
    assert built_in["nominal_rig"] == "built-in"
    toml = tmp_path / "my-axis.toml"
    toml.write_text("[control]\nkv = 350.0\n")
    from_file = feedid.identify(rec, method="arx", params=toml).summary
    assert from_file["nominal_rig"] == str(toml)
    from_dict = feedid.identify(rec, method="arx", params={"control": {"kv": 350.0}}).summary
    assert from_dict["nominal_rig"] == "dict"
    # the other rig was simulated (Kv 350 lags the ramp more than 700)
    assert from_file["sim_rms_error_m"] == pytest.approx(from_dict["sim_rms_error_m"], rel=1e-12)
    assert from_file["sim_rms_error_m"] > 1.5 * built_in["sim_rms_error_m"]
    assert "nominal_rig" not in feedid.identify(rec, method="arx", nominal=False).summary


def test_the_gil_is_released_while_identifying():
    rec = feedid.simulate("multisine", seed=1, duration=4.0)
    done = threading.Event()

    def work():
        feedid.identify(rec, method="auto")
        done.set()

    th = threading.Thread(target=work)
    count = 0
    th.start()
    while not done.is_set():
        count += 1  # runs only while the other thread has let the GIL go
    th.join()
    assert count > 10_000, count


def test_help_explains_every_argument_with_units():
    doc = inspect.getdoc(feedid.identify)
    for arg in ["time", "command", "position", "method", "window", "horizon", "order", "hop", "params"]:
        assert f"{arg} :" in doc or f"{arg}," in doc, arg
    for unit in ["[s]", "[m]", "[samples]"]:
        assert unit in doc
    assert "[Hz]" in inspect.getdoc(feedid.Streamer)
    assert "[A]" in inspect.getdoc(feedid.simulate)


def test_compensate_makes_the_model_follow_the_desired_trajectory():
    t = np.arange(5000) * 2e-4
    # a smooth move of 2 mm with rest at both ends
    s = np.clip((t - 0.2) / 0.5, 0, 1)
    desired = 2e-3 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    out = feedid.compensate(t, desired)
    assert out["command"].shape == desired.shape
    assert out["predicted_error"]["rms"] < 0.05 * np.max(np.abs(desired))
    rec = feedid.simulate("scurve", seed=1)
    run = feedid.identify(rec, method="arx")
    out2 = feedid.compensate(t, desired, run)
    assert np.all(np.isfinite(out2["command"]))
    # a check recording with dropped samples: the model runs through them
    keep = np.ones(len(rec), dtype=bool)
    keep[400:403] = False
    gapped = tuple(np.array(v)[keep] for v in (rec.time, rec.command, rec.position))
    full = feedid.compensate(t, desired, run, check=rec)
    part = feedid.compensate(t, desired, run, check=gapped)
    a, b = part["benefit"]["expected_benefit"], full["benefit"]["expected_benefit"]
    assert abs(a / b - 1) < 0.02, (a, b)


def test_warnings_name_python_keywords_not_cli_flags():
    # lengths in mm read as metres: the position moves far too fast
    rec = feedid.simulate("ramp", seed=1)
    t, u, y = (np.array(v) for v in (rec.time, rec.command, rec.position))
    run = feedid.identify(t, u * 1e3, y * 1e3, method="arx")
    warnings = run.summary["warnings"]
    speed = [w for w in warnings if "far beyond any feed drive" in w]
    assert speed, warnings
    assert 'unit="mm"' in speed[0] and "time_unit" in speed[0], speed
    assert not any("--" in w for w in warnings), warnings
