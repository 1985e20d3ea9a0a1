"""Matplotlib plots of msp results (imported lazily: matplotlib is optional)."""

from __future__ import annotations

from typing import Any


def plot_result(res: Any, ax: Any = None, title: str | None = None) -> Any:
    """Two panels, as ``msp run --plot``: the set point (dashed) and the output on top, the control
    and the load disturbance (dashed, when there is one) below. Returns the Figure.

    With ``ax`` (a pair of Axes) the curves are drawn there instead.
    """
    import matplotlib.pyplot as plt
    import numpy as np

    if ax is None:
        fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(9, 6), height_ratios=[3, 2],
                                     layout="constrained")
    else:
        a1, a2 = ax
        fig = a1.figure
    a1.plot(res.t, res.r, "k--", lw=1.5, label="r (set point)")
    a1.plot(res.t, res.y, lw=1.5, label="y")
    a1.set_ylabel("set point r, output y")
    a1.legend(loc="best")
    a1.grid(True, alpha=0.3)
    a2.plot(res.t, res.u, lw=1.2, color="tab:red", label="u (control)")
    loads = False
    if np.any(res.d != 0.0):
        a2.plot(res.t, res.d, "--", lw=1.2, color="0.35", label="d (input load)")
        loads = True
    d_out = getattr(res, "d_out", None)
    if d_out is not None and len(d_out) == len(res.t) and np.any(np.asarray(d_out) != 0.0):
        a2.plot(res.t, d_out, "--", lw=1.2, color="sienna", label="d_out (output load)")
        loads = True
    a2.set_ylabel("control u, loads" if loads else "control u")
    # what was scheduled, marked on the time axis; manual and tracking periods shaded
    marks = []
    for e in res.events:
        if e["kind"] == "setpoint" and e["at"] > 0:
            marks.append((e["at"], f"r → {e['value']:.4g}"))
        elif e["kind"] == "disturbance":
            marks.append((e["at"], f"{e['location']} load {e['value']:.4g}"))
    held_from = None
    for op in sorted(getattr(res, "operator_events", None) or [], key=lambda o: o["at"]):
        action = op["action"]
        name, value = (action, None) if isinstance(action, str) else next(iter(action.items()))
        marks.append((op["at"], name if value is None else f"{name} {value}"))
        if name in ("manual", "track") and held_from is None:
            held_from = op["at"]
        elif name == "auto" and held_from is not None:
            for a in (a1, a2):
                a.axvspan(held_from, op["at"], color="tab:orange", alpha=0.12, lw=0)
            held_from = None
    if held_from is not None:
        for a in (a1, a2):
            a.axvspan(held_from, res.t[-1], color="tab:orange", alpha=0.12, lw=0)
    for i, (at, text) in enumerate(marks):
        for a in (a1, a2):
            a.axvline(at, ls=":", color="0.45", lw=1)
        a1.annotate(text, (at, 1.0 - 0.07 * (i % 4)), xycoords=("data", "axes fraction"),
                    fontsize="small", color="0.35", va="top", xytext=(2, -2),
                    textcoords="offset points")
    a2.set_xlabel("time t (s)")
    a2.legend(loc="best")
    a2.grid(True, alpha=0.3)
    a2.set_xlim(res.t[0], res.t[-1])
    if title is None:
        p = res.controller["params"]
        key = ", ".join(f"{k} = {p[k]:.4g}" for k in ("kp", "ti", "td", "lambda")
                        if k in p and p[k] is not None and np.isfinite(p[k]))
        title = f"{res.controller['name']} ({key}) on {res.plant}"
    a1.set_title(title)
    return fig


def plot_margins(m: Any, ax: Any = None) -> Any:
    """Bode (magnitude; the unwrapped phase, as MATLAB's ``bode``, up to ten times the highest
    crossover) and Nyquist of a margins result, as ``msp margins --plot``: gm marked at wcg, pm at
    wcp, the unit and Ms circles. Returns the Figure.
    """
    import matplotlib.pyplot as plt
    import numpy as np

    if ax is None:
        fig = plt.figure(figsize=(12, 6), layout="constrained")
        grid = fig.add_gridspec(2, 2, width_ratios=[1, 1])
        a1 = fig.add_subplot(grid[0, 0])
        a2 = fig.add_subplot(grid[1, 0], sharex=a1)
        a3 = fig.add_subplot(grid[:, 1])
    else:
        a1, a2, a3 = ax
        fig = a1.figure
    w, l = m.w, m.l[:, 0] + 1j * m.l[:, 1]
    crossings = [x for x in (m.wcg, m.wcp) if x is not None and np.isfinite(x) and x > 0]
    shown = w <= 10 * max(crossings) if crossings else np.ones_like(w, dtype=bool)
    w, l, phase = w[shown], l[shown], np.asarray(m.phase_unwrapped)[shown]
    a1.semilogx(w, 20 * np.log10(np.abs(l)), color="tab:blue")
    a1.axhline(0.0, color="0.5", lw=0.8)
    a1.set_ylabel("|L| (dB)")
    a2.semilogx(w, phase, color="tab:red")
    a2.set_ylabel("arg L (deg)")
    a2.set_xlabel("ω (rad/s)")
    if np.isfinite(m.wcp) and np.isfinite(m.pm):
        # the -180 deg (mod 360) line the phase margin is measured from
        p = phase[np.argmin(np.abs(w - m.wcp))]
        a2.axhline(p - m.pm, color="0.5", lw=0.8)
        a2.plot([m.wcp, m.wcp], [p - m.pm, p], color="tab:green", lw=3)
        a2.annotate(f"pm {m.pm:.3g}°", (m.wcp, p), color="tab:green")
    if np.isfinite(m.wcg) and np.isfinite(m.gm_db):
        a1.plot([m.wcg, m.wcg], [0.0, -m.gm_db], color="tab:green", lw=3)
        a1.annotate(f"gm {m.gm_db:.3g} dB", (m.wcg, -m.gm_db), color="tab:green")
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
    a1.set_title(f"{m.controller['name']} on {m.plant}")
    near = np.abs(l) < 10
    a3.plot(np.where(near, l.real, np.nan), np.where(near, l.imag, np.nan), color="tab:blue",
            label="L(jω), ω > 0")
    t = np.linspace(0, 2 * np.pi, 241)
    a3.plot(np.cos(t), np.sin(t), "--", color="0.5", lw=1, label="unit circle")
    if np.isfinite(m.ms) and m.ms > 0:
        a3.plot(-1 + np.cos(t) / m.ms, np.sin(t) / m.ms, color="tab:green", lw=1,
                label=f"Ms circle (Ms = {m.ms:.3g})")
    a3.plot([-1], [0], "o", color="tab:red")
    a3.set_xlim(-2.5, 1.5)
    a3.set_ylim(-2.5, 1.5)
    a3.set_aspect("equal")
    a3.set_xlabel("Re L")
    a3.set_ylabel("Im L")
    a3.grid(True, alpha=0.3)
    a3.legend(loc="lower right")
    a3.set_title("Nyquist")
    return fig


def plot_tradeoff(t: Any, ax: Any = None) -> Any:
    """``Ms`` against the IAE of a unit input load and of a unit set-point step (log scale), a
    curve per scheme through its λ sweep, its own tuning ringed, as ``msp tradeoff --plot``.
    Returns the Figure; with ``ax`` (a pair of Axes) it draws there."""
    import matplotlib.pyplot as plt
    import numpy as np

    if ax is None:
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 5), layout="constrained")
    else:
        a1, a2 = ax
        fig = a1.figure
    names: list[str] = []
    for p in t["points"]:
        if p["scheme"] not in names:
            names.append(p["scheme"])
    for a, key, what in ((a1, "iae_load", "IAE, unit input load"),
                         (a2, "iae_setpoint", "IAE, unit set-point step")):
        for name in names:
            pts = [p for p in t["points"] if p["scheme"] == name and p["stable"]
                   and p["ms"] is not None and p[key] is not None and np.isfinite(p[key])]
            if not pts:
                continue
            x = np.array([p["ms"] for p in pts])
            y = np.array([p[key] for p in pts])
            (line,) = a.plot(x, y, "o-", ms=3, lw=1.5, label=name)
            own = [p for p in pts if p["default"]]
            if own:
                a.plot([own[0]["ms"]], [own[0][key]], "o", ms=10, mfc="none", mew=2,
                       color=line.get_color())
        a.set_yscale("log")
        a.set_xlabel("Ms (robustness: smaller is more robust)")
        a.set_ylabel(what)
        a.grid(True, which="both", alpha=0.3)
        a.legend(loc="best", fontsize="small")
    fig.suptitle(f"robustness against performance: {t['plant']}")
    return fig


def plot_step(s: Any, ax: Any = None) -> Any:
    """The open-loop step response, its final value dashed, the 10-90 % rise and the settling
    time marked, as ``msp step --plot``. Returns the Figure; with ``ax`` it draws there."""
    import matplotlib.pyplot as plt
    import numpy as np

    if ax is None:
        fig, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
    else:
        fig = ax.figure
    ax.plot(s.t, s.y, color="tab:blue", lw=1.5, label="y (unit step at t = 0)")
    k = s.dc_gain
    if k is not None and np.isfinite(k):
        ax.axhline(k, ls="--", color="k", lw=1, label=f"final value {k:.4g}")
        if np.isfinite(s.settling_time):
            ax.axvline(s.settling_time, ls=":", color="tab:green",
                       label=f"settling {s.settling_time:.4g} s (2 %)")
        if np.isfinite(s.rise_time):
            ax.axhspan(0.1 * k, 0.9 * k, color="tab:orange", alpha=0.08,
                       label=f"rise 10-90 %: {s.rise_time:.4g} s")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("y")
    ax.set_title(f"step response: {s.plant}")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    ax.set_xlim(s.t[0], s.t[-1])
    return fig


def plot_mimo(res: Any, axes: Any = None) -> Any:
    """A multivariable run: a panel per output (its set point dashed), then a panel per input,
    sharing the time axis (as ``msp run --plot`` draws it). Returns the axes."""
    import matplotlib.pyplot as plt

    n = len(res.y)
    if axes is None:
        _, axes = plt.subplots(2 * n, 1, sharex=True, figsize=(8, 2.2 * n * 2))
    for i in range(n):
        ax = axes[i]
        ax.plot(res.t, res.r[i], "k--", lw=1, label=f"r{i + 1}")
        ax.plot(res.t, res.y[i], lw=1.2, label=f"y{i + 1}")
        ax.set_ylabel(f"r{i + 1}, y{i + 1}")
        ax.legend(loc="best")
        axu = axes[n + i]
        axu.plot(res.t, res.u[i], lw=1.2, label=f"u{i + 1}")
        axu.set_ylabel(f"input u{i + 1}")
    axes[-1].set_xlabel("t (s)")
    axes[0].set_title(f"{res.report['scheme']} (F = {res.report['f']:.4g}) on {res.report['plant']}",
                      fontsize=9)
    return axes
