"""García, Santos, Normey-Rico & Albertos, Example 1 (García et al. (2010) Figs. 8-9).

Unstable cascade process: primary e^(-4s)/(20s-1), secondary 2e^(-2s)/(20s+1),
T = 0.2 s. FSPCC and GPCC against Uma et al. 2009, all with the same primary
controller Gcs = (4.6571 + 0.1829/s + 12.2857 s)/(2.8571 s + 1) and set-point
weight 0.3, the inner IMC loop 0.5(20s+1)/(2s+1); Uma's disturbance controller
Gcd = (3.1190 + 0.0921/s + 6.6156 s)(3s+1)/(0.144s+1) and Gf = 1/(36s+1);
FSPCC's filter from the same lead and lag; GPCC's Fk = 1/(36s+1).
Loads of -1 at d2 (t = 150 s) and -0.2 at d1 (t = 300 s); top: nominal
(Fig. 8), bottom: +20 % primary dead time, -20 % primary time constant (Fig. 9).
Writes garcia_example1.png.
"""

import pathlib
import sys

import matplotlib.pyplot as plt

import msp

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
params = {
    "kp": 4.6571, "ki": 0.1829, "kd": 12.2857, "tau": 2.8571, "epsilon": 0.3, "lambda2": 2.0,
    "fspcc.tf": 36.0, "fspcc.lead": 3.0, "fspcc.lag": 0.144,
    "gpcc.tk": 36.0,
    "uma.kpd": 3.1190, "uma.kid": 0.0921, "uma.kdd": 6.6156, "uma.lead": 3.0, "uma.lag": 0.144, "uma.tf": 36.0,
}
scenario = dict(inner_plant="2e^-2s/(20s+1)", ts=0.2, duration=450, params=params,
                disturbance=["d2:-1@150", "d1:-0.2@300"])
cases = [({}, "nominal (Fig. 8)"), ({"delay": 0.2, "tau": -0.2}, "+20 % L1, -20 % T1 (Fig. 9)")]
fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
for row, (perturb, title) in zip(axes, cases):
    runs = msp.compare("e^-4s/(20s-1)", ["fspcc", "gpcc", "uma"], perturb=perturb, **scenario)
    for res in runs:
        row[0].plot(res.t, res.y, label=res.controller["name"])
        row[1].plot(res.t, res.u, label=res.controller["name"])
        assert res.stable
    peak = {r.controller["name"]: abs(r.u[r.t >= 150]).max() for r in runs}
    row[0].set_title(f"process output, {title}", fontsize=9)
    row[1].set_title("control action (peak after 150 s: "
                     + ", ".join(f"{k} {v:.3g}" for k, v in peak.items()) + ")", fontsize=9)
    row[1].set_ylim(-10, 10)
    for ax in row:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
for ax in axes[-1]:
    ax.set_xlabel("t (s)")
fig.tight_layout()
fig.savefig(out / "garcia_example1.png", dpi=90)
