"""msp.run against python-control's forced_response, measured side by side in one run.

Two loops on the MathWorks example plant P = 5.6 e^(-93.9 s)/(40.2 s + 1):

1. Its PI controller (Kp = 0.0501, Ti = 47.3, the example's pidtune result), Ts = 0.1 s,
   3000 s (30 001 samples), a unit set-point step. python-control needs a rational delay:
   a 5th-order Padé approximation. The target: msp.run at least 300x faster.
2. The Smith predictor with Kaya's PI (lambda = L) on msp's grid for the plant (10 001
   samples), whose exact answer is y = 1 - exp(-(t - L)/lambda) after the delay (Kaya (2003)
   Eq. 25): the error of each against it.

msp.run computes the stability verdict and the robustness figures when they are first read
(``result.stable``, ``result.robustness``, ``result.report()``); the timings below are of
runs that do not read them, then of one that does.

Run: python benches/python_vs_control.py (with msp and control installed).
"""

import time

import numpy as np

import control
import msp

PLANT = "5.6*e^-93.9s/(40.2s+1)"
K, T, L = 5.6, 40.2, 93.9
KP, TI = 0.0501, 47.3


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def interleaved(a, b, rounds=10, per_round=4):
    """Best times of both, measured in alternation: a virtual machine's speed
    drifts by tens of percent over seconds, and a ratio of two times taken
    minutes apart would measure the drift."""
    best_a, best_b = float("inf"), float("inf")
    out_a = out_b = None
    for _ in range(rounds):
        for _ in range(per_round):
            t, out_a = timed(a)
            best_a = min(best_a, t)
        t, out_b = timed(b)
        best_b = min(best_b, t)
    return best_a, out_a, best_b, out_b


def pi_msp():
    return msp.run(PLANT, "pi", {"kp": KP, "ti": TI}, setpoint=1.0, ts=0.1, duration=3000.0)


def pi_control():
    c = control.tf([KP * TI, KP], [TI, 0])
    g = control.tf([K], [T, 1])
    num, den = control.pade(L, 5)
    loop = control.feedback(c * g * control.tf(num, den), 1)
    t = np.arange(0.0, 3000.0 + 0.05, 0.1)
    return t, control.forced_response(loop, T=t, U=np.ones_like(t)).outputs


# the Smith predictor on msp's own grid for this plant (ts = L/1000, duration 10 L)
TS, DURATION = 0.0939, 939.0


def smith_msp():
    return msp.run(PLANT, setpoint=1.0, ts=TS, duration=DURATION)


def smith_control():
    kp, ti = T / (K * L), T
    c = control.tf([kp * ti, kp], [ti, 0])
    g = control.tf([K], [T, 1])
    num, den = control.pade(L, 5)
    delay = control.tf(num, den)
    loop = control.feedback(c * g, 1) * delay  # Smith predictor, perfect model
    t = np.arange(0.0, DURATION + TS / 2, TS)
    return t, control.forced_response(loop, T=t, U=np.ones_like(t)).outputs


def exact(t):
    return np.where(t > L, 1.0 - np.exp(-(t - L) / L), 0.0)


if __name__ == "__main__":
    t_msp, res, t_ctl, (t, y_ctl) = interleaved(pi_msp, pi_control)
    n = len(res.t)
    print(f"PI, Ts 0.1 s, 3000 s ({n} samples)")
    print(f"  msp.run                  {t_msp * 1e3:8.3f} ms   {t_msp / n * 1e9:6.1f} ns/sample")
    print(f"  control.forced_response  {t_ctl * 1e3:8.3f} ms   (5th-order Padé)")
    print(f"  speed-up                 {t_ctl / t_msp:8.1f} x   (target: 300 x)")
    print(f"  largest difference of y  {np.max(np.abs(res.y - y_ctl)):.2e} (the Padé's error)")
    t_full, full = timed(lambda: pi_msp().report())
    print(f"  msp.run + its analysis   {t_full * 1e3:8.3f} ms   (stable={full['stable']})")

    t_msp, res, t_ctl, (t, y_ctl) = interleaved(smith_msp, smith_control)
    err_msp = np.max(np.abs(res.y - exact(res.t)))
    err_ctl = np.max(np.abs(y_ctl - exact(t)))
    print(f"Smith predictor, Kaya's PI ({len(res.t)} samples), against the exact response")
    print(f"  msp.run                  {t_msp * 1e3:8.3f} ms   max error {err_msp:.2e}")
    print(f"  control.forced_response  {t_ctl * 1e3:8.3f} ms   max error {err_ctl:.2e}")
    print(f"  speed-up                 {t_ctl / t_msp:8.1f} x")
