"""A transport delay that grows with the process (a slower flow) under a Smith predictor:
the plant's dead time goes from 93.9 s to 140.85 s at 700 s, with the controller's model
left as it was and with the model's dead time updated at the same time
(``Controller.set_dead_time``, the CLI's ``--event T:dead-time=θ``). Then a set-point step.

    python examples/dead_time_change.py [OUT]   (a file, e.g. docs/guide/src/figures/msp-dead-time.svg as
                                                 scripts/figures writes it, or a directory:
                                                 OUT/dead_time_change.png)
"""

import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.hashsalt"] = "msp"  # the same file from the same code
import matplotlib.pyplot as plt  # noqa: E402

import msp  # noqa: E402

PLANT = "5.6*e^-93.9s/(40.2s+1)"  # the MathWorks Smith predictor example
COMMON = dict(controller="smith", ts=0.939, setpoint=["1@0", "2@900"], duration=1800.0)


def main(out: pathlib.Path) -> None:
    moved = "700:plant-dead-time=140.85"
    stale = msp.run(PLANT, events=[moved], **COMMON)
    updated = msp.run(PLANT, events=[moved, "700:dead-time=140.85"], **COMMON)
    fig, (ax, ax_u) = plt.subplots(2, 1, figsize=(9, 6), sharex=True, height_ratios=(2, 1))
    ax.plot(updated.t, updated.r, "k--", lw=1, label="r (set point)")
    ax.plot(stale.t, stale.y, color="tab:red", label="y, the model's dead time left at 93.9 s")
    ax.plot(updated.t, updated.y, color="tab:blue", label="y, the model's dead time updated")
    ax_u.plot(stale.t, stale.u, color="tab:red")
    ax_u.plot(updated.t, updated.u, color="tab:blue")
    for a in (ax, ax_u):
        a.axvline(700, color="gray", lw=0.8)
        a.grid(alpha=0.3)
    ax.text(710, 1.45, "plant dead time 93.9 s -> 140.85 s", color="gray")
    ax.set_ylabel("output y")
    ax_u.set_ylabel("control u")
    ax_u.set_xlabel("time t (s)")
    ax.set_title("Smith predictor on " + PLANT + ": a dead-time change at 700 s")
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(out, metadata={"Date": None})


if __name__ == "__main__":
    target = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    main(target / "dead_time_change.png" if target.is_dir() else target)
