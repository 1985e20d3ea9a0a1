"""msp.run against python-control's forced_response of the same Smith-predictor loop.

The loop: P = 5.6 e^(-93.9 s)/(40.2 s + 1) with the Smith predictor and Kaya's PI
(lambda = L), a unit set-point step. python-control needs a rational delay: a
5th-order Padé approximation. The exact answer is y = 1 - exp(-(t - L)/lambda) after
the delay (Kaya (2003) Eq. 25). Prints the time per call and the largest error of each.

Run: python benches/python_vs_control.py (with msp and control installed).
"""

import time

import numpy as np

import control
import msp

PLANT = "5.6*e^-93.9s/(40.2s+1)"
K, T, L = 5.6, 40.2, 93.9
# a unit set-point step on msp's grid for this plant (ts = L/1000, duration 10 L:
# 10 001 samples; given, so that the run is this step alone and not the default
# scenario's step and load); python-control gets the same time grid
TS = 0.0939
DURATION = 939.0


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def interleaved(rounds=10, per_round=4):
    """Best times of both, measured in alternation: a virtual machine's speed
    drifts by tens of percent over seconds, and a ratio of two times taken
    minutes apart would measure the drift."""
    best_msp, best_ctl = float("inf"), float("inf")
    res = ctl = None
    for _ in range(rounds):
        for _ in range(per_round):
            t, res = timed(with_msp)
            best_msp = min(best_msp, t)
        t, ctl = timed(with_control)
        best_ctl = min(best_ctl, t)
    return best_msp, res, best_ctl, ctl


def with_msp():
    return msp.run(PLANT, setpoint=1.0, ts=TS, duration=DURATION)


def with_control():
    kp, ti = T / (K * L), T
    c = control.tf([kp * ti, kp], [ti, 0])
    g = control.tf([K], [T, 1])
    num, den = control.pade(L, 5)
    delay = control.tf(num, den)
    loop = control.feedback(c * g, 1) * delay  # Smith predictor, perfect model
    t = np.arange(0.0, DURATION + TS / 2, TS)
    resp = control.forced_response(loop, T=t, U=np.ones_like(t))
    return t, resp.outputs


def exact(t):
    return np.where(t > L, 1.0 - np.exp(-(t - L) / L), 0.0)


if __name__ == "__main__":
    t_msp, res, t_ctl, (t, y_ctl) = interleaved()
    err_msp = np.max(np.abs(res.y - exact(res.t)))
    err_ctl = np.max(np.abs(y_ctl - exact(t)))
    print(f"msp.run                  {t_msp * 1e3:8.3f} ms   max error vs exact {err_msp:.2e}")
    print(f"control.forced_response  {t_ctl * 1e3:8.3f} ms   max error vs exact {err_ctl:.2e} (5th-order Padé)")
    print(f"speed-up                 {t_ctl / t_msp:8.1f} x")
