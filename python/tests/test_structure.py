"""Drive structures from Python: the closed loop, the simulation, the
estimation and the retuned gains of examples/emps.toml."""

import math
import pathlib

import numpy as np
import pytest

import feedid

EMPS_TOML = pathlib.Path(__file__).resolve().parents[2] / "examples" / "emps.toml"


def test_the_emps_closed_loop_is_the_closed_form_second_order_system():
    s = feedid.structure(EMPS_TOML)
    g, kv, kp, m, fv = 35.1507, 243.45, 160.18, 95.1089, 203.5034
    assert s["stable"]
    assert s["denominator"] == pytest.approx([m, fv + g * kv, g * kv * kp], rel=1e-12)
    wn = math.sqrt(g * kv * kp / m)
    for p in s["poles"]:
        assert p["freq_hz"] == pytest.approx(wn / (2 * math.pi), rel=1e-9)
    assert s["following_error_per_velocity"] == pytest.approx((fv + g * kv) / (g * kv * kp), rel=1e-12)


def test_a_structure_is_estimated_back_from_its_own_simulated_run():
    rate = 1000.0
    t = np.arange(8000) / rate
    command = 0.05 * np.sin(0.7 * t) + 0.02 * np.sin(2.3 * t)
    run = feedid.simulate_structure(EMPS_TOML, command, rate)
    assert run["position"].shape == command.shape
    assert np.max(np.abs(run["output"])) <= 10.0
    fit = feedid.fit_structure(EMPS_TOML, command, run["position"], rate, "M,Fv,Fc,offset")
    values = {e["param"]: e["value"] for e in fit["estimates"]}
    assert all(e["verdict"] == "identifiable" for e in fit["estimates"])
    assert fit["restarts_elsewhere"] == 0
    assert values["M"] == pytest.approx(95.1089, rel=1e-6)
    assert values["Fv"] == pytest.approx(203.5034, rel=1e-6)
    assert values["offset"] == pytest.approx(-3.1648, abs=1e-4)
    assert "[mechanics]" in fit["toml"]
    with pytest.raises(feedid.InputError, match="M, Fv, Fc, offset"):
        feedid.fit_structure(EMPS_TOML, command, run["position"], rate, ["Kv"])


def test_tune_returns_the_gains_for_the_bandwidth_asked(tmp_path):
    t = feedid.tune(EMPS_TOML, 40.0)
    assert t["after"]["bandwidth_hz"] == pytest.approx(40.0, rel=1e-6)
    assert t["overshoot_percent"][1] < 5.0
    out = tmp_path / "tuned.toml"
    out.write_text(t["toml"])
    assert feedid.structure(out)["bandwidth_hz"] == pytest.approx(40.0, rel=1e-6)
    rig = tmp_path / "rig.toml"
    rig.write_text("[control]\nkv = 30.0\n")
    with pytest.raises(feedid.InputError, match="not a drive structure"):
        feedid.tune(rig, 40.0)


def test_tune_places_the_poles_of_a_pi_velocity_loop(tmp_path):
    # P around PI on a 20 kg mass: the bandwidth asked, the integral kept
    pi = tmp_path / "pi.toml"
    pi.write_text(
        "[position]\nkp = 30.0\n[velocity]\nkind = \"PI\"\nkp = 200.0\nki = 20.0\n"
        "[drive]\ngain = 20.0\n[mechanics]\nmass = 20.0\n[friction]\nviscous = 50.0\n"
    )
    t = feedid.tune(pi, 15.0)
    assert t["after"]["bandwidth_hz"] == pytest.approx(15.0, rel=1e-6)
    assert t["after"]["stable"]
    assert 0.0 < t["velocity_ki"][1] < t["position_kp"][1]
    assert t["position_kd"] == [0.0, 0.0]
    out = tmp_path / "tuned.toml"
    out.write_text(t["toml"])
    assert feedid.structure(out)["bandwidth_hz"] == pytest.approx(15.0, rel=1e-6)


def test_the_papers_cascade_reads_as_a_structure_with_its_seventh_order_closed_loop():
    paper = pathlib.Path(__file__).resolve().parents[2] / "examples" / "paper.toml"
    s = feedid.structure(paper)
    assert s["stable"]
    assert len(s["poles"]) == 7
    assert len(s["denominator"]) == 8
    assert s["following_error_per_velocity"] == pytest.approx(1.0 / 700.0, rel=1e-9)
