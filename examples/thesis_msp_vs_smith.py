"""The thesis's modified Smith predictor vs the Smith predictor for model 1 (Bag (2022) Fig. 5.4).

P(s) = 0.2 e^(-7.4 s)/s; both with Kp = 2/(K λ), Ti = 2λ, λ = θ/4; a step load
at the plant input at t = 40 s. Writes thesis_msp_vs_smith.png.
"""

import pathlib
import sys

import matplotlib.pyplot as plt

import msp

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
plant = "0.2/s*e^-7.4s"
common = dict(duration=80, disturbance="input:-0.1@40")
runs = [(msp.run(plant, "karan-dey", **common), "MSP (Karan–Dey)"), (msp.run(plant, "smith", **common), "Smith predictor")]
fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
for res, label in runs:
    a1.plot(res.t, res.y, label=label)
    a2.plot(res.t, res.u, label=label)
a1.plot(runs[0][0].t, runs[0][0].r, "k--", lw=0.8)
a1.set_ylabel("y")
a2.set_ylabel("u")
a2.set_xlabel("t (s)")
a1.legend()
a1.set_title("model 1: " + plant)
fig.savefig(out / "thesis_msp_vs_smith.png", dpi=100)
