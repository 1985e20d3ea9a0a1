"""The Python module against the CLI, the core and python-control."""

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


@pytest.mark.skipif(not pathlib.Path(MSP_BIN).exists(), reason="the msp binary is not built")
@pytest.mark.parametrize(
    "plant, args, kwargs",
    [
        ("0.2/s*e^-7.4s", [], {}),
        ("5.6*e^-93.9s/(40.2s+1)", ["--controller", "smith", "--set", "kp=0.05", "--ts", "0.7",
                                    "--disturbance", "input:-0.1@300"],
         {"controller": "smith", "params": {"kp": 0.05}, "ts": 0.7, "disturbance": "input:-0.1@300"}),
        ("e^-10s/(s+1)^2", ["--noise", "0.01", "--seed", "7", "--setpoint", "1@0", "--setpoint", "2@50"],
         {"noise": 0.01, "seed": 7, "setpoint": [(1.0, 0.0), (2.0, 50.0)]}),
        ("0.2/s*e^-7.4s", ["--float32"], {"float32": True}),
    ],
)
def test_results_equal_the_cli_bit_for_bit(plant: str, args: list[str], kwargs: dict) -> None:
    ref = cli_csv("--plant", plant, *args)
    res = msp.run(plant, **kwargs)
    for key in ("t", "r", "y", "u", "d"):
        assert np.array_equal(getattr(res, key), ref[key]), key
    for name, values in res.signals.items():
        assert np.array_equal(values, ref[name]), name

@pytest.mark.skipif(not pathlib.Path(MSP_BIN).exists(), reason="the msp binary is not built")
@pytest.mark.parametrize("plant, args", [("0.2/s*e^-7.4s", []), ("5*e^-6s/(100s-1)", ["--duration", "60"])])
def test_the_run_report_is_the_clis(plant: str, args: list[str], tmp_path: pathlib.Path) -> None:
    path = tmp_path / "report.json"
    subprocess.run([MSP_BIN, "run", "-q", "--plant", plant, *args, "--report", str(path),
                    "--output", str(tmp_path / "run.csv")], check=True)
    cli = json.loads(path.read_text())
    res = msp.run(plant, duration=60.0) if args else msp.run(plant)
    _same(res.report(), cli)
    assert res.metrics["iae"] == cli["metrics"]["iae"] and res.plant_kind == cli["plant_kind"]

def test_figures_read_in_any_order_are_the_runs() -> None:
    """msp.run computes its metrics, event figures and analysis when first read: read in any order,
    they are the same as when read together, and the signals they come from are read-only."""
    args = ("5.6*e^-93.9s/(40.2s+1)", "pi", {"kp": 0.0501, "ti": 47.3})
    kw = dict(setpoint=1.0, disturbance="input:-0.1@1500", ts=0.1, duration=3000.0)
    whole = msp.run(*args, **kw).report()
    a = msp.run(*args, **kw)
    assert a.stable is True and a.robustness["pm"] == whole["robustness"]["pm"]
    assert a.metrics == whole["metrics"] and a.events == whole["events"]
    b = msp.run(*args, **kw)
    assert b.events == whole["events"] and b.warnings == whole["warnings"]
    assert b.report() == whole and a.report() == whole
    assert not any(getattr(a, k).flags.writeable for k in ("t", "r", "y", "u"))
    with pytest.raises(ValueError, match="read-only"):
        a.y[0] = 1.0

def test_a_runs_arrays_are_its_own_whatever_ran_before() -> None:
    """A freed run's buffers serve the next run (no fresh pages to fault in): the arrays a
    result holds never change under later runs, and a run writes every element it reports —
    a load column of zeros after a run with a load, the controller's signals under other
    names, a shorter run in longer buffers."""
    plant = "5.6*e^-93.9s/(40.2s+1)"
    quiet = dict(setpoint=1.0, ts=0.1, duration=600.0)

    def columns(res):
        cols = {k: np.array(getattr(res, k)) for k in ("t", "r", "y", "u", "d", "d_out")}
        cols.update({f"signals.{k}": np.array(v) for k, v in res.signals.items()})
        return cols

    def same(a, b):
        assert a.keys() == b.keys()
        for k in a:
            assert np.array_equal(a[k], b[k]), k

    first = msp.run(plant, "pi", {"kp": 0.0501, "ti": 47.3}, **quiet)
    kept = columns(first)
    for controller, kw in (("pid", dict(disturbance="input:-0.1@100", duration=3000.0)),
                           ("smith", dict(disturbance="output:0.2@50")),
                           ("pi", dict(disturbance="input:0.3@10", duration=1200.0))):
        other = msp.run(plant, controller, **{**quiet, **kw})
        assert np.any(other.d != 0) or np.any(other.d_out != 0)
        del other
    same(columns(first), kept)
    again = msp.run(plant, "pi", {"kp": 0.0501, "ti": 47.3}, **quiet)
    same(columns(again), kept)
    assert not np.any(again.d) and not np.any(again.d_out) and len(again.t) == 6001

def test_float32_runs_the_controller_in_float32() -> None:
    wide = msp.run("0.2/s*e^-7.4s")
    narrow = msp.run("0.2/s*e^-7.4s", float32=True)
    assert narrow.float32 and not wide.float32
    assert np.array_equal(narrow.u.astype(np.float32).astype(np.float64), narrow.u)
    assert not np.array_equal(wide.u.astype(np.float32).astype(np.float64), wide.u)
    assert np.max(np.abs(narrow.y - wide.y)) < 1e-4 * np.max(np.abs(wide.y))

def test_update_many_equals_a_loop_of_update() -> None:
    rng = np.random.default_rng(3)
    r = np.ones(500)
    y = rng.normal(size=500).cumsum() * 0.01
    for make in (lambda: msp.SmithPredictor("5.6*e^-93.9s/(40.2s+1)", 1.0),
                 lambda: msp.KaranDey("0.2/s*e^-7.4s", 0.074),
                 lambda: msp.Pid(1.2, 3.0, 0.5, ts=0.1, umin=-1, umax=1)):
        a, b = make(), make()
        many = a.update_many(r, y)
        loop = np.array([b.update(ri, yi) for ri, yi in zip(r, y)])
        assert np.array_equal(many, loop)

def test_controller_classes_expose_signals_and_params() -> None:
    c = msp.SmithPredictor("5.6*e^-93.9s/(40.2s+1)", 1.0)
    assert c.name == "smith"
    assert math.isclose(c.params["kp"], 40.2 / (5.6 * 93.9))
    c.update(1.0, 0.0)
    c.update(1.0, 0.0)
    assert c.ym > 0 and c.signals["ym"] == c.ym
    c.reset()
    assert c.ym == 0.0
    with pytest.raises(AttributeError):
        c.not_a_signal  # noqa: B018

def test_every_registry_scheme_has_a_class() -> None:
    assert msp._check_classes() == []

def test_controllers_list_their_design_keys() -> None:
    by_name = {c["name"]: c for c in msp.controllers()}
    assert by_name["gpcc"]["design"] == ["lambda", "alpha", "lambda2", "epsilon", "tk"]
    # F's a and b are parameters (the PI's design does not read them): a
    # value given replaces the tuned one
    assert by_name["filtered-smith"]["design"] == ["lambda", "alpha"]
    base = msp.tune("5.6*e^-93.9s/(40.2s+1)", "filtered-smith")["controller"]["params"]
    tuned = msp.tune("5.6*e^-93.9s/(40.2s+1)", "filtered-smith", params={"b": 7.0})["controller"]["params"]
    assert tuned["b"] == 7.0 and base["b"] != 7.0

def test_errors_are_value_errors_naming_the_column() -> None:
    with pytest.raises(ValueError, match="column 5"):
        msp.run("0.2/x*e^-7.4s")
    with pytest.raises(ValueError, match="unknown controller"):
        msp.run("0.2/s*e^-7.4s", controller="nope")
    with pytest.raises(ValueError, match="no parameter 'zeta'"):
        msp.run("0.2/s*e^-7.4s", params={"zeta": 1.0})
    with pytest.raises(ValueError, match="ts"):
        msp.Pid(1.0, ts=0.0)

def test_metrics_match_the_thesis() -> None:
    res = msp.run("0.2/s*e^-7.4s", setpoint=1.0)  # the set-point step alone (Table 5.4)
    assert res.controller["name"] == "karan-dey" and not res.default_scenario
    assert abs(res.metrics["rise_time"] - 2.04) < 0.03
    assert abs(res.metrics_delayed_reference["iae"] - 0.93) < 0.014
    assert set(res.metrics) == set(res.metrics_delayed_reference) == {
        "iae", "ise", "itae", "itse", "tv", "rise_time", "settling_time", "settling_min",
        "settling_max", "overshoot", "undershoot", "peak", "peak_time"}

def test_python_control_transfer_function_with_delay() -> None:
    control = pytest.importorskip("control")
    tf = control.tf([5.6], [40.2, 1.0])
    a = msp.run(tf, delay=93.9, ts=1.0)
    b = msp.run("5.6*e^-93.9s/(40.2s+1)", ts=1.0)
    assert np.array_equal(a.y, b.y)
    assert msp.tune((tf, 93.9)) == msp.tune("5.6*e^-93.9s/(40.2s+1)")

@pytest.mark.parametrize("scheme,plant,ts", [
    ("pid", "e^-2s/(2s+1)", 0.25), ("smith", "e^-0.5s/(s+1)", 0.1),
    ("karan-dey", "0.2/s*e^-7.4s", 0.74), ("watanabe-ito", "0.2/s*e^-7.4s", 0.74),
    ("fsp", "e^-1s/(5s-1)", 0.1), ("huang", "e^-2s/(2s+1)", 0.25),
    # a dead time of 2.5 samples: the plant by the modified z-transform
    ("smith", "e^-0.25s/(s+1)", 0.1),
])
def test_to_control_is_the_loop_msp_analyses(scheme: str, plant: str, ts: float) -> None:
    control = pytest.importorskip("control")
    c = msp.Controller(scheme, plant, ts)
    sys = c.to_control()
    assert set(sys) == {"cr", "cy", "plant", "L", "S", "T"} and all(s.dt == ts for s in sys.values())
    # python-control's own margin of L against msp's sampled-loop analysis
    gm, pm, wcg, wcp = control.margin(sys["L"])
    m = msp.margins(plant, scheme, ts=ts, discrete=True)
    for ours, theirs in [(m["gm"], gm), (m["pm"], pm), (m["wcg"], wcg), (m["wcp"], wcp)]:
        assert math.isclose(ours, theirs, rel_tol=1e-6) or (math.isinf(ours) and math.isinf(theirs))
    # S + T = 1 and L = Cy·P, at frequencies across the band
    w = np.linspace(0.01, 0.99, 7) * math.pi / ts
    one = control.frequency_response(sys["S"], w).complex + control.frequency_response(sys["T"], w).complex
    assert np.allclose(one, 1.0, atol=1e-9)
    lp = control.frequency_response(sys["cy"] * sys["plant"], w).complex
    assert np.allclose(lp, control.frequency_response(sys["L"], w).complex, rtol=1e-9)
    # the coefficients msp tune --json prints
    t = msp.tune(plant, scheme, ts=ts)["transfer"]
    num, den = sys["L"].num[0][0], sys["L"].den[0][0]
    assert np.allclose(np.trim_zeros(np.array(t["l"]["num"]), "f"), num)
    assert np.allclose(np.array(t["l"]["den"]), den)
    # per sample: u = Cr·r − Cy·y from the controller object itself, at
    # rest before the first sample (a step there kicks a derivative as the
    # transfer functions from rest do)
    n = 200
    k = np.arange(n)
    r, y = np.ones(n), 0.2 + np.sin(0.3 * k)
    c.reset_to_rest()
    u = np.array([c.update(float(a), float(b)) for a, b in zip(r, y)])
    _, ur = control.forced_response(sys["cr"], T=k * ts, U=r)
    _, uy = control.forced_response(sys["cy"], T=k * ts, U=y)
    assert np.allclose(u, ur - uy, rtol=1e-8, atol=1e-9)

def test_a_run_starts_the_loop_at_rest_as_to_control_does() -> None:
    # a PID with a derivative (the Smith predictor on an integrator with a
    # lag: td 0.43) and the set point's step at the first sample: the run's
    # input is Cr·r − Cy·y from rest, the derivative's kick included
    control = pytest.importorskip("control")
    plant, ts = "2/(s*(3s+1))*e^-1s", 0.05
    res = msp.run(plant, "smith", ts=ts, duration=10)
    c = msp.Controller("smith", plant, ts)
    assert c.params["td"] > 0 and res.t[0] == 0 and res.r[0] == 1
    sys = c.to_control()
    _, ur = control.forced_response(sys["cr"], T=res.t, U=res.r)
    _, uy = control.forced_response(sys["cy"], T=res.t, U=res.y)
    # (Cr·r and Cy·y are each some 800 where the input settles near 0: the
    # rounding of the two order-24 recursions, relative to their size)
    scale = max(np.abs(ur).max(), np.abs(uy).max())
    assert np.allclose(res.u, ur - uy, rtol=0, atol=1e-10 * scale)
    # and the controller object reset to rest gives the same, sample for sample
    c.reset_to_rest()
    u = c.update_many(np.asarray(res.r), np.asarray(res.y))
    assert np.array_equal(u, res.u)
    # reset instead: the first sample is the derivative's reference (no kick)
    c.reset()
    assert c.update(1.0, 0.0) < res.u[0]

def test_to_control_of_a_cascade_gives_the_controller_only() -> None:
    pytest.importorskip("control")
    c = msp.Controller("gpcc", "2e^-2s/s", 0.1, inner_plant="4e^-2s/(s+1)")
    assert set(c.to_control()) == {"cr", "cy"}

def test_parse_plant_round_trip() -> None:
    p = msp.parse_plant("e^-10s/(s+1)^2")
    assert p.num == [1.0] and p.den == [1.0, 2.0, 1.0] and p.delay == 10.0 and p.kind == "stable"
    assert msp.parse_plant(str(p)) == p

def test_to_pandas_and_plot(tmp_path: pathlib.Path) -> None:
    res = msp.run("0.2/s*e^-7.4s", duration=30)
    pd = pytest.importorskip("pandas")
    df = res.to_pandas()
    assert isinstance(df, pd.DataFrame) and list(df.columns)[:4] == ["r", "y", "u", "d"]
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    fig = res.plot()
    fig.savefig(tmp_path / "x.png")
    assert (tmp_path / "x.png").stat().st_size > 1000

EXAMPLES = sorted((ROOT / "examples").glob("*.py"))

@pytest.mark.parametrize("script", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_examples_write_their_png(script: pathlib.Path, tmp_path: pathlib.Path) -> None:
    pytest.importorskip("matplotlib")
    env = dict(os.environ, MPLBACKEND="Agg")
    subprocess.run([sys.executable, str(script), str(tmp_path)], check=True, env=env, cwd=tmp_path)
    pngs = list(tmp_path.glob("*.png"))
    assert pngs and all(p.stat().st_size > 1000 for p in pngs)

def test_compare_matches_the_cli_table_inputs() -> None:
    runs = msp.compare("0.2/s*e^-7.4s", ["karan-dey", "smith"], perturb="delay=+10%", duration=60)
    assert [r.controller["name"] for r in runs] == ["karan-dey", "smith"]
    assert all(r.plant == "0.2*e^(-8.14s)/s" and r.model == "0.2*e^(-7.4s)/s" for r in runs)
    again = msp.compare("0.2/s*e^-7.4s", ["karan-dey"], perturb={"delay": 0.1}, duration=60)
    assert np.array_equal(again[0].y, runs[0].y)

def test_every_scheme_class_runs_per_sample() -> None:
    for cls, plant in [(msp.FilteredSmith, "5.6*e^-93.9s/(40.2s+1)"), (msp.Huang, "5.6*e^-93.9s/(40.2s+1)"),
                       (msp.WatanabeIto, "0.2/s*e^-7.4s"), (msp.AstromHangLim, "0.2/s*e^-7.4s"),
                       (msp.MatausekMicic, "0.2/s*e^-7.4s"), (msp.KayaAtherton, "0.2/s*e^-7.4s"),
                       (msp.DisturbanceEstimator, "0.2/s*e^-7.4s"), (msp.PidLoop, "0.2/s*e^-7.4s")]:
        c = cls(plant, 0.5)
        u = [c.update(1.0, 0.0) for _ in range(5)]
        assert all(np.isfinite(u)), cls
        assert c.name == cls.scheme

def test_rule_selects_a_pid_tuning() -> None:
    zn = msp.tune("0.2/s*e^-7.4s", "pid", rule="zn")["controller"]["params"]
    assert math.isclose(zn["ti"], 0.5 * 4 * 7.4)

def test_run_and_compare_take_every_scenario_field() -> None:
    """The scenario's fields are defined once, in the library, and read once by the compiled
    module (``SCENARIO_KEYWORDS``: ``set`` as ``params``, ``lambda`` as ``lambda_``); the
    public functions type them once (``TuneOptions`` ⊂ ``DesignOptions`` ⊂ ``RunOptions``, with
    ``controller`` and ``params`` in the signatures), each the set its compiled function reads,
    and a keyword that is no field is refused by name."""
    import inspect

    from msp import _msp

    renamed = {"set": "params", "lambda": "lambda_"}
    want = [renamed.get(f, f) for f in _msp.SCENARIO_FIELDS if f != "plant"]
    assert sorted(_msp.SCENARIO_KEYWORDS) == sorted(want)
    named = {"controller", "params"}
    # a matrix plant's own keywords (the CLI's flags), which its run reads beside these
    matrix_only = set(msp.MATRIX_KEYWORDS) - set(_msp.SCENARIO_KEYWORDS)
    assert matrix_only <= set(msp.RunOptions.__annotations__)
    for options, compiled in ((msp.RunOptions, [*_msp.SCENARIO_KEYWORDS, *matrix_only]),
                              (msp.DesignOptions, _msp.DESIGN_KEYWORDS),
                              (msp.TuneOptions, _msp.TUNE_KEYWORDS)):
        assert sorted(set(options.__annotations__) | named) == sorted(compiled), options
    for fn, options in ((msp.run, "RunOptions"), (msp.compare, "RunOptions"),
                        (msp.margins, "DesignOptions"), (msp.sweep, "DesignOptions"),
                        (msp.tune, "TuneOptions")):
        sig = inspect.signature(fn).parameters
        assert sig["scenario"].annotation == f"Unpack[{options}]", fn
        assert "params" in sig and ("controller" in sig or fn is msp.compare), fn
    for call in (lambda: msp.run("1/(s+1)", setpiont=1.0),
                 lambda: msp.compare("1/(s+1)", ["pi"], setpiont=1.0),
                 lambda: msp.margins("1/(s+1)", setpoint=1.0)):
        with pytest.raises(TypeError, match="'setpiont'|'setpoint'"):
            call()
    # every keyword reaches its field: the run's report echoes the scenario
    res = msp.run("2*e^-3s/(4s+1)", "pi", {"kp": 0.5}, ts=0.1, duration=20.0, setpoint=[(1.0, 0.0)],
                  disturbance="input:0.1@10", noise=0.0, seed=3, umin=-5.0, umax=5.0, substeps=2,
                  float32=False, max_memory=1 << 28, events=["5:manual=0.2", "6:auto"],
                  actuator=(-4.0, 4.0), reset_feedback=True, setpoint_ramp=10.0)
    assert res.controller["params"]["kp"] == 0.5 and len(res.t) == 401
    assert res.u_applied is not None and [e["at"] for e in res.operator_events] == [5.0, 6.0]
    # sequences as tuples or lists alike (the compiled module reads either)
    as_list = msp.run("2*e^-3s/(4s+1)", "pi", ts=0.1, duration=20.0, setpoint=[(1.0, 0.0), "2@10"],
                      disturbance=["input:0.1@5"], events=["12:manual=0.3"])
    as_tuple = msp.run("2*e^-3s/(4s+1)", "pi", ts=0.1, duration=20.0, setpoint=((1.0, 0.0), "2@10"),
                       disturbance=("input:0.1@5",), events=("12:manual=0.3",))
    assert np.array_equal(as_list.y, as_tuple.y) and as_list.r[-1] == 2.0 and as_list.d.max() == 0.1

def test_hostile_expressions_raise_not_crash() -> None:
    """Deeply nested and huge expressions raise ValueError; the interpreter survives
    (run in a subprocess so that a crash would show as its exit status)."""
    code = (
        "import msp\n"
        "for expr in ['(' * 6000 + '1' + ')' * 6000, '(' * 2000 + '1' + ')' * 2000,\n"
        "             '1/(s+1)' + '+0' * 5_000_000, '2 3*e^-1s/(s+1)']:\n"
        "    try:\n"
        "        msp.run(expr)\n"
        "    except ValueError as e:\n"
        "        assert len(str(e)) < 400, len(str(e))\n"
        "    else:\n"
        "        raise SystemExit('accepted: ' + expr[:20])\n"
        "for kw in [dict(ts=1e-12), dict(max_memory=1024)]:\n"
        "    try:\n"
        "        msp.run('0.2/s*e^-7.4s', **kw)\n"
        "    except ValueError as e:\n"
        "        assert 'the limit is' in str(e), str(e)\n"
        "    else:\n"
        "        raise SystemExit('accepted: ' + repr(kw))\n"
        "for kw in [dict(grid=2**64 - 1), dict(samples=2**64 - 1)]:\n"
        "    try:\n"
        "        msp.sweep('0.2/s*e^-7.4s', 'karan-dey', gain='-10%..10%', **kw)\n"
        "    except ValueError as e:\n"
        "        assert 'the limit is' in str(e), str(e)\n"
        "    else:\n"
        "        raise SystemExit('accepted: ' + repr(kw))\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "ok"

def test_errors_name_what_the_user_gave() -> None:
    with pytest.raises(ValueError, match="`ti` must be greater than zero"):
        msp.Pid(kp=1.0, ti=0.0, td=0.0, ts=0.1)
    t = np.arange(200) * 0.5
    u = np.where(t >= 5, 1.0, 0.0)
    y = 2.0 * (1 - np.exp(-np.maximum(t - 7, 0) / 10))
    bad = y.copy()
    bad[40] = np.nan
    with pytest.raises(ValueError, match="`output` is not a finite number at data row 41"):
        msp.identify(t, u, bad, "fopdt")
    back = t.copy()
    back[100] = back[99]
    with pytest.raises(ValueError, match="`time` must increase: data row 101"):
        msp.identify(back, u, y, "fopdt")

def test_a_reverse_acting_plant_is_the_mirror_of_its_positive_twin() -> None:
    pos = msp.run("2*e^-3s/(5s+1)")
    neg = msp.run("-2*e^-3s/(5s+1)")
    assert neg.controller["params"]["kp"] == -pos.controller["params"]["kp"] < 0
    assert np.allclose(neg.y, pos.y, rtol=0, atol=1e-12) and np.allclose(neg.u, -pos.u, rtol=0, atol=1e-12)

def test_pi_means_a_pi() -> None:
    res = msp.run("e^-10s/(s+1)^2", controller="pi")
    assert res.controller["name"] == "pi" and res.controller["params"]["td"] == 0.0
    assert msp.run("e^-10s/(s+1)^2", controller="pid").controller["params"]["td"] > 0.0

def test_ti_inf_switches_the_integral_off() -> None:
    res = msp.run("e^-1s/(s+1)", controller="pi", params={"kp": 1.0, "ti": math.inf}, duration=40.0)
    assert abs(res.y[-1] - 0.5) < 1e-9  # K·kp/(1 + K·kp)

def test_a_controller_is_operated_as_in_a_plant() -> None:
    """Manual and back to auto without a bump (the plant, an FOPDT with 100 samples of dead
    time, simulated here exactly); the model's dead time changed at run time within its room."""
    c = msp.Controller("smith", "5.6*e^-93.9s/(40.2s+1)", 0.939, max_dead_time=120.0)
    y_line = [0.0] * 100
    a, b = math.exp(-0.939 / 40.2), 5.6 * (1 - math.exp(-0.939 / 40.2))
    x, u = 0.0, 0.0
    for _ in range(3000):
        u = c.update(1.0, x)
        y_line.append(u)
        x = a * x + b * y_line.pop(0)
    assert c.mode == "auto" and abs(x - 1.0) < 1e-6
    c.manual(u + 0.2)
    assert c.mode == "manual"
    for _ in range(500):
        assert c.update(1.0, x) == u + 0.2
        y_line.append(u + 0.2)
        x = a * x + b * y_line.pop(0)
    c.auto()
    first = c.update(1.0, x)
    assert abs(first - (u + 0.2)) < 0.01, first
    assert c.dead_time == 93.9 or abs(c.dead_time - 93.9) < 1e-9
    c.set_dead_time(112.68)
    assert abs(c.dead_time - 112.68) < 1e-9
    with pytest.raises(ValueError, match="delay"):
        c.set_dead_time(500.0)
    with pytest.raises(ValueError, match="theta"):
        c.set_dead_time(float("nan"))
    with pytest.raises(ValueError):
        c.manual(float("nan"))
    before = c.update(1.0, x)
    c.retune(kp=2 * c.params["kp"], ti=50.0)
    assert c.params["ti"] == 50.0
    assert abs(c.update(1.0, x) - before) < 0.01  # bumpless: one sample of the new law
    with pytest.raises(ValueError, match="not a gain"):
        c.retune(beta=1.0)
    c.ramp_dead_time(100.0, 0.5)
    c.update(1.0, x)
    assert abs(c.dead_time - (112.68 - 0.5 * 0.939)) < 1e-9  # half a sample per sample
    c.set_setpoint_ramp(0.01)
    with pytest.raises(ValueError):
        c.set_setpoint_ramp(0.0)
    named = msp.SmithPredictor("5.6*e^-93.9s/(40.2s+1)", 0.939, max_dead_time=120.0)
    named.set_dead_time(112.68)
    assert abs(named.dead_time - 112.68) < 1e-9
    ramped = msp.run("2*e^-3s/(4s+1)", "smith", setpoint=1.0, duration=60.0, setpoint_ramp=0.1)
    assert ramped.u[0] < 0.2 * msp.run("2*e^-3s/(4s+1)", "smith", setpoint=1.0, duration=60.0).u[0]
    fsp = msp.Controller("fsp", "5*e^-6s/(100s-1)", 0.06, max_dead_time=7.2)
    with pytest.raises(ValueError, match="whole samples"):
        fsp.set_dead_time(7.0)
    fsp.set_dead_time(7.2)  # 120 samples: Fr and S redesigned
    assert abs(fsp.dead_time - 7.2) < 1e-9
    with pytest.raises(ValueError, match="capacity"):
        fsp.set_dead_time(9.0)  # beyond max_dead_time
    with pytest.raises(ValueError, match="no model dead time"):
        msp.Controller("pid", "2*e^-3s/(4s+1)", 0.1).set_dead_time(4.0)
    # a cascade: the dead time from the plant input to y (L1 + L2 = 4 s)
    for scheme in ["fspcc", "gpcc", "uma", "kaya-cascade"]:
        params = {"kpd": 0.0436, "kid": 0.0, "kdd": 0.1206} if scheme == "uma" else None
        cc = msp.Controller(scheme, "2e^-2s/s", 0.1, params, inner_plant="4e^-2s/(s+1)",
                            max_dead_time=5.0)
        assert abs(cc.dead_time - 4.0) < 1e-9, scheme
        cc.set_dead_time(5.0)
        assert abs(cc.dead_time - 5.0) < 1e-9, scheme
        with pytest.raises(ValueError, match="capacity"):
            cc.set_dead_time(6.0)

def test_run_takes_operator_events_and_an_outside_actuator() -> None:
    res = msp.run("2*e^-3s/(4s+1)", "pi", setpoint=1.0, duration=100.0, actuator=(0.0, 0.55))
    assert res.u_applied is not None and res.u_applied.max() <= 0.55 < res.u.max()
    fed = msp.run("2*e^-3s/(4s+1)", "pi", setpoint=1.0, duration=100.0, actuator=(0.0, 0.55),
                  reset_feedback=True)
    own = msp.run("2*e^-3s/(4s+1)", "pi", setpoint=1.0, duration=100.0, umin=0.0, umax=0.55)
    assert abs(fed.metrics["overshoot"] - own.metrics["overshoot"]) < 1.0
    assert res.metrics["overshoot"] > fed.metrics["overshoot"] + 0.5
    ev = msp.run("0.2/s*e^-7.4s", setpoint=1.0, duration=200.0, events=["60:manual=0.3", "120:auto"])
    assert [e["at"] for e in ev.operator_events] == [60.0, 120.0]
    assert ev.operator_events[0]["action"] == {"manual": 0.3}
    k = int(round(90.0 / ev.ts))
    assert ev.u[k] == 0.3 and ev.u_applied[k] == 0.3
    with pytest.raises(ValueError, match="unknown action"):
        msp.run("0.2/s*e^-7.4s", events=["60:beta=3"])
    with pytest.raises(ValueError, match="actuator"):
        msp.run("0.2/s*e^-7.4s", actuator=(1.0, 0.0))
    # the CLI and Python write the same report for the same events
    cli = json.loads(subprocess.run([MSP_BIN, "run", "-q", "--plant", "0.2/s*e^-7.4s", "--setpoint", "1",
                                     "--duration", "200", "--event", "60:manual=0.3", "--event", "120:auto",
                                     "--report", "-", "-o", "/dev/null"],
                                    check=True, capture_output=True, text=True).stdout)
    assert cli["operator_events"] == ev.report()["operator_events"]
    # a cascade process whose primary's transport delay grows at a steady state,
    # the controller told: nothing moves (García et al. (2010) Example 2)
    cas = msp.run("2e^-2s/s", "gpcc", inner_plant="4e^-2s/(s+1)", ts=0.1, setpoint=1.0,
                  duration=300.0, events=["200:plant-dead-time=5", "200:dead-time=5"])
    k = int(round(200.0 / cas.ts))
    assert np.abs(cas.y[k:] - 1.0).max() < 1e-6
    assert all(e["output_change"] < 1e-6 for e in cas.operator_events)

def test_a_plant_from_coefficients_has_the_grammars_degree_bound():
    """msp.Plant(num, den) is bounded as the plant grammar is: degree 256 at most."""
    assert msp.Plant([1.0], [1.0] * 257).order == 256
    with pytest.raises(ValueError, match="256"):
        msp.Plant([1.0], [1.0] * 2001)

def test_arrays_as_python_control_gives_them():
    """python-control's (1, n) outputs (and columns) are taken as the vectors they are; an array
    of another shape, or of things that are not numbers, is the ValueError the docs promise,
    naming the argument."""
    t = np.arange(0.0, 50.0, 0.1)
    y = 1.0 - np.exp(-np.maximum(t - 2.0, 0.0) / 5.0)
    flat = msp.step_info(t, y)
    assert msp.step_info(t[np.newaxis, :], y[np.newaxis, :]) == flat
    assert msp.step_info(t[:, np.newaxis], y) == flat
    u = (t >= 1.0).astype(float)
    assert msp.identify(t[np.newaxis, :], u[np.newaxis, :], y[np.newaxis, :])["model"] == \
        msp.identify(t, u, y)["model"]
    with pytest.raises(ValueError, match="y: a vector"):
        msp.step_info(t, np.ones((2, t.size)))
    with pytest.raises(ValueError, match="t: not an array"):
        msp.step_info(["a", "b"], [1.0, 2.0])
