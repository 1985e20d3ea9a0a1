"""Matplotlib plots of msp results (imported lazily: matplotlib is optional)."""

from __future__ import annotations

from typing import Any


def plot_result(res: Any, ax: Any = None, title: str | None = None) -> Any:
    """Two panels: set point and output on top, actuator below. Returns the Figure.

    With ``ax`` (a pair of Axes) the curves are drawn there instead.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5), height_ratios=[3, 2])
    else:
        a1, a2 = ax
        fig = a1.figure
    a1.plot(res.t, res.r, "k--", lw=1, label="r")
    a1.plot(res.t, res.y, lw=1.5, label=f"y ({res.controller['name']})")
    a1.set_ylabel("r, y")
    a1.legend(loc="best")
    a1.grid(True, alpha=0.3)
    a2.plot(res.t, res.u, lw=1.2, color="tab:red", label="u")
    a2.set_ylabel("u")
    a2.set_xlabel("t (s)")
    a2.grid(True, alpha=0.3)
    a1.set_title(title if title is not None else f"{res.controller['name']} — {res.plant}")
    return fig
