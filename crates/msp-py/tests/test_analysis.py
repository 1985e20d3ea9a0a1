"""The Python module's analysis and design against the CLI, python-control
and MATLAB: margins, steps, tuning rules, matrix plants, step information,
sweeps, autotuning and identification, cascades."""

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
    # the module and the parts it is split into by concept (each public name defined in one)
    import importlib
    attempted = 0
    for part in ("msp", "msp._analysis", "msp._common", "msp._options", "msp._results", "msp._schemes"):
        result = doctest.testmod(importlib.import_module(part), extraglobs={"msp": msp},
                                 optionflags=doctest.ELLIPSIS)
        assert result.failed == 0, (part, result)
        attempted += result.attempted
    assert attempted >= 15, attempted
    # every public name is the module's or one of its parts'
    assert all(getattr(msp, n).__module__ in ("msp", "msp._msp") or getattr(msp, n).__module__.startswith("msp._")
               for n in msp.__all__ if hasattr(getattr(msp, n), "__module__")), msp.__all__
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
