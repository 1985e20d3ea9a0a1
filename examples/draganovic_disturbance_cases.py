"""Draganović, Stojić & Matijević's disturbance estimator, Cases 1-6 (Draganović et al. (2001) Figs. 3-7).

Plant e^(-5s)/(s(0.9s+1)(0.5s+1)(0.3s+1)(0.1s+1)), model e^(-6.8s)/s, main
controller Kr = 0.5 (Td = 2 s). Constant loads for Cases 1-3, a ramp for Cases
4-5, a sinusoid at 0.05 rad/s for Case 6. Writes draganovic_cases.png.
"""

import math
import pathlib
import sys

import matplotlib.pyplot as plt

import msp

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
plant = "e^-5s/(s(0.9s+1)(0.5s+1)(0.3s+1)(0.1s+1))"
w0 = 0.05
cases = [
    (1, {}, "input:-0.1@70", "Case 1: P (Fig. 3)"),
    (2, {}, "input:-0.1@70", "Case 2: PD (Fig. 4)"),
    (3, {"tde": 0.55 * 6.8}, "input:-0.1@70", "Case 3: lead (Fig. 5)"),
    (4, {}, "input:ramp:-0.01@70", "Case 4: PI, ramp (Fig. 6)"),
    (5, {"alpha": 0.7}, "input:ramp:-0.01@70", "Case 5: PI, alpha = 0.7 (Fig. 6)"),
    (6, {}, f"input:sine:0.1@37~{w0 / (2 * math.pi)}", "Case 6: sinusoid (Fig. 7)"),
]
fig, axes = plt.subplots(3, 2, sharex=True, figsize=(10, 8))
for ax, (case, extra, dist, title) in zip(axes.flat, cases):
    res = msp.run(plant, "disturbance-estimator", {"case": case, "td": 2.0, **extra},
                  model="e^-6.8s/s", ts=0.02, duration=300, disturbance=dist)
    ax.plot(res.t, res.y, label="y")
    ax.plot(res.t, res.r, "k--", lw=0.8)
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
for ax in axes[-1]:
    ax.set_xlabel("t (s)")
fig.tight_layout()
fig.savefig(out / "draganovic_cases.png", dpi=90)
