"""The results the module's functions return: a run's, a multivariable run's,
margins, a trade-off and a step response."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np

from . import _msp
from ._msp import Controller, Estimator, Pid, Plant, __version__, controllers, parse_plant

if sys.version_info >= (3, 11):
    from typing import Unpack
elif TYPE_CHECKING:
    from typing_extensions import Unpack


class MimoResult:
    """A multivariable run (:func:`run` of a matrix plant): the signals as numpy arrays, a row
    per loop, and the report of ``msp run --plant "[…]" --report``.

    Attributes
    ----------
    t : numpy.ndarray
        The sample instants (s).
    r, y, u : numpy.ndarray
        Shape ``(n, samples)``: each loop's set point, output and input.
    report : dict
        ``{"plant", "rga", "pairing", "niederlinski", "scheme", "ts", "f", "loops",
        "decoupler", "rule", "alone", "stability", "decoupler_stability", "lcm", "duration",
        "setpoints", "loads", "iae", "interaction"}``.
    iae : list of float
        Each loop's IAE.
    interaction : list of dict
        Per set-point step: ``step_loop`` (0-based), ``at`` and ``deviation`` (the largest of
        each output up to the next step).
    stable : bool or None
        The sampled loop's verdict (the generalized Nyquist criterion on ``det(I + GC)``).
    """

    def __init__(self, raw: Tuple[Dict[str, Any], Any, List[Any]]) -> None:
        import numpy as np

        report, t, loops = raw
        self.report: Dict[str, Any] = report
        self.t = t
        self.r = np.array([c[0] for c in loops])
        self.y = np.array([c[1] for c in loops])
        self.u = np.array([c[2] for c in loops])
        self.iae: List[float] = report["iae"]
        self.interaction: List[Dict[str, Any]] = report["interaction"]
        self.stable: Optional[bool] = report["stability"]["stable"]

    def __repr__(self) -> str:
        n = len(self.y)
        return (f"MimoResult({self.report['scheme']} on a {n}x{n} plant, {len(self.t)} samples, "
                f"IAE {[round(v, 4) for v in self.iae]})")

    def plot(self, axes: Any = None) -> Any:
        """A panel per output (set point dashed) and per input, as ``msp run --plot``."""
        from msp.plotting import plot_mimo

        return plot_mimo(self, axes)


class Result:
    """The outcome of a closed-loop run: signals as numpy arrays and the figures.

    The signals are the simulator's own buffers, read-only (``result.y.copy()`` for an array to
    change). The figures of a run of :func:`run` or :func:`simulate` (``metrics``, ``events``,
    ``stable``, ``robustness``...) are computed from them when first read: a run whose figures
    are never read costs the simulation alone.

    Attributes
    ----------
    t, r, y, u, d : numpy.ndarray
        Time, set point, plant output, actuator value, input (load) disturbance.
    d_out : numpy.ndarray
        Output disturbance.
    u_applied : numpy.ndarray or None
        What the plant received when ``actuator`` limits it or operator ``events`` run
        (``None`` otherwise).
    y2, d_inner : numpy.ndarray or None
        Cascade processes: the secondary output as measured and the disturbance
        ``d0`` at the secondary output (``None`` for a single plant).
    inner_plant, inner_model : str or None
        Cascade processes: the secondary process and the controller's model of it.
    signals : dict of str to numpy.ndarray
        The controller's internal signals (also readable as attributes).
    metrics, metrics_delayed_reference : dict of str to float
        Step information and integral indices on ``r - y`` and on
        ``r(t - θm) - y`` with time counted from ``θm``.
    controller : dict
        ``{"name": ..., "params": {...}}``.
    events : list of dict
        One entry per set-point step (``kind="setpoint"``: ``at``, ``until``, ``value``, ``iae`` and the
        step information of its segment) and per disturbance (``kind="disturbance"``: ``location``,
        ``value``, ``peak_deviation``, ``peak_time``, ``recovery_time``, ``iae``), in time order.
    operator_events : list of dict
        The ``events`` of the call, each with ``at``, ``action`` and ``output_change`` (the
        controller output's change at the event's sample).
    robustness : dict or None
        The tuned loop's ``gm``, ``pm``, ``dm``, ``ms``, ``mt`` (sampled view).
    design : dict
        What the scheme designed beside its parameters (FSP's and FSPCC's ``Fr``: ``kf``, ``rho1``...,
        ``gamma1``..., ``cancels``; GPCC's ``gamma``, ``f2``, ``f1_taps``, ``f1_gain``); empty for
        schemes whose parameters are all they design.
    scenario : dict
        The scenario as it was given (the report's copy: ``msp run --scenario report.json`` reruns it).
    msp_version : str
        The version of msp that made the run.
    default_scenario : bool
        The run is msp's default scenario, chosen because the call named no ``setpoint``,
        ``disturbance`` or ``duration``: a unit set-point step at 0 s, then a step load at the plant
        input once the response has settled (``events`` says when and how large), ending soon after
        the load is rejected.
    chosen : list of str
        Which of ``ts``, ``duration`` and ``lambda`` msp chose because the call did not give them.
    stable : bool or None
        The loop's stability verdict from its characteristic equation (``None`` when it could not
        be decided; ``stability["reason"]`` says why).
    stability : dict
        ``stable``, ``unstable_poles`` (closed-loop poles outside the unit circle),
        ``open_loop_unstable_poles``, ``simulation`` (the run's cross-check), ``as_built_until``
        (when an event or the adaptation changed the loop, s: the verdict is the loop's as built,
        the simulation compared up to then; ``None``: the loop analysed ran to the end) and
        ``reason``.
    plant, plant_kind, model, ts, duration, samples, float32, diverged_at, warnings
        The rest of the run report: the same keys and values as
        ``msp run --report`` writes (:meth:`report` returns them as one dict).
    """

    t: np.ndarray
    r: np.ndarray
    y: np.ndarray
    u: np.ndarray
    d: np.ndarray
    d_out: np.ndarray
    u_applied: Optional[np.ndarray]
    y2: Optional[np.ndarray]
    d_inner: Optional[np.ndarray]
    inner_plant: Optional[str]
    inner_model: Optional[str]
    signals: Dict[str, np.ndarray]
    metrics: Dict[str, float]
    metrics_delayed_reference: Dict[str, float]
    controller: Dict[str, Any]
    plant: str
    plant_kind: str
    model: str
    ts: float
    chosen: List[str]
    design: Dict[str, Any]
    scenario: Dict[str, Any]
    msp_version: str
    default_scenario: bool
    events: List[Dict[str, Any]]
    operator_events: List[Dict[str, Any]]
    robustness: Optional[Dict[str, float]]
    duration: float
    samples: int
    stable: Optional[bool]
    stability: Dict[str, Any]
    diverged_at: Optional[float]
    float32: bool
    warnings: List[str]

    _ARRAYS = ("t", "r", "y", "u", "u_applied", "d", "d_out", "y2", "d_inner", "signals")
    # computed when first read (the figures of a long run, the stability verdict and the robustness
    # analysis cost more than the simulation): a run that never reads them does not pay for them
    _MEASURED = ("metrics", "metrics_delayed_reference", "events")
    _ANALYSED = ("stable", "stability", "robustness", "warnings")

    def __init__(self, raw: Mapping[str, Any]) -> None:
        self.y2 = self.d_inner = self.u_applied = None
        pending = raw.get("_analysis")
        lazy = self._MEASURED + self._ANALYSED if pending is not None else ()
        for key, value in raw.items():
            if key != "_analysis" and key not in lazy:
                setattr(self, key, value)
        self._report = {k: v for k, v in raw.items() if k not in self._ARRAYS and k != "_analysis"}
        self._pending = pending
        self._missing = set(lazy)

    def _complete(self, names: Tuple[str, ...]) -> None:
        pending = self.__dict__.get("_pending")
        if pending is None or not self._missing.intersection(names):
            return
        done = pending.measure() if names == self._MEASURED else pending.compute()
        self._report.update(done)
        self.__dict__.update(done)
        self._missing.difference_update(done)
        if not self._missing:
            self._pending = None

    def report(self) -> Dict[str, Any]:
        """The run report: the keys and values ``msp run --report`` writes (NaN where it writes null)."""
        self._complete(self._MEASURED)
        self._complete(self._ANALYSED)
        return dict(self._report)

    def __getattr__(self, name: str) -> Any:
        for names in (self._MEASURED, self._ANALYSED):
            if name in names and name in self.__dict__.get("_missing", ()):
                self._complete(names)
                return self.__dict__[name]
        signals = self.__dict__.get("signals", {})
        if name in signals:
            return signals[name]
        raise AttributeError(name)

    def __repr__(self) -> str:
        return (f"<msp.Result {self.controller['name']} on {self.plant}: {len(self.t)} samples, "
                f"ts={self.ts:g}, stable={self.stable}>")

    def to_pandas(self) -> Any:
        """The signals as a pandas DataFrame indexed by time (needs pandas)."""
        import pandas as pd  # type: ignore[import-untyped]

        cols: Dict[str, np.ndarray] = {"r": self.r, "y": self.y, "u": self.u, "d": self.d}
        if self.y2 is not None:
            cols["y2"] = self.y2
        cols.update(self.signals)
        return pd.DataFrame(cols, index=pd.Index(self.t, name="t"))

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """A matplotlib Figure of r, y and u (needs matplotlib: ``pip install msp[plot]``)."""
        from .plotting import plot_result

        return plot_result(self, ax=ax, **kwargs)


class _Report(Dict[str, Any]):
    """A result dict whose keys read as attributes too (``m.gm`` for ``m["gm"]``)."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


class Margins(_Report):
    """The result of :func:`margins`: a dict with the keys of ``msp margins --json`` (kept for
    code that indexes it), every key also an attribute (``m.gm``, ``m.w``, ``m.l``), a short
    ``repr`` with the numbers, and :meth:`plot` for Bode and Nyquist."""

    def __repr__(self) -> str:
        def f(v: Any) -> str:
            return "None" if v is None else f"{v:.4g}"

        return (f"<msp.Margins {self['controller']['name']} on {self['plant']} ({self['view']}): "
                f"gm={f(self['gm'])} ({f(self['gm_db'])} dB) at {f(self['wcg'])} rad/s, "
                f"pm={f(self['pm'])} deg at {f(self['wcp'])} rad/s, dm={f(self['dm'])} s, "
                f"ms={f(self['ms'])}, mt={f(self['mt'])}, stable={self['stable']}>")

    def plot(self, ax: Any = None) -> Any:
        """A matplotlib Figure: Bode (phase unwrapped, gm and pm marked) and Nyquist with the unit and
        Ms circles, as ``msp margins --plot`` (needs matplotlib: ``pip install msp[plot]``)."""
        from .plotting import plot_margins

        return plot_margins(self, ax=ax)


class Tradeoff(_Report):
    """The result of :func:`tradeoff`: the keys of ``msp tradeoff --json`` (``plant``, ``ts``,
    ``factors``, ``points``, ``skipped``), read as attributes too, and :meth:`plot`."""

    def scheme(self, name: str) -> List[Dict[str, Any]]:
        """The points of one scheme, λ increasing."""
        return [p for p in self["points"] if p["scheme"] == name]

    def plot(self, ax: Any = None) -> Any:
        """A matplotlib Figure as ``msp tradeoff --plot``: ``Ms`` against the IAE of a unit input load
        (left) and of a unit set-point step (right), a curve per scheme, its own tuning ringed."""
        from .plotting import plot_tradeoff

        return plot_tradeoff(self, ax=ax)


class Step(_Report):
    """The result of :func:`step`: the keys of ``msp step --json`` with ``t`` and ``y`` (kept for
    code that indexes it), read as attributes too, and :meth:`plot`."""

    def plot(self, ax: Any = None) -> Any:
        """A matplotlib Figure as ``msp step --plot``: the response, its final value dashed, the
        rise (10-90 %) and the settling time marked (needs matplotlib: ``pip install msp[plot]``)."""
        from .plotting import plot_step

        return plot_step(self, ax=ax)
