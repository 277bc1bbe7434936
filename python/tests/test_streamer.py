"""feedid.Streamer against feedid.identify: where the streamer has the
same data (each window waits for its command, or the command lead covers
the horizon) its predictions are identify's, sample for sample."""

import math

import numpy as np
import pytest

import feedid


def by_sample(t, rows, column=1):
    """Predictions (or bounds: column 2, 3) keyed by sample index (the latest
    wins, as in batch); forecasts past the last sample (the last window's
    horizon) left out."""
    t = np.asarray(t)
    out = {}
    for row in rows:
        time, y = row[0], row[column]
        if time > t[-1] + 0.5 * (t[-1] - t[-2]):
            continue
        # measured samples carry their time; horizons not yet measured carry
        # t_last + m·dt, equal to the sample time up to rounding
        k = int(np.argmin(np.abs(t - time)))
        assert abs(t[k] - time) <= 1e-9 * max(1.0, abs(time)), f"time {time} is not a sample time"
        out[k] = y
    return out


@pytest.mark.parametrize("method", ["auto", "arx", "paper", "nn"])
@pytest.mark.parametrize("scenario", ["multisine", "ramp"])
def test_streamer_waiting_for_its_command_predicts_what_identify_predicts(method, scenario):
    rec = feedid.simulate(scenario, seed=4)
    run = feedid.identify(rec, method=method)
    s = feedid.Streamer(method=method, extrapolate="wait" if method != "paper" else None)
    rows = []
    for t, u, y in zip(rec.time, rec.command, rec.position):
        rows += s.push(t, u, y)
    rows += s.finish()
    got = by_sample(rec.time, rows)
    want = {k: v for k, v in enumerate(run.predicted) if not math.isnan(v)}
    assert len(want) > 0.5 * len(rec)
    assert set(got) == set(want)
    scale = float(np.ptp(rec.position))
    err = max(abs(got[k] - want[k]) for k in want)
    assert err <= 1e-12 * scale, err
    # the same intervals as identify's, around the prediction
    for col, arr in [(2, run.lower), (3, run.upper)]:
        b = by_sample(rec.time, rows, col)
        assert max(abs(b[k] - arr[k]) for k in want) <= 1e-12 * scale
    for _, y, lo, hi in rows:
        assert lo <= y <= hi
    st = s.stats
    assert st["lines"] == len(rec) and st["samples_scored"] == len(want)
    assert st["rms_error_m"] == pytest.approx(run.summary["rms_error_m"], rel=1e-9)


def test_a_command_lead_covering_the_horizon_gives_identify_predictions_ahead():
    rec = feedid.simulate("chirp", seed=5)
    run = feedid.identify(rec, method="arx", horizon=8)
    lead = 8
    t, u, y = rec.time, rec.command, rec.position
    n = len(t)
    # line j: time and position of sample j, command of sample j + lead
    u_ahead = np.concatenate([u[lead:], np.full(lead, u[-1])])
    s = feedid.Streamer(method="arx", horizon=8, command_lead=lead)
    rows = s.push_many(t, u_ahead, y) + s.finish()
    # the first `lead` positions have no command: sample j is line j + lead
    got = {k - lead: p for k, p in by_sample(t, rows).items()}
    # the stream's samples are the recording shifted by the lead
    shifted = feedid.identify(t[lead:], u[lead:], y[lead:], method="arx", horizon=8)
    want = {k: v for k, v in enumerate(shifted.predicted) if not math.isnan(v)}
    common = set(want) & set(got)
    assert len(common) > 0.9 * len(want)
    scale = float(np.ptp(y))
    assert max(abs(got[k] - want[k]) for k in common) <= 1e-12 * scale
    assert s.stats["predicted_late"] == 0 and s.stats["unused_positions"] == lead
    assert run.summary["samples_predicted"] > 0


def test_push_refuses_time_going_back_and_keeps_going():
    s = feedid.Streamer(rate=1000.0, method="arx")
    s.push(0.0, 0.0, 0.0)
    s.push(0.001, 0.0, 0.0)
    with pytest.raises(feedid.InputError) as e:
        s.push(0.001, 0.0, 0.0)
    assert isinstance(e.value, ValueError)
    s.push(0.002, 0.0, 0.0)
    assert s.stats["samples"] == 3
    with pytest.raises(feedid.InputError, match="auto"):
        feedid.Streamer(order="auto")
