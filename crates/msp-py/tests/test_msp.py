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

ROOT = pathlib.Path(__file__).resolve().parents[3]
MSP_BIN = os.environ.get("MSP_BIN", str(ROOT / "target" / "debug" / "msp"))


def cli_csv(*args: str) -> dict[str, np.ndarray]:
    out = subprocess.run([MSP_BIN, "run", "-q", *args], check=True, capture_output=True, text=True).stdout
    rows = list(csv.reader(io.StringIO(out)))
    header, data = rows[0], rows[1:]
    return {h: np.array([float(r[i]) for r in data]) for i, h in enumerate(header)}


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


def _same(py: object, cli: object, where: str = "") -> None:
    """``py`` equals the JSON value ``cli``: NaN where the JSON has null, floats bit for bit."""
    if isinstance(cli, dict):
        assert isinstance(py, dict) and set(py) == set(cli), (where, py, cli)
        for k in cli:
            _same(py[k], cli[k], f"{where}.{k}")
    elif isinstance(cli, list):
        assert isinstance(py, list) and len(py) == len(cli), where
        for i, (a, b) in enumerate(zip(py, cli)):
            _same(a, b, f"{where}[{i}]")
    elif cli is None and isinstance(py, float):
        assert math.isnan(py), where
    else:
        assert py == cli, (where, py, cli)


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


def test_margins_agree_with_python_control_on_the_exact_delay_loop() -> None:
    control = pytest.importorskip("control")
    kp, ti = 0.0501, 47.3
    m = msp.margins("5.6*e^-93.9s/(40.2s+1)", "pid", {"kp": kp, "ti": ti, "td": 0.0}, ts=0.05)
    w = np.logspace(-4, 0, 20_000)
    s = 1j * w
    loop = kp * (1 + 1 / (ti * s)) * 5.6 * np.exp(-93.9 * s) / (40.2 * s + 1)
    gm, pm, _, wpc, wgc, _ = control.stability_margins(control.frd(loop, w))
    assert math.isclose(m["gm"], gm, rel_tol=0.01)
    assert math.isclose(m["pm"], pm, rel_tol=0.01)
    assert math.isclose(m["wcg"], wpc, rel_tol=0.01)
    assert math.isclose(m["wcp"], wgc, rel_tol=0.01)
    assert m["stable"] and math.isclose(m["dm"], math.radians(m["pm"]) / m["wcp"], rel_tol=1e-9)


def test_step_is_the_open_loop_response() -> None:
    s = msp.step("2*e^-1.3s/(5s+1)")
    exact = np.where(s["t"] > 1.3, 2.0 * (1.0 - np.exp(-(s["t"] - 1.3) / 5.0)), 0.0)
    assert np.allclose(s["y"], exact, atol=1e-12, rtol=0.0)
    assert s["dc_gain"] == 2.0 and math.isclose(s["rise_time"], 5.0 * math.log(9.0), rel_tol=1e-4)
    cli = json.loads(subprocess.run([MSP_BIN, "step", "--plant", "2*e^-1.3s/(5s+1)", "--json"],
                                    check=True, capture_output=True, text=True).stdout)
    assert cli == {k: v for k, v in s.items() if k not in ("t", "y")}
    i = msp.step("0.2/s*e^-7.4s")
    assert i["dc_gain"] is None and math.isnan(i["rise_time"])


def test_margins_of_the_bare_plant_are_matlabs() -> None:
    m = msp.margins("1/(s^3+2s^2+3s+4)", continuous=True)
    assert m["controller"]["name"] == "none" and m["view"] == "continuous"
    assert math.isclose(m["gm"], 2.0, rel_tol=1e-9) and math.isclose(m["wcg"], math.sqrt(3.0), rel_tol=1e-9)
    assert math.isclose(msp.margins("1/(s^3+2s^2+3s+4)", "none", {"kp": 0.5}, continuous=True)["gm"], 4.0,
                        rel_tol=1e-9)
    assert msp.margins("1/(s^3+2s^2+3s+4)")["gm"] < 1.95
    with pytest.raises(ValueError):
        msp.margins("1/(s+1)", discrete=True, continuous=True)


def test_continuous_verdicts_and_margins_agree_with_python_control() -> None:
    """python-control's own margin fixtures (control/tests/margin_test.py), the plant alone in the
    continuous view: the verdict is the closed loop's poles' (control.feedback), the margins
    python-control's (its gm of a loop stable only above a gain is msp's gm_lower; a phase margin
    past 180 degrees is wrapped as python-control wraps it)."""
    control = pytest.importorskip("control")
    s = control.tf("s")
    cases = [
        ("(s+2)/(s^2+2s+3)", (s + 2) / (s**2 + 2 * s + 3)),
        ("1/(s^3+2s^2+3s+4)", 1 / (s**3 + 2 * s**2 + 3 * s + 4)),
        ("3(10+s)/(2+s)", 3 * (10 + s) / (2 + s)),
        ("0.01(10-s)/((2+s)(1+s))", 0.01 * (10 - s) / (2 + s) / (1 + s)),
        ("2s/(s+1)", 2 * s / (s + 1)),
        ("2/(s+1)^3", 2 / (s + 1) ** 3),
        ("(s+0.1)/(s(s+1))", (s + 0.1) / s / (s + 1)),
        ("(s+0.1)/(s^2(s+1))", (s + 0.1) / s**2 / (s + 1)),
        ("(s+0.1)^2/(s^3(s+1))", (s + 0.1) ** 2 / s**3 / (s + 1)),
        ("(s-18)/(s^2-3s-10)", (s - 18) / (s**2 - 3 * s - 10)),
    ]
    for text, sys in cases:
        m = msp.margins(text, continuous=True)
        stable = bool(np.all(np.real(control.feedback(sys, 1).poles()) < 0))
        assert m["stable"] == stable, (text, m["stability"])
        if not stable:
            continue
        gm, pm, _, wpc, wgc, _ = control.stability_margins(sys)
        ours_gm = m["gm_lower"] if m["gm_lower"] > 0 else m["gm"]
        assert math.isclose(ours_gm, gm, rel_tol=2e-3) or (math.isinf(ours_gm) and math.isinf(gm)), text
        pm_ours = m["pm"] - 360.0 if math.isfinite(m["pm"]) and m["pm"] > 180.0 else m["pm"]
        assert math.isclose(pm_ours, pm, rel_tol=2e-3) or (math.isinf(pm_ours) and math.isinf(pm)), text
        if math.isfinite(wgc):
            assert math.isclose(m["wcp"], wgc, rel_tol=2e-3), text


def test_margins_phase_is_unwrapped_as_matlabs_bode() -> None:
    m = msp.margins("e^-20s/(s+1)", continuous=True)
    want = np.degrees(-np.arctan(m.w) - 20.0 * m.w)
    assert np.allclose(m.phase_unwrapped, want, rtol=1e-9, atol=1e-9)
    k = msp.margins("0.2/s*e^-7.4s", "karan-dey")
    # where the plot shows it (dense in the delay's turning): no jump of a turn between points
    shown = k.w <= 10 * max(k.wcg, k.wcp)
    assert np.all(np.abs(np.diff(k.phase_unwrapped[shown])) < 90.0)


def test_margins_of_the_thesis_plant_point_to_the_printed_tables() -> None:
    m = msp.margins("0.2/s*e^-7.4s", "karan-dey")
    assert "Table 5.1" in m["published"] and math.isclose(m["gm_db"], 4.55, abs_tol=0.01)
    assert "published" not in msp.margins("0.3/s*e^-7.4s", "karan-dey")


def test_tune_rules_is_the_cli_table_and_amigo_is_the_published_rule() -> None:
    rows = msp.tune_rules("2*e^-3s/(4s+1)")
    cli = json.loads(subprocess.run([MSP_BIN, "tune", "--plant", "2*e^-3s/(4s+1)", "--rules", "--json"],
                                    check=True, capture_output=True, text=True).stdout)["rules"]
    assert [(r["rule"], r["controller"]) for r in rows] == [(r["rule"], r["controller"]) for r in cli]
    amigo = next(r for r in rows if r["rule"] == "amigo" and r["controller"] == "pi")
    k, t, l = 2.0, 4.0, 3.0  # Astrom & Hagglund (2004): AMIGO PI for a FOPDT
    kp = 0.15 / k + (0.35 - l * t / (l + t) ** 2) * t / (k * l)
    ti = 0.35 * l + 13 * l * t * t / (t * t + 12 * l * t + 7 * l * l)
    p = amigo["tuning"]["params"]
    assert math.isclose(p["kp"], kp, rel_tol=1e-12) and math.isclose(p["ti"], ti, rel_tol=1e-12)
    assert amigo["tuning"]["tuning"]["b"] == 0.0
    res = msp.run("2*e^-3s/(4s+1)", "pi", rule="amigo")
    assert math.isclose(res.controller["params"]["kp"], kp, rel_tol=1e-12)


def test_design_target_is_met_and_reported() -> None:
    t = msp.tune("2*e^-3s/(4s+1)", "pi", target="ms=1.4")
    assert t["controller"]["target"]["target"] == "ms=1.4"
    assert math.isclose(t["robustness"]["ms"], 1.4, rel_tol=1e-3)
    res = msp.run("2*e^-3s/(4s+1)", "smith", target="pm=70")
    assert math.isclose(res.controller["target"]["achieved"], 70.0, rel_tol=1e-3)
    with pytest.raises(ValueError, match="out of reach"):
        msp.tune("0.2/s*e^-7.4s", "karan-dey", target="ms=1.4")
    with pytest.raises(ValueError, match="Ms > 1"):
        msp.tune("2*e^-3s/(4s+1)", target="ms=0.9")


def test_a_crossover_with_a_phase_margin_gives_pidtunes_pi() -> None:
    # MathWorks' dead-time example: pidtune(P, pidstd(1,1), 0.006) gives Kp 0.0501, Ti 47.3
    t = msp.tune("5.6e^-93.9s/(40.2s+1)", "pi", target="wc=0.006,pm=60")
    p = t["controller"]["params"]
    assert (round(p["kp"], 4), round(p["ti"], 1)) == (0.0501, 47.3)
    rep = t["controller"]["target"]
    assert rep["lambda"] is None and rep["pm"] == 60.0
    assert math.isclose(rep["pm_achieved"], 60.0, abs_tol=0.1)
    with pytest.raises(ValueError, match="a PI only lags"):
        msp.tune("5.6e^-93.9s/(40.2s+1)", "pi", target="wc=0.1,pm=60")


WOOD_BERRY = [["12.8e^-1s/(16.7s+1)", "-18.9e^-3s/(21s+1)"],
              ["6.6e^-7s/(10.9s+1)", "-19.4e^-3s/(14.4s+1)"]]


def test_a_matrix_plant_gives_luybens_blt_tuning_and_the_clis_report() -> None:
    t = msp.tune(WOOD_BERRY)
    assert round(t["rga"][0][0], 2) == 2.01 and t["pairing"] == [0, 1]
    assert [round(l["kp"], 3) for l in t["loops"]] == [0.375, -0.075]
    assert [round(t["loops"][0]["ti"], 2), round(t["loops"][1]["ti"], 1)] == [8.29, 23.6]
    assert abs(t["f"] - 2.55) < 0.006
    # the same numbers as msp tune --json, from the matrix string
    text = "[" + "; ".join(", ".join(r) for r in WOOD_BERRY) + "]"
    out = subprocess.run([MSP_BIN, "tune", "--plant", text, "--json"], check=True,
                         capture_output=True, text=True).stdout
    assert json.loads(out) == msp.tune(text)
    with pytest.raises(ValueError, match="square"):
        msp.tune([["1/(s+1)", "2/(s+1)"]])
    # python-control transfer functions with their delays, exactly
    import control

    pc = [[(control.tf([12.8], [16.7, 1]), 1.0), (control.tf([-18.9], [21, 1]), 3.0)],
          [(control.tf([6.6], [10.9, 1]), 7.0), (control.tf([-19.4], [14.4, 1]), 3.0)]]
    assert msp.tune(pc)["loops"] == msp.tune(WOOD_BERRY)["loops"]
    s = msp.tune(WOOD_BERRY, rule="simc")
    assert s["rule"] == "simc" and abs(s["alone"][0]["kp"] - 16.7 / 25.6) < 1e-12
    d = msp.tune(WOOD_BERRY, "decoupled", ts=1.0)
    assert [e["realization"]["as"] for e in d["decoupler"]] == ["exact", "exact"]
    assert d["stability"]["stable"] and d["decoupler_stability"]["stable"]


def test_a_matrix_plant_runs_as_the_cli_does(tmp_path: pathlib.Path) -> None:
    kw = dict(ts=1.0, duration=200.0, loop_setpoint=["1:1@0", "2:1@100"],
              loop_disturbance="1:input:0.05@150")
    res = msp.run(WOOD_BERRY, "decoupled", **kw)
    assert res.y.shape == (2, 201) and res.t.shape == (201,)  # 0, 1, …, 200 min
    # decoupled: the step of loop 1 leaves output 2 where it was (to rounding)
    first = res.interaction[0]
    assert first["step_loop"] == 0 and first["deviation"][1] < 1e-9
    assert res.stable is True
    text = "[" + "; ".join(", ".join(r) for r in WOOD_BERRY) + "]"
    csv_path, rep_path = tmp_path / "wb.csv", tmp_path / "wb.json"
    subprocess.run([MSP_BIN, "run", "--plant", text, "-c", "decoupled", "--ts", "1",
                    "--duration", "200", "--loop-setpoint", "1:1@0", "--loop-setpoint", "2:1@100",
                    "--loop-disturbance", "1:input:0.05@150", "-q", "-o", str(csv_path),
                    "--report", str(rep_path)], check=True)
    cols = np.loadtxt(csv_path, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(cols[:, 2], res.y[0])
    np.testing.assert_array_equal(cols[:, 6], res.u[1])
    assert json.loads(rep_path.read_text())["iae"] == res.iae
    axes = res.plot()
    assert len(axes) == 4
    pi, dec = msp.compare(WOOD_BERRY, ["pi", "decoupled"], **kw)
    assert pi.report["scheme"] == "pi" and pi.interaction[0]["deviation"][1] > 0.3
    np.testing.assert_array_equal(dec.y, res.y)
    with pytest.raises(ValueError, match="does not take umin"):
        msp.run(WOOD_BERRY, umin=0.0)
    noisy = msp.run(WOOD_BERRY, ts=1.0, duration=100.0, noise=0.01, seed=3, actuator=(-0.1, 0.1))
    assert noisy.u.max() <= 0.1 and noisy.u.min() >= -0.1
    held = msp.run(WOOD_BERRY, "decoupled", ts=1.0, duration=200.0, loop_setpoint=["1:1@0"],
                   loop_event=["1:50:manual=0.2", "1:120:auto"])
    assert (held.u[0][50:120] == 0.2).all()
    with pytest.raises(ValueError, match="LOOP:TIME:manual=VALUE"):
        msp.run(WOOD_BERRY, loop_event="1:50:hand")


def test_step_info_of_data_is_python_controls_and_the_clis(tmp_path: pathlib.Path) -> None:
    import control

    h = control.tf([8, 18, 32], [1, 6, 14, 24])  # MATLAB's documented stepinfo example
    t = np.linspace(0.0, 10.0, 100001)
    resp = control.step_response(h, t)
    y = np.asarray(resp.outputs).ravel()
    ours = msp.step_info(t, y, yfinal=32 / 24)
    peer = control.step_info(y, t, yfinal=32 / 24)
    # python-control takes the samples themselves, msp interpolates the crossings: within a step
    for key, name in (("rise_time", "RiseTime"), ("settling_time", "SettlingTime"),
                      ("peak", "Peak"), ("peak_time", "PeakTime"), ("overshoot", "Overshoot"),
                      ("settling_min", "SettlingMin"), ("settling_max", "SettlingMax")):
        assert math.isclose(ours[key], peer[name], abs_tol=2e-4), (key, ours[key], peer[name])
    assert math.isclose(ours["rise_time"], 0.2087, abs_tol=6e-5)   # MATLAB's documented figures
    assert math.isclose(ours["settling_time"], 3.4972, abs_tol=6e-5)
    tight = msp.step_info(t, y, yfinal=32 / 24, settling_threshold=0.005)
    assert math.isclose(tight["settling_time"], 4.8896, abs_tol=2e-4)
    csv = tmp_path / "step.csv"
    np.savetxt(csv, np.column_stack([t, y]), delimiter=",", header="t,y", comments="")
    cli = json.loads(subprocess.run([MSP_BIN, "stepinfo", "--data", str(csv), "--yfinal", str(32 / 24),
                                     "--json"], check=True, capture_output=True, text=True).stdout)
    assert cli == pytest.approx(ours, rel=1e-12)
    with pytest.raises(ValueError):
        msp.step_info([0.0, 1.0], [0.0])
    with pytest.raises(ValueError):
        msp.step_info(t, y, rise_limits=(0.9, 0.1))


def test_simulate_is_run_with_the_equivalent_steps() -> None:
    t = np.arange(0.0, 200.0 + 1e-9, 0.5)
    r = np.where(t >= 20.0, 1.0, 0.0)
    d = np.where(t >= 120.0, -0.1, 0.0)
    for plant, controller in (("2e^-3s/(4s+1)", "smith"), ("0.2/s*e^-4s", "karan-dey")):
        res = msp.simulate(plant, controller, t=t, r=r, d=d, events="150:manual=0.2")
        same = msp.run(plant, controller, setpoint=["0@0", "1@20"], disturbance="input:-0.1@120",
                       ts=0.5, duration=200.0, events="150:manual=0.2")
        assert np.array_equal(res.y, same.y) and np.array_equal(res.u, same.u)
        assert np.array_equal(res.r, r)
    with pytest.raises(ValueError, match="uniform"):
        msp.simulate("2e^-3s/(4s+1)", t=np.array([0.0, 0.5, 1.2]), r=np.ones(3))
    with pytest.raises(ValueError, match="same length"):
        msp.simulate("2e^-3s/(4s+1)", t=t, r=r[:-1])


def test_the_verdict_names_the_loop_it_covers() -> None:
    """A process drift at 100 s (its gain changes sign: the loop runs away after it): the verdict
    is the loop's as built, cross-checked by the run up to the drift; modes alone change nothing."""
    r = msp.run("e^-1s/(4s+1)", "smith", ts=0.1, duration=300.0, events=["100:plant-gain=-1"])
    st = r.stability
    assert st["stable"] is True and st["as_built_until"] == 100.0 and st["simulation"] is True, st
    assert "the loop as built: at 100 s the process drifts" in st["reason"], st
    r = msp.run("e^-1s/(4s+1)", "smith", ts=0.1, duration=300.0, events=["120:manual=0.3", "150:auto"])
    assert r.stability["as_built_until"] is None and r.stability["simulation"] is True, r.stability


def test_the_time_plot_marks_what_was_scheduled() -> None:
    import matplotlib

    matplotlib.use("Agg")
    r = msp.run("2e^-3s/(4s+1)", "smith", ts=0.1, setpoint=["1@0", "0.5@40"], disturbance="output:0.1@80",
                events=["120:manual=0.3", "150:auto"], duration=220.0)
    fig = r.plot()
    texts = [t.get_text() for t in fig.axes[0].texts]
    for want in ("r → 0.5", "output load 0.1", "manual 0.3", "auto"):
        assert want in texts, (want, texts)
    labels = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert "d_out (output load)" in labels
    assert len(fig.axes[0].patches) >= 1  # the manual period shaded


def test_step_result_plots() -> None:
    import matplotlib

    matplotlib.use("Agg")
    s = msp.step("2*e^-1.3s/(5s+1)")
    assert s.dc_gain == 2.0 and s["rise_time"] == s.rise_time
    fig = s.plot()
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any("final value 2" in x for x in labels) and any("settling" in x for x in labels)


def test_tradeoff_is_the_clis_and_plots() -> None:
    import matplotlib

    matplotlib.use("Agg")
    t = msp.tradeoff("2*e^-3s/(4s+1)", ["smith", "pi"])
    cli = json.loads(subprocess.run([MSP_BIN, "tradeoff", "--plant", "2*e^-3s/(4s+1)", "-c", "smith,pi",
                                     "-q", "--json"], check=True, capture_output=True, text=True).stdout)
    assert [(p["scheme"], p["lambda"]) for p in t.points] == [(p["scheme"], p["lambda"]) for p in cli["points"]]
    smith = t.scheme("smith")
    # Kaya's tuning with a perfect model: the set-point IAE is L + lambda (Kaya (2003) Eqs. 20-21)
    assert all(abs(p["iae_setpoint"] - (3.0 + p["lambda"])) < 2 * t.ts for p in smith)
    fig = t.plot()
    assert len(fig.axes) == 2 and all(a.get_yscale() == "log" for a in fig.axes)


def test_tune_reports_robustness_as_the_cli() -> None:
    t = msp.tune("0.2/s*e^-7.4s")
    assert t["controller"]["name"] == "karan-dey" and t["chosen"] == ["lambda"]
    assert math.isclose(t["robustness"]["pm"], 33.1, abs_tol=0.1) and t["robustness"]["ms"] > 2.0
    assert "Ms = 2.52" in t["warnings"][0]
    cli = json.loads(subprocess.run([MSP_BIN, "tune", "--plant", "0.2/s*e^-7.4s", "--json"],
                                    check=True, capture_output=True, text=True).stdout)
    assert cli == t


def test_a_bare_run_is_the_default_scenario() -> None:
    res = msp.run("0.2/s*e^-7.4s")
    assert res.default_scenario and [e["kind"] for e in res.events] == ["setpoint", "disturbance"]
    load = res.events[1]
    assert math.isclose(load["value"], -0.1) and load["at"] > res.events[0]["settling_time"]
    assert load["recovery_time"] < res.duration - load["at"]


def test_run_reports_each_event() -> None:
    res = msp.run("0.2/s*e^-7.4s", setpoint=[(1, 0), (2, 100)], disturbance="input:-0.1@200", duration=400)
    kinds = [e["kind"] for e in res.events]
    assert kinds == ["setpoint", "setpoint", "disturbance"]
    assert res.events[1]["overshoot"] < 1.0 and res.metrics["overshoot"] < 1.0
    assert res.events[2]["peak_deviation"] < 0.0 and res.events[2]["location"] == "input"


def test_a_nan_perturbation_is_named() -> None:
    with pytest.raises(ValueError, match="perturbation gain"):
        msp.compare("0.2/s*e^-7.4s", ["smith"], perturb={"gain": float("nan")})


def test_identify_refuses_closed_loop_data() -> None:
    res = msp.run("5.6*e^-93.9s/(40.2s+1)", "pi", noise=0.01)
    with pytest.raises(ValueError, match="closed-loop data"):
        msp.identify(res.t, res.u, res.y)


def test_readme_figures_render_from_the_current_code(tmp_path: pathlib.Path) -> None:
    """Every SVG the README and the guide show is made by scripts/figures from today's code; each renders to a
    PNG of the expected size that is not blank (more than 2 % of its pixels drawn)."""
    import re

    import cairosvg  # type: ignore[import-untyped]
    from PIL import Image

    subprocess.run(["bash", str(ROOT / "scripts" / "figures"), str(tmp_path)], check=True,
                   env={**os.environ, "MSP_BIN": MSP_BIN, "PYTHON": sys.executable})
    pages = [ROOT / "README.md", *sorted((ROOT / "docs" / "guide" / "src").glob("*.md"))]
    shown = sorted({pathlib.Path(name).name for page in pages
                    for name in re.findall(r"\(((?:docs/guide/src/)?figures/[\w.-]+\.svg)\)",
                                           page.read_text())})
    assert len(shown) >= 6, shown
    for name in shown:
        svg = tmp_path / pathlib.Path(name).name
        png = tmp_path / (svg.stem + ".png")
        cairosvg.svg2png(url=str(svg), write_to=str(png))
        img = Image.open(png).convert("L")
        assert img.width >= 800 and img.height >= 400, (name, img.size)
        drawn = float((np.asarray(img) < 200).mean())
        assert drawn > 0.02, (name, drawn)


def _polylines(svg: str) -> list:
    """The data traces of an msp SVG (the sub-pixel ones, each in its clip group): point lists."""
    import re

    return [[tuple(map(float, p.split(","))) for p in pts.split()]
            for pts in re.findall(r'<g clip-path="url\(#fine\d+\)">.*?points="([^"]*)"', svg)]


def _legends(svg: str) -> list:
    """The legend boxes (x, y, w, h) of a plotters SVG: white, translucent, bordered."""
    import re

    return [tuple(map(float, m)) for m in re.findall(
        r'<rect x="([\d.]+)" y="([\d.]+)" width="([\d.]+)" height="([\d.]+)" opacity="0.8[05]?" '
        r'fill="#FFFFFF"', svg)]


def test_cli_plots_render_with_what_a_report_needs(tmp_path: pathlib.Path) -> None:
    """Each kind of CLI plot rendered to PNG: traces with sub-pixel coordinates, legends clear of
    the traces, every scheduled event marked on the time axis."""
    import cairosvg
    from PIL import Image

    plots = {
        "run": ["run", "--plant", "0.2/s*e^-7.4s", "-q", "-o", os.devnull, "--setpoint", "1@0",
                "--setpoint", "0.5@60", "--disturbance", "input:-0.05@100",
                "--disturbance", "output:0.1@140", "--event", "170:manual=0.2", "--event", "190:auto",
                "--duration", "240", "--plot"],
        "adapt": ["run", "--plant", "e^-1s/(4s+1)", "-c", "smith", "-q", "-o", os.devnull, "--ts", "0.1",
                  "--duration", "600", *[a for i in range(12) for a in ("--setpoint", f"{i % 2 == 0:d}@{30 * i}")],
                  "--adapt", "--event", "100:plant-lag=8", "--plot"],
        "bode": ["margins", "--plant", "5.6*e^-93.9s/(40.2s+1)", "-c", "smith", "--plot"],
        "nyquist": ["margins", "--plant", "0.2/s*e^-7.4s", "-c", "karan-dey", "--nyquist"],
        "step": ["step", "--plant", "e^-2s/(3s+1)^2", "--plot"],
        "tradeoff": ["tradeoff", "--plant", "e^-2s/(3s+1)", "--plot"],
    }
    for kind, args in plots.items():
        svg_path = tmp_path / f"{kind}.svg"
        subprocess.run([MSP_BIN, *args, str(svg_path)], check=True, capture_output=True)
        svg = svg_path.read_text()
        lines = _polylines(svg)
        assert lines, kind
        # sub-pixel: most coordinates of a smooth trace are not whole pixels
        coords = [c for line in lines if len(line) > 5 for p in line for c in p]
        fractional = sum(1 for c in coords if c != round(c)) / max(len(coords), 1)
        assert fractional > 0.5, (kind, fractional)
        # no legend box covers a trace point (sampled along each segment)
        for (x, y, w, h) in _legends(svg):
            for line in lines:
                for (a, b), (c, d) in zip(line, line[1:]):
                    for f in np.linspace(0.0, 1.0, 5):
                        px, py = a + f * (c - a), b + f * (d - b)
                        assert not (x + 1 < px < x + w - 1 and y + 1 < py < y + h - 1), (kind, px, py)
        png = tmp_path / f"{kind}.png"
        cairosvg.svg2png(url=str(svg_path), write_to=str(png))
        img = np.asarray(Image.open(png).convert("RGB")).astype(int)
        assert float((img.sum(axis=2) < 600).mean()) > 0.02, kind
        if kind == "run":
            # a marker (a grey dashed vertical line) at each scheduled time, on both panels
            x0, x1 = 72.0, 876.0  # the panels' pixel span for t in [0, 240]
            # (grey 110 anti-aliased over two columns: near-neutral 100-195; the grid is lighter)
            neutral = (img.max(axis=2) - img.min(axis=2)) <= 20  # (over the manual shading too)
            grey = neutral & (img[:, :, 0] >= 100) & (img[:, :, 0] <= 195)
            for t in (60, 100, 140, 170, 190):
                col = int(round(x0 + (x1 - x0) * t / 240.0))
                hits = grey[:, col - 2:col + 2].any(axis=1).mean()
                assert hits > 0.25, (t, hits)
            # and nowhere else: a column far from every event has none of it
            assert grey[:, 400:404].any(axis=1).mean() < 0.05
            for text in ("r → 0.5", "input load -0.05", "output load 0.1", "manual 0.2", "auto"):
                assert text in svg, text


def test_controllers_and_the_module_read_like_python_control() -> None:
    sp = msp.SmithPredictor("5.6*e^-93.9s/(40.2s+1)", ts=1.0)
    assert repr(sp) == "<msp.SmithPredictor smith: kp=0.07645 ti=40.2 td=0 lambda=93.9, ts=1 s>"
    assert sp.kp == sp.params["kp"] and sp.ts == 1.0
    with pytest.raises(AttributeError, match="no signal or parameter 'kq'"):
        sp.kq
    assert dir(msp) == sorted(msp.__all__) and "np" not in dir(msp)


def test_margins_is_a_short_result_with_a_plot(tmp_path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    m = msp.margins("0.2/s*e^-7.4s", "karan-dey")
    assert isinstance(m, dict) and m["gm"] == m.gm and m.w.shape == (m.l.shape[0],)
    text = repr(m)
    assert len(text) < 300 and "gm=1.689" in text and "pm=33.11" in text, text
    fig = m.plot()
    assert len(fig.axes) == 3
    fig.savefig(tmp_path / "m.png")
    assert (tmp_path / "m.png").stat().st_size > 10_000


def test_every_public_function_is_documented_and_its_examples_run() -> None:
    """numpy-style docstrings: every parameter under Parameters, then Returns, Raises and an
    Example; the examples run as doctests."""
    import doctest
    import inspect
    import re

    for name in ("run", "compare", "margins", "sweep", "autotune", "identify", "tune", "step"):
        fn = getattr(msp, name)
        doc = inspect.getdoc(fn) or ""
        for section in ("Parameters", "Returns", "Raises", "Examples"):
            assert f"{section}\n---" in doc, (name, section)
        params = doc.split("Parameters\n----------\n", 1)[1].split("\nReturns\n", 1)[0]
        documented = set(re.findall(r"^(?:\*\*)?([a-z_0-9]+)(?=[ ,:]|$)", params, re.M))
        documented |= {n.strip() for line in re.findall(r"^([a-z_0-9, ]+) :", params, re.M)
                       for n in line.split(",")}
        for p in inspect.signature(fn).parameters.values():
            assert p.name in documented, (name, p.name)
    for cls in (msp.Result, msp.Margins, msp.SmithPredictor, msp.Pid, msp.Plant, msp.Estimator):
        assert (inspect.getdoc(cls) or "").strip(), cls
    result = doctest.testmod(msp, extraglobs={"msp": msp}, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 15 and result.failed == 0, result
    # the classes and functions made in Rust, with their examples
    finder = doctest.DocTestFinder()
    runner = doctest.DocTestRunner()
    tests = [t for obj in (msp.Controller, msp.Estimator, msp.Pid, msp.Plant, msp.parse_plant, msp.controllers)
             for t in finder.find(obj, obj.__name__, globs={}) if t.examples]
    assert sorted(t.name for t in tests) == [
        "Controller", "Controller.to_control", "Estimator", "Pid", "Pid.reset_to_rest", "Plant", "controllers",
        "parse_plant"]
    for t in tests:
        runner.run(t)
    assert runner.summarize(verbose=False).failed == 0


def test_tune_and_run_report_the_designed_filter() -> None:
    params = {"tf": 36.0, "lead": 3.0, "lag": 0.144}
    t = msp.tune(GARCIA_1["plant"], "fspcc", params, inner_plant=GARCIA_1["inner_plant"], ts=0.2)
    assert math.isclose(t["design"]["kf"], 14.9524, rel_tol=5e-3) and abs(t["design"]["rho2"] - 0.9957) < 5e-4
    res = msp.run(GARCIA_1["plant"], "fspcc", params, inner_plant=GARCIA_1["inner_plant"], ts=0.2, setpoint=1.0,
                  duration=100)
    assert res.design == t["design"]


def test_run_says_what_it_chose() -> None:
    assert msp.run("1/(s+1)^2").chosen == ["ts", "duration", "lambda"]
    assert msp.run("1/(s+1)^2", lambda_=1.0, ts=0.1).chosen == ["duration"]


def test_margins_call_a_p_only_loop_stable_where_it_settles_off_the_set_point() -> None:
    m = msp.margins("1/(s+1)", "pid", {"kp": 1.0, "ti": math.inf, "td": 0.0})
    assert m["stable"] is True and m["stability"]["simulation"] is True
    m = msp.margins("e^-1s/(s+1)", "pid", {"kp": 3.0, "ti": math.inf, "td": 0.0})
    assert m["stable"] is False and m["stability"]["unstable_poles"] >= 1
    # an unstable loop has no margins: NaN (null in the JSON), with the reason
    assert math.isnan(m["gm"]) and math.isnan(m["ms"])


def test_run_reports_the_verdict() -> None:
    res = msp.run("0.2/s*e^-7.4s", "pid", {"kp": 5.0, "ti": 20.0, "td": 0.0})
    assert res.stable is False and res.stability["stable"] is False
    assert "outside the unit circle" in res.stability["reason"]
    assert msp.run("0.2/s*e^-7.4s").stable is True


def test_sweep_columns_and_shards() -> None:
    args = dict(controller="karan-dey", gain="-10%..+10%", delay=(-0.05, 0.05), grid=4, ts=0.074, duration=60)
    whole = msp.sweep("0.2/s*e^-7.4s", **args)
    assert len(whole["iae"]) == 16 and whole["stable"].dtype == bool
    a = msp.sweep("0.2/s*e^-7.4s", shard=(0, 2), **args)
    b = msp.sweep("0.2/s*e^-7.4s", shard=(1, 2), **args)
    merged = np.concatenate([a["iae"], b["iae"]])[np.argsort(np.concatenate([a["index"], b["index"]]))]
    assert np.array_equal(merged, whole["iae"])


def test_autotune_and_identify() -> None:
    import inspect

    from msp import _msp

    # the public keywords are the compiled function's
    compiled = set(inspect.signature(_msp.autotune).parameters) - {"plant"}
    assert set(msp.RelayOptions.__annotations__) == compiled
    out = msp.autotune("2*e^-4s/(5s+1)")
    ident = out["identified"]
    assert ident["model"] == "fopdt"
    assert abs(ident["k"] - 2) < 0.02 and abs(ident["t"] - 5) < 0.05 and abs(ident["l"] - 4) < 0.04
    assert out["run"].controller["name"] == "smith" and out["run"].stable
    with pytest.raises(RuntimeError, match="aborted"):
        msp.autotune("0.2/s*e^-7.4s", band=0.5)
    t = np.arange(0, 60, 0.05)
    u = np.where(t >= 5, 1.0, 0.0)
    # an exact FOPDT response to compare with
    y = np.where(t > 9, 2 * (1 - np.exp(-(t - 9) / 5)), 0.0)
    fit = msp.identify(t, u, y, "fopdt")
    assert abs(fit["k"] - 2) < 0.02 and abs(fit["t"] - 5) < 0.1 and abs(fit["l"] - 4) < 0.1
    # an unstable process: the unstable FOPDT from the biased relay's cycle, a stable loop
    out = msp.autotune("2e^-1s/(3s-1)")
    ident = out["identified"]
    assert ident["model"] == "ufopdt"
    assert abs(ident["k"] - 2) < 4e-3 and abs(ident["t"] - 3) < 6e-3 and abs(ident["l"] - 1) < 2e-3
    assert out["run"].stable
    with pytest.raises(ValueError, match="relay"):
        msp.identify(t, u, y, "ufopdt")


@pytest.mark.skipif(not pathlib.Path(MSP_BIN).exists(), reason="the msp binary is not built")
def test_autotune_reports_as_the_cli(tmp_path: pathlib.Path) -> None:
    """The relay and the fit are the library's reports: the same keys and numbers as
    ``msp autotune --report``."""
    path = tmp_path / "a.json"
    subprocess.run([MSP_BIN, "autotune", "--plant", "2*e^-4s/(5s+1)", "--bias", "0.2", "--report", str(path)],
                   check=True, capture_output=True)
    cli = json.loads(path.read_text())
    out = msp.autotune("2*e^-4s/(5s+1)", bias=0.2)
    for key in ("relay", "identified"):
        assert sorted(out[key]) == sorted(cli[key]), key
        for k, v in out[key].items():
            assert v == cli[key][k] or (isinstance(v, float) and abs(v - cli[key][k]) <= 1e-12 * abs(v)), (key, k)
    assert out["relay"]["gain"] is not None and {"ku", "tu", "cycles"} <= set(out["relay"])


def test_disturbance_dicts_are_the_scenario_files_form() -> None:
    """A dict is read as a scenario file's structured disturbance (the library's serde): the
    flag's place names, the input when none, and an unknown field refused by name."""
    kw = dict(ts=0.1, duration=20.0)
    flag = msp.run("2*e^-3s/(4s+1)", "pi", disturbance="load:0.1@5", **kw)
    as_dict = msp.run("2*e^-3s/(4s+1)", "pi", disturbance={"value": 0.1, "at": 5}, **kw)
    assert np.array_equal(flag.y, as_dict.y) and as_dict.d.max() == 0.1
    with pytest.raises(ValueError, match="unknown field `valeu`"):
        msp.run("2*e^-3s/(4s+1)", "pi", disturbance={"valeu": 0.1}, **kw)
    with pytest.raises(ValueError, match=r"'input' \(d2\)"):
        msp.run("2*e^-3s/(4s+1)", "pi", disturbance={"location": "middle", "value": 0.1}, **kw)


def test_sweep_ranges_refused_by_name() -> None:
    with pytest.raises(ValueError, match="gain: the lower end is above the upper end"):
        msp.sweep("0.2/s*e^-7.4s", "karan-dey", gain=(0.2, -0.2), grid=2)
    with pytest.raises(ValueError, match="delay: a change of -100 %"):
        msp.sweep("0.2/s*e^-7.4s", "karan-dey", delay="-100%..0%", grid=2)


GARCIA_1 = {"plant": "e^-4s/(20s-1)", "inner_plant": "2e^-2s/(20s+1)"}


@pytest.mark.skipif(not pathlib.Path(MSP_BIN).exists(), reason="the msp binary is not built")
def test_cascade_results_equal_the_cli_bit_for_bit() -> None:
    ref = cli_csv("--plant", GARCIA_1["plant"], "--inner-plant", GARCIA_1["inner_plant"], "--ts", "0.2",
                  "--duration", "200", "--disturbance", "d2:-1@50", "--disturbance", "d0:-0.5@100",
                  "--disturbance", "d1:-0.2@150", "--controller", "gpcc")
    res = msp.run(GARCIA_1["plant"], "gpcc", inner_plant=GARCIA_1["inner_plant"], ts=0.2, duration=200,
                  disturbance=["d2:-1@50", {"location": "d0", "value": -0.5, "at": 100},
                               {"location": "output", "value": -0.2, "at": 150}])
    for key in ("t", "r", "y", "u", "d", "d_out", "y2", "d_inner"):
        assert np.array_equal(getattr(res, key), ref[key]), key
    for name, values in res.signals.items():
        assert np.array_equal(values, ref[name]), name
    assert res.inner_plant == "2*e^(-2s)/(20s + 1)" and res.stable


def test_cascade_controller_per_sample_equals_the_simulation() -> None:
    res = msp.run(GARCIA_1["plant"], "fspcc", inner_plant=GARCIA_1["inner_plant"], ts=0.2, duration=100)
    c = msp.Fspcc(GARCIA_1["plant"], 0.2, inner_plant=GARCIA_1["inner_plant"])
    assert c.is_cascade and c.name == "fspcc"
    u = np.array([c.update(r, y, y2) for r, y, y2 in zip(res.r, res.y, res.y2)])
    assert np.array_equal(u, res.u)
    again = msp.Fspcc(GARCIA_1["plant"], 0.2, inner_plant=GARCIA_1["inner_plant"])
    assert np.array_equal(again.update_many(res.r, res.y, res.y2), res.u)
    assert again.r2 == c.r2


def test_cascade_compare_margins_and_tune() -> None:
    runs = msp.compare(GARCIA_1["plant"], ["fspcc", "gpcc"], perturb={"delay": 0.2, "tau": -0.2},
                       inner_plant=GARCIA_1["inner_plant"], ts=0.2, duration=300)
    assert all(r.stable and r.plant == "e^(-4.8s)/(16s - 1)" for r in runs)
    m = msp.margins(GARCIA_1["plant"], "gpcc", inner_plant=GARCIA_1["inner_plant"], ts=0.2,
                    uncertainty="delay=20%,tau=-20%")
    assert m["stable"] and m["robust_peak"] > 0.0
    if pathlib.Path(MSP_BIN).exists():
        import json

        out = subprocess.run([MSP_BIN, "margins", "--plant", GARCIA_1["plant"], "--inner-plant",
                              GARCIA_1["inner_plant"], "-c", "gpcc", "--ts", "0.2", "--json", "--uncertainty",
                              "delay=20%,tau=-20%"], check=True, capture_output=True, text=True).stdout
        assert json.loads(out)["robust_peak"] == m["robust_peak"]
    t = msp.tune(GARCIA_1["plant"], inner_plant=GARCIA_1["inner_plant"])
    assert t["controller"]["name"] == "fspcc" and t["controller"]["params"]["lambda2"] == 2.0
    r = msp.tune(GARCIA_1["plant"], "gpcc", inner_plant=GARCIA_1["inner_plant"], ts=0.2,
                 uncertainty={"delay": 0.2, "tau": -0.2})
    assert r["robust_peak"] == m["robust_peak"]
    with pytest.raises(ValueError, match="inner"):
        msp.run(GARCIA_1["plant"], "fspcc")


def test_cascade_sweep_perturbs_the_primary() -> None:
    cols = msp.sweep(GARCIA_1["plant"], "fspcc", inner_plant=GARCIA_1["inner_plant"], delay="-20%..+20%",
                     grid=3, ts=0.2, duration=300)
    assert list(cols["delay"]) == [-0.2, 0.0, 0.2] and cols["stable"].all()


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
    # the estimator's counts: the report's as the signals' last row (the CLI's JSON alike)
    est = adaptive.report()["estimator"]
    assert est["learnt"] == adaptive.signals["learnt"][-1] > 0 and fixed.report()["estimator"] is None
    assert set(est) == {"learnt", "onsets", "restarts"}
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
    assert (c.state["learnt"], c.state["onsets"], c.state["restarts"]) == (0, 0, 0)
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
