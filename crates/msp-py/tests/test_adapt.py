"""The Python module's adaptation: the estimator, the adaptive controller
per sample, the monitor, against the core and the CLI."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import msp
from _shared import MSP_BIN, ROOT, _same, cli_csv  # noqa: F401


def test_estimator_decimates_and_finds_load_onsets():
    """msp.Estimator(decimation=10) in a PI loop on 1.6 e^(-6 s)/(10 s + 1) sampled at 0.05 s
    (120 samples of dead time, 12 of its own): started from the true model, an output load
    and an input load at rest are each an onset, and the estimate stays the process's."""
    ts, k, tau, d = 0.05, 1.6, 10.0, 120
    a = math.exp(-ts / tau)
    est = msp.Estimator(ts=ts, d_min=4, decimation=10)
    est.start_from(k, tau, d * ts)
    kp, ki = 0.4 / k, 0.4 / k * ts / tau
    y, integral, line = 0.0, 0.0, [0.0] * d
    blocks = 0
    learnt = {}
    for j in range(60000):
        if j % 10000 == 0:
            learnt[j] = est.learnt
        d_out = 0.3 if j >= 20000 else 0.0
        d_in = 0.2 if j >= 40000 else 0.0
        e = 1.0 - (y + d_out)
        integral += ki * e
        u = kp * e + integral
        blocks += est.update(y + d_out, u)
        late, line[j % d] = line[j % d], u + d_in
        y = a * y + k * (1 - a) * late
    # a block's learning ends three samples after the block where it learns
    # (spread over four calls), in the block's own call at rest (nothing
    # but the chosen model runs): the run ends at rest, 20 000 samples after
    # the last load, so the last block's is done too
    assert blocks == 6000
    assert est.onsets == 2
    # each load's response compared in levels by the level test (the onset
    # opens it), those taken as evidence among them
    compared, used = est.level_responses
    assert compared >= 2 and 0 <= used <= compared, est.level_responses
    # step loads are no ramps
    assert est.level_ramps == 0, est.level_ramps
    # it learns from the controller's answer to each load, and nothing at
    # rest (the last 10 000 samples)
    assert learnt[30000] > learnt[20000] and learnt[50000] > learnt[40000], learnt
    assert est.learnt == learnt[50000], (est.learnt, learnt)
    e = est.estimate
    assert abs(e["k"] / k - 1) < 0.02 and abs(e["tau"] / tau - 1) < 0.02, e
    assert abs(e["theta"] - d * ts) < 0.5, e

def test_adapt_bound_warns_instead_of_applying():
    """run(adapt={"bound": 1.2}) as msp run --adapt-bound 1.2: the process's gain rises 30 %,
    past the bound on the commissioned gain: the log says "edge" with the estimate's gain,
    the model in use stays; a bound not above 1 is refused."""
    steps = [(float(i % 2), 30.0 * i) for i in range(20)]
    kw = dict(controller="smith", lambda_=2.0, ts=0.1, duration=600.0,
              setpoint=steps, events=["150:plant-gain=1.3"])
    out = msp.run("e^-1s/(4s+1)", adapt={"bound": 1.2}, **kw)
    log = out.report()["adaptation"]
    assert log and all(c["kind"] == "edge" for c in log), log
    assert abs(log[0]["k"] - 1.3) < 0.1
    assert out.signals["k_model"][-1] == 1.0
    with pytest.raises(ValueError, match="bound"):
        msp.run("e^-1s/(4s+1)", adapt={"bound": 1.0}, **kw)

def test_adapt_follows_a_process_lag_that_doubled():
    """run(adapt=True) as msp run --adapt: after the process's lag doubles (4 s -> 8 s), the
    Smith predictor's model in use becomes the process's (within 10 %); without adaptation it
    stays; a bad option is refused by name."""
    steps = [(float(i % 2), 30.0 * i) for i in range(20)]
    kw = dict(controller="smith", lambda_=2.0, ts=0.1, duration=600.0,
              setpoint=steps, events=["150:plant-lag=8"])
    adaptive = msp.run("e^-1s/(4s+1)", adapt=True, **kw)
    fixed = msp.run("e^-1s/(4s+1)", **kw)
    assert abs(adaptive.signals["tau_model"][-1] - 8.0) < 0.8
    assert abs(adaptive.signals["k_model"][-1] - 1.0) < 0.05
    assert abs(adaptive.signals["theta_model"][-1] - 1.0) < 0.1
    assert "tau_model" not in fixed.signals
    log = adaptive.report()["adaptation"]
    assert log and log[-1]["kind"] == "applied" and log[-1]["tau"] == adaptive.signals["tau_model"][-1]
    assert fixed.report()["adaptation"] == []
    # the adaptive state at the end: the report's as the signals' last row (the CLI's JSON
    # alike), under the names of Controller.state
    state = adaptive.report()["adaptive"]
    assert state["learnt"] == adaptive.signals["learnt"][-1] > 0 and fixed.report()["adaptive"] is None
    for name in ("k_model", "tau_model", "theta_model", "onsets", "restarts", "responses", "responses_used", "responses_ramps"):
        assert state[name] == adaptive.signals[name][-1], name
    assert set(state) == set(msp.SmithPredictor("e^-1s/(4s+1)", 0.1, adapt=True).state)
    with pytest.raises(ValueError, match="unknown option 'speed'"):
        msp.run("e^-1s/(4s+1)", adapt={"speed": 1}, **kw)
    with pytest.raises(ValueError, match="dead zone"):
        msp.run("e^-1s/(4s+1)", adapt={"dead_zone": -1.0}, **kw)

def test_monitor_raises_an_alarm_when_the_gain_drifts():
    """run(monitor=True) as msp run --monitor: the process's gain rises 30 % and the alarm is
    raised, the model's error against the process tends to 0.3 (the model predicts y/1.3),
    nothing is applied; the per-sample controller's monitor (adapt={"apply": False}) says the
    same in state["model_alarm"] and state["mismatch"]."""
    steps = [(float(i % 2), 30.0 * i) for i in range(30)]
    kw = dict(controller="smith", lambda_=2.0, ts=0.1, duration=900.0, setpoint=steps,
              events=["150:plant-gain=1.3"])
    out = msp.run("e^-1s/(4s+1)", monitor=True, **kw)
    log = out.report()["adaptation"]
    assert log and all(c["kind"] == "alarm" for c in log) and 150 < log[0]["at"] < 450, log
    assert abs(out.signals["mismatch"][-1] - 0.3) < 0.02
    assert out.signals["model_alarm"][-1] == 1.0 and out.signals["k_model"][-1] == 1.0
    a = math.exp(-0.1 / 4.0)
    c = msp.SmithPredictor("e^-1s/(4s+1)", 0.1, lambda_=2.0, adapt={"apply": False})
    y, line = 0.0, [0.0] * 10
    for k in range(9000):
        u = c.update(1.0 if (k // 300) % 2 == 0 else 0.0, y)
        late, line[k % 10] = line[k % 10], u
        y = a * y + (1.3 if k >= 1500 else 1.0) * (1 - a) * late
    e = c.state
    assert e["model_alarm"] and abs(e["mismatch"] - 0.3) < 0.02 and e["k_model"] == 1.0, e
    # the state is the controller's signals after the last update, under their names
    sig = c.signals
    assert e.keys() - {"frozen"} <= sig.keys(), (e.keys(), sig.keys())
    assert all(float(e[n]) == sig[n] or math.isnan(sig[n]) for n in e.keys() - {"frozen"}), (e, sig)

def test_estimator_finds_gain_lag_and_fractional_dead_time():
    """msp.Estimator on 2 e^(-1.25 s)/(4 s + 1) sampled exactly at Ts = 0.1 (the half sample of
    dead time in b0 = K(1 - a^0.5), b1 = K(a^0.5 - a)) under a switching input: K, tau and
    theta; nothing learnt from samples marked not ok; candidates ended by d_max; bad settings
    refused."""
    a = math.exp(-0.1 / 4.0)
    b0, b1 = 2.0 * (1 - a ** 0.5), 2.0 * (a ** 0.5 - a)
    est = msp.Estimator(ts=0.1, d_min=4)
    idle = msp.Estimator(ts=0.1, d_min=4)
    short = msp.Estimator(ts=0.1, d_min=4, d_max=9)
    assert est.estimate is None
    y, us = 0.0, []
    for k in range(12000):
        u = 1.0 if (k // 150) % 2 else -1.0
        est.update(y, u)
        idle.update(y, u, ok=False)
        short.update(y, u)
        us.append(u)
        late = lambda m: us[k - m] if k >= m else 0.0
        y = a * y + b0 * late(12) + b1 * late(13)
    e = est.estimate
    assert abs(e["k"] - 2.0) < 1e-3 and abs(e["tau"] - 4.0) < 4e-3, e
    assert abs(e["theta"] - 1.25) < 0.01 and e["d"] == 12, e
    assert idle.estimate is None
    # candidates only to d_max = 9: the longest of them, never the process's 12
    assert len(short.costs) == 6 and short.estimate["d"] <= 9, short.estimate  # none past d_max
    with pytest.raises(ValueError):
        msp.Estimator(ts=0.1, d_min=4, d_max=3)
    with pytest.raises(ValueError):
        msp.Estimator(ts=0.0, d_min=4)
    with pytest.raises(ValueError):
        msp.Estimator(ts=0.1, d_min=5000)

def test_estimator_monitor_weighs_the_model_in_use():
    """msp.Estimator's monitor on 2 e^(-1.25 s)/(4 s + 1) sampled exactly: a model in use whose
    gain is 1.4 shows an error of about (2 - 1.4)/1.4 relative to its own prediction, over the
    last response and over the long memory (to 5 %: the rival is the estimator's own model, which
    learns, and over the last response also the change detector's simulations); the process's own
    model none; nothing before a whole response (``window``
    samples) was compared. The measured noise level follows the noise: twice the noise, twice
    the level (to 10 %)."""
    a = math.exp(-0.1 / 4.0)
    b0, b1 = 2.0 * (1 - a ** 0.5), 2.0 * (a ** 0.5 - a)

    def run(k_model, sigma=0.0, samples=6000):
        est = msp.Estimator(ts=0.1, d_min=4)
        est.set_reference(k_model, 4.0, 1.25)
        rng = np.random.default_rng(7)
        y, us = 0.0, []
        for k in range(samples):
            u = 1.0 if (k // 150) % 2 else -1.0
            est.update(y + sigma * rng.standard_normal(), u)
            if k < est.window:
                assert est.mismatch is None and est.recent_mismatch is None
            us.append(u)
            late = lambda m: us[k - m] if k >= m else 0.0
            y = a * y + b0 * late(12) + b1 * late(13)
        return est

    wrong, right = run(1.4), run(2.0)
    expected = 0.6 / 1.4
    assert abs(wrong.recent_mismatch["error"] - expected) < 0.05 * expected, wrong.recent_mismatch
    assert abs(wrong.mismatch["error"] - expected) < 0.05 * expected, wrong.mismatch
    assert wrong.mismatch["evidence"] > 100
    assert right.mismatch["error"] < 0.01 and right.recent_mismatch["error"] < 0.01
    levels = [run(2.0, sigma, 3000).noise_level for sigma in (0.01, 0.02)]
    assert 0 < levels[0] and abs(levels[1] / levels[0] - 2.0) < 0.2, levels
    with pytest.raises(ValueError):
        msp.Estimator(ts=0.1, d_min=4).set_reference(0.0, 4.0, 1.25)

def test_estimator_detects_a_dead_time_step():
    """msp.Estimator started from the process 2 e^(-1.25 s)/(4 s + 1) whose dead time steps to
    1.65 s at sample 6000: the change detector restarts the candidates once (never before the
    step), and the estimated dead time is right within two of its windows (4 + 16 + 4 tau/Ts =
    180 samples each) and the bank's hold of 50 — the costs' comparison alone takes thousands."""
    a = math.exp(-0.1 / 4.0)
    b0, b1 = 2.0 * (1 - a ** 0.5), 2.0 * (a ** 0.5 - a)
    est = msp.Estimator(ts=0.1, d_min=4)
    est.start_from(2.0, 4.0, 1.25)
    y, us, right_from = 0.0, [], None
    for k in range(9000):
        u = 1.0 if (k // 150) % 2 else -1.0
        est.update(y, u)
        if k < 6000:
            assert est.restarts == 0
        else:
            e = est.estimate
            right = e is not None and abs(e["theta"] - 1.65) < 0.05 and abs(e["k"] - 2.0) < 0.1
            right_from = (right_from if right_from is not None else k) if right else None
        us.append(u)
        late = lambda m: us[k - m] if k >= m else 0.0
        d = 12 if k < 6000 else 16
        y = a * y + b0 * late(d) + b1 * late(d + 1)
    assert est.restarts == 1
    assert right_from is not None and right_from < 6000 + 2 * 180 + 50, right_from

def test_adaptive_controller_per_sample():
    """msp.SmithPredictor(..., adapt=True) one sample at a time against the exact sampled
    process e^(-s)/(8s + 1) (the model said 4 s): the model in use becomes the process's;
    frozen, it learns nothing (the estimate stays the model it started from); a controller that
    does not adapt refuses freeze()."""
    a = math.exp(-0.1 / 8.0)

    def loop(c, samples=6000):
        y, line = 0.0, [0.0] * 10
        for k in range(samples):
            r = 1.0 if (k // 300) % 2 == 0 else 0.0
            u = c.update(r, y)
            late, line[k % 10] = line[k % 10], u
            y = a * y + (1 - a) * late

    c = msp.SmithPredictor("e^-1s/(4s+1)", 0.1, lambda_=2.0, adapt=True)
    assert c.state["tau_model"] == 4.0
    # the estimator's counts, as msp.Estimator's: nothing learnt before any data
    counts = ("learnt", "onsets", "restarts", "responses", "responses_used", "responses_ramps")
    assert [c.state[n] for n in counts] == [0] * 6
    loop(c)
    e = c.state
    assert abs(e["tau_model"] - 8.0) < 0.8 and abs(e["k_model"] - 1.0) < 0.05, e
    # learnt from most of the 6000 samples (the set point moves every 300)
    assert 1000 < e["learnt"] <= 6000 and isinstance(e["learnt"], int), e
    # the dead time identified: its evidence past what a switch of dead time needs (20)
    assert e["evidence"] >= 20.0, e
    # the log: every change applied, the last one the model in use, in time order
    log = c.log
    assert log and all(x["kind"] == "applied" for x in log), log
    assert (log[-1]["k"], log[-1]["tau"], log[-1]["theta"]) == (
        e["k_model"], e["tau_model"], e["theta_model"])
    assert [x["sample"] for x in log] == sorted(x["sample"] for x in log)
    assert all(abs(x["at"] - 0.1 * x["sample"]) < 1e-9 for x in log)
    frozen = msp.SmithPredictor("e^-1s/(4s+1)", 0.1, lambda_=2.0, adapt=True)
    frozen.freeze()
    loop(frozen)
    # frozen: the estimate stays the model it started from, nothing learnt or applied
    assert frozen.state["tau_model"] == 4.0 and abs(frozen.state["tau_hat"] - 4.0) < 1e-9
    assert frozen.state["learnt"] == 0 and frozen.state["frozen"], frozen.state
    assert e["adapt_changes"] == len(log) and e["adapt_kind"] == 1 and not e["frozen"], e
    plain = msp.SmithPredictor("e^-1s/(4s+1)", 0.1)
    assert plain.state is None and plain.log == [] and frozen.log == []
    with pytest.raises(ValueError, match="does not adapt"):
        plain.freeze()


def test_background_design_waits_for_its_call():
    """adapt={"background_design": True}: the filtered Smith predictor, rebuilt for each model,
    is designed between samples (as a device's background task would). msp.run takes the same
    model a sample later; a per-sample controller takes it only when design() is called, and
    without the calls keeps the model it was built for."""
    steps = [(float(i % 2), 30.0 * i) for i in range(20)]
    kw = dict(controller="fsp", ts=0.1, duration=600.0, setpoint=steps, events=["150:plant-lag=8"])
    inline = msp.run("e^-1s/(4s+1)", adapt=True, **kw).report()["adaptation"]
    later = msp.run("e^-1s/(4s+1)", adapt={"background_design": True}, **kw).report()["adaptation"]
    a = [(c["at"], c["tau"]) for c in inline if c["kind"] == "applied"]
    b = [(c["at"], c["tau"]) for c in later if c["kind"] == "applied"]
    assert a and len(a) == len(b)
    for (t1, tau1), (t2, tau2) in zip(a, b):
        assert abs((t2 - t1) - 0.1) < 1e-9 and abs(tau1 - tau2) < 1e-6 * tau1
    a8 = math.exp(-0.1 / 8.0)

    def loop(c, call):
        y, line, built = 0.0, [0.0] * 10, 0
        for k in range(6000):
            r = 1.0 if (k // 300) % 2 == 0 else 0.0
            u = c.update(r, y)
            built += c.design() if call else 0
            late, line[k % 10] = line[k % 10], u
            y = a8 * y + (1 - a8) * late
        return built

    designed = msp.FilteredSmith("e^-1s/(4s+1)", 0.1, adapt={"background_design": True})
    assert designed.design() is False
    assert loop(designed, True) >= 1 and abs(designed.state["tau_model"] - 8.0) < 0.8
    idle = msp.FilteredSmith("e^-1s/(4s+1)", 0.1, adapt={"background_design": True})
    assert loop(idle, False) == 0 and idle.state["tau_model"] == 4.0
    assert msp.SmithPredictor("e^-1s/(4s+1)", 0.1).design() is False
    # the Smith predictor's model changes in place: the option has nothing to act on, and
    # says so (a warning here, msp.run's warnings, as the CLI's)
    with pytest.warns(UserWarning, match="has no effect on this scheme"):
        msp.SmithPredictor("e^-1s/(4s+1)", 0.1, adapt={"background_design": True})
    run = msp.run("e^-1s/(4s+1)", controller="smith", ts=0.1, duration=60.0, adapt={"background_design": True})
    assert any("has no effect" in w for w in run.warnings), run.warnings
    assert not any("background" in w for w in msp.run("e^-1s/(4s+1)", adapt={"background_design": True}, **kw).warnings)
