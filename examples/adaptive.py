"""Adaptive dead-time compensation on a drifting process: e^(-s)/(4s + 1) whose lag doubles at
150 s, whose dead time grows to 1.5 s at 450 s and whose gain rises by half at 750 s, under a
Smith predictor with the model it was
built with (fixed) and with its model kept right by on-line identification (``adapt=True``,
the CLI's ``--adapt``). Set-point changes every 30 s; measurement noise 2 % of the step. Prints
the set-point IAE from 1050 s on of both and of the loop built with the drifted process's model.

    python examples/adaptive.py [OUT]   (a file, e.g. docs/guide/src/figures/msp-adapt.svg as scripts/figures
                                         writes it, or a directory: OUT/adaptive.png)
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.hashsalt"] = "msp"  # the same file from the same code
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import msp  # noqa: E402

PLANT = "e^-1s/(4s+1)"
DRIFT = ["150:plant-lag=8", "450:plant-dead-time=1.5", "750:plant-gain=1.5"]
FROM = 1050.0
COMMON = dict(controller="smith", lambda_=2.0, ts=0.1, duration=1200.0, noise=0.02, seed=3,
              setpoint=[(float(i % 2 == 0), 30.0 * i) for i in range(40)], events=DRIFT)


def main(out: pathlib.Path) -> None:
    fixed = msp.run(PLANT, **COMMON)
    adaptive = msp.run(PLANT, adapt=True, **COMMON)
    truth = msp.run("1.5*e^-1.5s/(8s+1)", **{**COMMON, "events": []})

    def iae(run):
        t, e = np.asarray(run.t), np.abs(np.asarray(run.r) - np.asarray(run.y))
        return float(np.sum(e[t >= FROM]) * COMMON["ts"])

    print(f"set-point IAE from {FROM:.0f} s: adaptive {iae(adaptive):.1f}, fixed {iae(fixed):.1f}, "
          f"the drifted process's model {iae(truth):.1f}")
    fig, (ax, ax_m) = plt.subplots(2, 1, figsize=(10, 6.5), sharex=True, height_ratios=(2, 1))
    ax.plot(fixed.t, fixed.r, "k--", lw=1, label="r (set point)")
    ax.plot(fixed.t, fixed.y, color="tab:red", lw=1, label="y, the model fixed")
    ax.plot(adaptive.t, adaptive.y, color="tab:blue", lw=1, label="y, the model adapted")
    s = adaptive.signals
    for name, first, color in (("k", 1.0, "tab:blue"), ("tau", 4.0, "tab:orange"), ("theta", 1.0, "tab:green")):
        hat = np.asarray(s[f"{name}_hat"]) / first
        ax_m.plot(adaptive.t, np.where((hat > 0.25) & (hat < 4), hat, np.nan), color=color, lw=0.8,
                  ls="--")
        ax_m.plot(adaptive.t, np.asarray(s[f"{name}_model"]) / first, color=color, lw=2,
                  label={"k": "K", "tau": "τ", "theta": "θ"}[name])
    for a in (ax, ax_m):
        for at in (150, 450, 750):
            a.axvline(at, color="gray", lw=0.8)
        for change in adaptive.report()["adaptation"]:
            a.axvline(change["at"], color="tab:blue", lw=0.6, ls=":")
        a.grid(alpha=0.3)
    ax.text(155, 1.3, "plant τ 4 s -> 8 s", color="gray")
    ax.text(455, 1.3, "plant θ 1 s -> 1.5 s", color="gray")
    ax.text(755, 1.3, "plant K 1 -> 1.5", color="gray")
    ax.set_ylim(-0.45, 1.45)
    ax.set_ylabel("output y (measured: 2 % noise)")
    ax_m.set_ylabel("model (—), estimate (- -)\nover the first model")
    ax_m.set_xlabel("time t (s)  (dotted: the model changed)")
    ax.set_title("Smith predictor on " + PLANT + " drifting: fixed and adaptive model")
    ax.legend(loc="lower right", ncols=3)
    ax_m.legend(loc="upper left", ncols=3)
    fig.tight_layout()
    fig.savefig(out, metadata={"Date": None})


if __name__ == "__main__":
    target = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    main(target / "adaptive.png" if target.is_dir() else target)
