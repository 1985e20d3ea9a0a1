"""PI control vs the Smith predictor on the MATLAB example plant (the MathWorks Smith predictor example).

P(s) = 5.6 e^(-93.9 s)/(40.2 s + 1); PI with Kp = 0.0501, Ti = 47.3 (the
example's pidtune design); a step load of -0.1 at the plant input at t = 1000 s.
Writes matlab_pi_vs_smith.png into the folder given as the first argument.
"""

import pathlib
import sys

import matplotlib.pyplot as plt

import msp

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
plant = "5.6*e^-93.9s/(40.2s+1)"
common = dict(ts=1.0, duration=2000, disturbance="input:-0.1@1000")
pi = msp.run(plant, "pid", {"kp": 0.0501, "ti": 47.3, "td": 0.0}, **common)
sp = msp.run(plant, "smith", **common)

fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
for res, label in ((pi, "PI"), (sp, "Smith predictor")):
    a1.plot(res.t, res.y, label=label)
    a2.plot(res.t, res.u, label=label)
a1.plot(sp.t, sp.r, "k--", lw=0.8)
a1.set_ylabel("y")
a2.set_ylabel("u")
a2.set_xlabel("t (s)")
a1.legend()
a1.set_title(plant)
fig.savefig(out / "matlab_pi_vs_smith.png", dpi=100)
