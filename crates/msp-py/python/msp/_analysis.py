"""Analysis, design and identification: margins, trade-offs, sweeps,
autotuning, steps, identification, simulation of given signals, step
information and tuning."""

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

from ._common import PlantLike, _plant, _scenario
from ._options import DesignOptions, MATRIX_KEYWORDS, PidOptions, RelayOptions, RunOptions, TuneOptions
from ._results import MimoResult, Margins, Result, Step, Tradeoff, _Report


def _relative(v: Union[str, float]) -> float:
    if isinstance(v, str):
        text = v.strip()
        return float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    return float(v)


def _range(r: Union[None, str, float, Tuple[float, float]]) -> Tuple[float, float]:
    if r is None:
        return (0.0, 0.0)
    if isinstance(r, str):
        a, _, b = r.partition("..")
        return (_relative(a), _relative(b or a))
    if isinstance(r, (int, float)):
        return (float(r), float(r))
    return (float(r[0]), float(r[1]))


def margins(
    plant: PlantLike,
    controller: Optional[str] = None,
    params: Optional[Mapping[str, float]] = None,
    *,
    delay: Optional[float] = None,
    discrete: bool = False,
    continuous: bool = False,
    uncertainty: Union[None, str, Mapping[str, float], Tuple[float, float]] = None,
    **scenario: Unpack[DesignOptions],
) -> Dict[str, Any]:
    """Margins of the loop at the plant input with the exact dead time, as ``msp margins``.

    Without ``controller`` (or with ``"none"``) the loop is the bare plant, ``L = G``, as
    MATLAB's ``margin(G)``; ``params={"kp": K}`` makes it a pure gain.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    controller : str, optional
        The scheme (:func:`controllers`), ``"none"`` or absent for the bare plant.
    params : dict, optional
        Overrides of tuned parameters, as :func:`run`.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.
    discrete : bool, optional
        The plant's exact discrete equivalent instead of the continuous plant behind the hold.
    continuous : bool, optional
        The continuous plant without the hold (the margins of a continuous design).
    uncertainty : str, dict or (gain, delay), optional
        A perturbation (``"gain=10%,delay=10%,tau=-20%"``) for Eq. 17's robust-stability peak
        ``max|T·Δ|`` with the exact multiplicative uncertainty.
    **scenario
        The keywords of :class:`DesignOptions`, as :func:`run` takes them (``max_memory``
        bounds the simulation that cross-checks the verdict); with ``inner_plant`` the loop is broken at
        the inner set point ``r2``.

    Returns
    -------
    Margins
        A dict with ``gm``, ``gm_db``, ``pm`` (degrees), ``wcg``, ``wcp``, ``dm`` (s), ``ms``,
        ``mt`` (python-control / MATLAB names), ``view``, ``controller``, ``inner`` (the model
        loop's margins), ``region`` (``{"gain", "dm"}`` points), ``stable`` (the verdict of the
        characteristic equation, ``None`` when it could not be decided), ``stability`` (the
        verdict with ``unstable_poles``, ``simulation`` and ``reason``; an unstable loop's margins
        are NaN), ``phase_unwrapped`` (degrees at ``w``, continuous as MATLAB's ``bode`` draws
        it, the plant's dead time exact), ``robust_peak``, ``published`` (present for the plants of Bag (2022) whose
        printed margins are another computation's: what the thesis computed, see
        ``docs/fidelity.md``) and the loop
        response ``w``, ``l`` (``l[:, 0] + 1j*l[:, 1]``); keys read as attributes too, and
        :meth:`Margins.plot` draws Bode and Nyquist.

    Raises
    ------
    ValueError
        As :func:`run`, and for a controller without a frequency response.

    Examples
    --------
    >>> m = msp.margins("1/(s^3+2s^2+3s+4)", continuous=True)
    >>> round(m.gm, 6), m.controller["name"]
    (2.0, 'none')
    """
    unc: Any = None
    if isinstance(uncertainty, (str, Mapping)):
        unc = uncertainty if isinstance(uncertainty, str) else {k: float(v) for k, v in uncertainty.items()}
    elif uncertainty is not None:
        unc = {"gain": float(uncertainty[0]), "delay": float(uncertainty[1])}
    kw = _scenario(scenario, controller=controller, params=params)
    return Margins(_msp.margins(_plant(plant, delay), discrete=discrete, continuous=continuous,
                                uncertainty=unc, **kw))


def tradeoff(
    plant: PlantLike,
    controllers: Optional[Sequence[str]] = None,
    *,
    model: Optional[PlantLike] = None,
    ts: Optional[float] = None,
    delay: Optional[float] = None,
) -> Tradeoff:
    """Robustness against performance for every scheme that applies to ``plant``, as
    ``msp tradeoff``: each scheme's λ swept from 1/8 to 8 times its own (13 points), and per point
    the loop's ``ms`` and delay margin ``dm`` beside the IAE of a unit set-point step
    (``iae_setpoint``), of a unit input load (``iae_load``; infinite where the load leaves an
    offset) and the control's total variation ``tv``.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    controllers : list of str, optional
        The schemes; by default every single-loop scheme for the plant tuned by λ.
    model : str, Plant or control.TransferFunction, optional
        The controllers' model (default: the plant).
    ts : float, optional
        The common sample period; chosen from the plant when absent.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.

    Returns
    -------
    Tradeoff
        ``points``: a dict per point with ``scheme``, ``lambda``, ``default`` (the scheme's own
        tuning), ``stable`` and the figures (NaN unless stable); ``skipped``: the schemes left
        out and why. :meth:`Tradeoff.plot` draws the picture.

    Examples
    --------
    >>> t = msp.tradeoff("0.2/s*e^-7.4s", ["karan-dey", "watanabe-ito"])
    >>> own = [p for p in t.points if p["default"]]
    >>> [p["scheme"] for p in own], all(p["stable"] for p in own)
    (['karan-dey', 'watanabe-ito'], True)
    """
    kw: Dict[str, Any] = {}
    if model is not None:
        kw["model"] = _plant(model, None)
    if ts is not None:
        kw["ts"] = float(ts)
    return Tradeoff(_msp.tradeoff(_plant(plant, delay), list(controllers or []), **kw))


def sweep(
    plant: PlantLike,
    controller: Optional[str] = None,
    params: Optional[Mapping[str, float]] = None,
    *,
    gain: Union[None, str, float, Tuple[float, float]] = None,
    delay: Union[None, str, float, Tuple[float, float]] = None,
    tau: Union[None, str, float, Tuple[float, float]] = None,
    grid: int = 11,
    samples: int = 0,
    seed: int = 1,
    shard: Tuple[int, int] = (0, 1),
    duration: Optional[float] = None,
    **scenario: Unpack[DesignOptions],
) -> Dict[str, np.ndarray]:
    """Many closed-loop runs over relative plant perturbations, in parallel, as ``msp sweep``.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    controller : str, optional
        The scheme; by default chosen by the plant's kind.
    params : dict, optional
        Overrides of tuned parameters, as :func:`run`.
    gain, delay, tau : str, float or (lo, hi), optional
        Ranges of relative changes (``"-20%..+20%"`` or ``(-0.2, 0.2)``); absent: no change.
    grid : int, optional
        Points per range on a full grid.
    samples : int, optional
        Instead of the grid, this many random points (Latin hypercube) seeded by ``seed``.
    seed : int, optional
        The seed of the random points.
    shard : (int, int), optional
        ``(i, n)``: only the runs whose index is ``i`` modulo ``n`` (for distributed engines).
    duration : float, optional
        As :func:`run`.
    **scenario
        The keywords of :class:`DesignOptions`, as :func:`run` takes them; with
        ``inner_plant`` the primary is perturbed, the secondary kept.

    Returns
    -------
    dict of str to numpy.ndarray
        One column per field: ``index``, ``gain``, ``delay``, ``tau``, ``stable``, the metrics
        and ``max_abs_u``.

    Raises
    ------
    ValueError
        As :func:`run`, and for a bad range or more runs than the limit.

    Examples
    --------
    >>> cols = msp.sweep("0.2/s*e^-7.4s", "karan-dey", gain="-10%..+10%", grid=3, ts=0.074, duration=60)
    >>> len(cols["iae"]), bool(cols["stable"].all())
    (3, True)
    """
    kw = _scenario(scenario, controller=controller, params=params, duration=duration)
    return _msp.sweep(_plant(plant), gain=_range(gain), delay=_range(delay), tau=_range(tau), grid=grid,
                      samples=samples, seed=seed, shard=(int(shard[0]), int(shard[1])), **kw)


def autotune(
    plant: PlantLike,
    *,
    delay: Optional[float] = None,
    **options: Unpack[RelayOptions],
) -> Dict[str, Any]:
    """Relay test on ``plant``, model identification, tuning and the closed loop, as ``msp autotune``.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.
    **options
        The keywords of :class:`RelayOptions`:
    relay_amplitude : float, optional
        The relay's output amplitude (default 1); the relay acts in the process's direction
        (a reverse-acting plant gets the negative amplitude), whatever its sign here.
    hysteresis : float, optional
        The relay's hysteresis (default: from the noise level).
    bias : float, optional
        A relay bias, which makes the cycle asymmetric and gives the static gain.
    noise : float, optional
        The standard deviation of measurement noise during the test (default 0).
    seed : int, optional
        The noise seed (default 0).
    model : str, optional
        The model to identify: ``"ipdt"``, ``"foipdt"``, ``"fopdt"``, ``"sopdt"`` or ``"ufopdt"``
        (default: the plain model of the plant's kind, or the one with a lag where the relay data
        shows it; the unstable FOPDT ``"ufopdt"`` for an unstable plant, from a biased relay).
    controller : str, optional
        The scheme to tune on the identified model.
    ts : float, optional
        The sample period (s).
    band : float, optional
        The safety band: the test aborts when the output leaves it (default: none).
    duration : float, optional
        The closed-loop run's duration (s).

    Returns
    -------
    dict
        ``{"identified": {"model": "fopdt", "k": …, "t": …, "l": …, "rmse": …, "r2": …},
        "relay": {...}, "run": Result}``.

    Raises
    ------
    RuntimeError
        When the relay test aborts (timeout, band).
    ValueError
        For a bad setting, or a model that does not fit the relay data.

    Examples
    --------
    >>> out = msp.autotune("2*e^-4s/(5s+1)", bias=0.2)
    >>> out["identified"]["model"]
    'fopdt'
    """
    raw = _msp.autotune(_plant(plant, delay), **options)
    raw["run"] = Result(raw["run"])
    return raw


def step(plant: PlantLike, *, ts: Optional[float] = None, duration: Optional[float] = None,
         delay: Optional[float] = None) -> Step:
    """The plant's own unit step response with its exact dead time, as ``msp step`` (MATLAB's
    ``step`` and ``stepinfo``, python-control's ``step_response`` and ``step_info``).

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    ts : float, optional
        The sample period of the response (s); the duration over 4000 when absent.
    duration : float, optional
        The simulated time (s); chosen from the plant when absent.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.

    Returns
    -------
    Step
        A dict ``{"t": ndarray, "y": ndarray, "plant", "plant_kind", "ts", "duration", "chosen",
        "dc_gain", "rise_time", "settling_time", "settling_min", "settling_max", "overshoot",
        "undershoot", "peak", "peak_time"}``; ``dc_gain`` is ``None`` and the step information NaN
        for a plant whose response does not settle (integrating or unstable); :meth:`Step.plot`
        draws it.

    Raises
    ------
    ValueError
        A plant expression that does not parse, or a period too small for the duration.

    Examples
    --------
    >>> s = msp.step("2*e^-1.3s/(5s+1)")
    >>> s["dc_gain"], round(s["rise_time"], 3)
    (2.0, 10.986)
    """
    return Step(_msp.step(_plant(plant, delay), ts=ts, duration=duration))


def _vector(name: str, v: Any) -> "np.ndarray":
    """``v`` as a contiguous float64 vector: a sequence, a 1-D array, or a row
    or column of a 2-D one (python-control's ``(1, n)`` outputs); anything
    else a ValueError that names it."""
    try:
        a = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not an array of numbers ({e})") from None
    if a.ndim == 2 and 1 in a.shape:
        a = a.reshape(-1)
    if a.ndim != 1:
        raise ValueError(f"{name}: a vector of samples is needed, got an array of shape {a.shape}")
    return np.ascontiguousarray(a)


def identify(t: Any, u: Any, y: Any, model: str = "fopdt") -> Dict[str, Any]:
    """Step-test identification, as ``msp identify``: the two-point or slope/intercept estimate,
    refined by least squares on the exact sampled response.

    Parameters
    ----------
    t, u, y : array_like
        Time (uniform, increasing), the input with an open-loop step, and the output.
    model : str, optional
        ``"fopdt"``, ``"sopdt"`` or ``"ipdt"``.

    Returns
    -------
    dict
        ``{"model": ..., "k", "t", "l" (and "t2" for SOPDT), "rmse", "r2"}``.

    Raises
    ------
    ValueError
        Non-finite data (naming the row), a time that does not increase, or closed-loop data
        (an input that moves at most samples).

    Examples
    --------
    >>> t = np.arange(0.0, 60.0, 0.05)
    >>> u = (t >= 5.0).astype(float)                      # a unit step at 5 s
    >>> y = np.where(t > 9.0, 2.0 * (1.0 - np.exp(-(t - 9.0) / 5.0)), 0.0)
    >>> fit = msp.identify(t, u, y)
    >>> round(fit["k"], 3), round(fit["t"], 2), round(fit["l"], 2)
    (2.0, 5.0, 4.0)
    """
    arr = [_vector(n, v) for n, v in (("t", t), ("u", u), ("y", y))]
    return _msp.identify(arr[0], arr[1], arr[2], model)


def simulate(
    plant: PlantLike,
    controller: Optional[str] = None,
    params: Optional[Mapping[str, float]] = None,
    *,
    t: Any,
    r: Any,
    d: Any = None,
    d_out: Any = None,
    delay: Optional[float] = None,
    **scenario: Unpack[RunOptions],
) -> "Result":
    """The forced response: :func:`run` with the set point and the loads as sampled arrays
    (python-control's ``forced_response``, MATLAB's ``lsim``), as ``msp run --input FILE.csv``.

    Parameters
    ----------
    plant, controller, params, delay
        As :func:`run`.
    t : array_like
        Times, uniform from 0: their step is the controller's period ``ts`` (a ``ts`` given must
        be it) and their end the duration.
    r : array_like
        The set point at each time, held until the next.
    d, d_out : array_like, optional
        Loads at the plant input and at its output at each time.
    **scenario
        The keywords of :class:`RunOptions` but ``setpoint`` and ``disturbance`` (the arrays
        replace them): operator ``events``, ``noise``, the actuator and the rest apply.

    Returns
    -------
    Result
        As :func:`run`: each change of ``r`` is a set-point step and each change of ``d`` a load
        step, so the result is the run with those steps, to the bit.

    Raises
    ------
    ValueError
        Arrays of different lengths, non-finite values, times that are not uniform from 0, a
        ``ts`` that is not their step, or ``setpoint``/``disturbance`` given as well.

    Examples
    --------
    >>> t = np.arange(0.0, 100.0 + 1e-9, 0.5)
    >>> res = msp.simulate("2e^-3s/(4s+1)", "pi", t=t, r=np.ones_like(t), d=np.where(t >= 50, -0.1, 0.0))
    >>> same = msp.run("2e^-3s/(4s+1)", "pi", setpoint="1@0", disturbance="input:-0.1@50", ts=0.5,
    ...                duration=100.0)
    >>> bool(np.array_equal(res.y, same.y))
    True
    """
    arrays = [None if v is None else _vector(n, v)
              for n, v in (("t", t), ("r", r), ("d", d), ("d_out", d_out))]
    kw = _scenario(scenario, controller=controller, params=params)
    return Result(_msp.simulate(_plant(plant, delay), arrays[0], arrays[1], arrays[2], arrays[3], **kw))


def step_info(
    t: Any,
    y: Any,
    *,
    yfinal: Optional[float] = None,
    yinit: Optional[float] = None,
    settling_threshold: float = 0.02,
    rise_limits: Tuple[float, float] = (0.1, 0.9),
) -> Dict[str, float]:
    """Step-response characteristics of recorded data, as MATLAB's ``stepinfo(y, t, yfinal, yinit)``
    and ``msp stepinfo``.

    Parameters
    ----------
    t, y : array_like
        Times (strictly increasing) and the response. The step is at ``t = 0`` (data that start
        later: at the first sample); times are measured from it.
    yfinal : float, optional
        The final value; by default the last sample (MATLAB's and python-control's convention).
    yinit : float, optional
        The value before the step; default 0.
    settling_threshold : float, optional
        The settling band as a fraction of the step (MATLAB's ``SettlingTimeThreshold``).
    rise_limits : (float, float), optional
        The rise time's fractions of the step (``RiseTimeLimits``).

    Returns
    -------
    dict
        ``rise_time``, ``settling_time``, ``settling_min``, ``settling_max``, ``overshoot``,
        ``undershoot`` (percent of the step), ``peak``, ``peak_time``: the keys of
        :func:`step`'s ``info``; crossings interpolated linearly between samples, NaN where a
        figure does not exist (a response that never rises).

    Raises
    ------
    ValueError
        Arrays of different lengths, fewer than two samples, non-finite values, times that do
        not increase, or thresholds outside (0, 1).

    Examples
    --------
    >>> t = np.linspace(0.0, 20.0, 20001)
    >>> info = msp.step_info(t, 1.0 - np.exp(-t / 2.0), yfinal=1.0)
    >>> round(info["rise_time"], 4), round(2.0 * float(np.log(9.0)), 4)
    (4.3944, 4.3944)
    """
    arr = [_vector(n, v) for n, v in (("t", t), ("y", y))]
    lo, hi = rise_limits
    return dict(_msp.step_info(arr[0], arr[1], None if yinit is None else float(yinit),
                               None if yfinal is None else float(yfinal), float(settling_threshold),
                               (float(lo), float(hi))))


def tune(
    plant: PlantLike,
    controller: Optional[str] = None,
    params: Optional[Mapping[str, float]] = None,
    *,
    delay: Optional[float] = None,
    uncertainty: Union[None, str, Mapping[str, float]] = None,
    **scenario: Unpack[TuneOptions],
) -> Dict[str, Any]:
    """The tuned controller as ``msp tune --json`` prints it.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    controller : str, optional
        The scheme; by default chosen by the plant's kind.
    params : dict, optional
        Overrides of tuned parameters or design values, as :func:`run`.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.
    uncertainty : str or dict, optional
        ``"delay=20%,tau=-20%"`` or a dict: adds Eq. 17's ``robust_peak`` on the exact discrete loop.
    **scenario
        The keywords of :class:`TuneOptions`, as :func:`run` takes them (``ts``: the period of
        the margins and of Eq. 17).

    Returns
    -------
    dict
        ``{"plant", "inner_plant", "controller": {"name", "params"}, "source", "chosen",
        "robustness": {"gm", "pm", "dm", "ms", ...}, "robust_peak", "robustly_stable",
        "warnings"}``: ``robustness`` holds the single loop's margins (sampled view), ``warnings``
        what they warn of (Ms above 2, a delay margin below 20 % of the dead time) with the λ or
        scheme that does better.

    Raises
    ------
    ValueError
        As :func:`run`.

    A multivariable plant (MATLAB's ``"[g11, g12; g21, g22]"``, or a nested list of expressions)
    gives ``msp tune``'s matrix report instead: ``{"plant", "rga", "pairing", "niederlinski",
    "scheme", "ts", "rule", "f", "loops": [{"kp", "ti", ...}, ...], "decoupler", "alone",
    "stability", "decoupler_stability", "lcm"}`` for ``controller`` ``"pi"`` (the BLT tuning
    of decentralized PI loops, Luyben 1986; the default), ``"smith"`` or ``"decoupled"``,
    at the period ``ts``.

    Examples
    --------
    >>> t = msp.tune("0.2/s*e^-7.4s")
    >>> t["controller"]["name"], round(t["controller"]["params"]["kp"], 4), t["chosen"]
    ('karan-dey', 5.4054, ['lambda'])
    """
    matrix = _matrix(plant)
    if matrix is not None:
        if params or delay is not None or uncertainty is not None or set(scenario) - {"ts", "rule"}:
            raise ValueError("a matrix plant's tuning takes controller, rule and ts only")
        return _msp.tune_matrix(matrix, controller, scenario.get("rule"), scenario.get("ts"))
    unc: Any = dict(uncertainty) if isinstance(uncertainty, Mapping) else uncertainty
    kw = _scenario(scenario, controller=controller, params=params)
    return _msp.tune(_plant(plant, delay), uncertainty=unc, **kw)


def _entry(e: Any) -> str:
    """A matrix entry as the plant grammar writes it: an expression as given, a number, or an
    :class:`Plant`, a python-control transfer function or a ``(tf, delay)`` pair with every
    coefficient written exactly (Python's shortest round-trip ``repr``)."""
    if isinstance(e, str):
        return e
    if isinstance(e, (int, float)) and not isinstance(e, bool):
        return repr(float(e))
    p = _plant(e)
    if isinstance(p, str):
        return p

    def poly(c: Sequence[float]) -> str:
        n = len(c) - 1
        return " + ".join(f"({float(x)!r})*s^{n - i}" for i, x in enumerate(c))

    text = f"({poly(p.num)})/({poly(p.den)})"
    return f"{text}*e^(-({float(p.delay)!r})*s)" if p.delay > 0 else text


def _matrix(plant: Any) -> Optional[str]:
    """A multivariable plant as MATLAB's matrix string: ``"[g11, g12; g21, g22]"`` as given,
    or a nested list of entries (expressions, ``0`` for a channel without coupling,
    :class:`Plant`, python-control transfer functions, ``(tf, delay)`` pairs); ``None`` else."""
    if isinstance(plant, str):
        return plant if plant.lstrip().startswith("[") else None
    if (isinstance(plant, (list, tuple)) and plant
            and all(isinstance(r, (list, tuple)) and not _is_pair(r) for r in plant)):
        return "[" + "; ".join(", ".join(_entry(e) for e in row) for row in plant) + "]"
    return None


def _is_pair(r: Any) -> bool:
    """A ``(tf, delay)`` pair rather than a matrix row."""
    return (isinstance(r, tuple) and len(r) == 2 and isinstance(r[1], (int, float))
            and hasattr(r[0], "num"))


def tune_rules(
    plant: PlantLike,
    *,
    delay: Optional[float] = None,
    **scenario: Unpack[TuneOptions],
) -> List[Dict[str, Any]]:
    """Every PI/PID tuning rule applied to ``plant``, as ``msp tune --rules``.

    The rules are IMC-PID, SIMC, AMIGO (Åström & Hägglund (2004), with its set-point
    weight ``b``) and the ultimate-cycle rules of :func:`controllers`' ``pid``/``pi``.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.
    **scenario
        The keywords of :class:`TuneOptions` (``lambda_`` for the λ rules, ``ts``).

    Returns
    -------
    list of dict
        A row per rule: ``{"rule", "controller"}`` (``"pi"`` or ``"pid"``), ``"tuning"`` (the
        controller's ``name``, ``params`` and ``tuning`` with ``b`` and ``c``), ``"stable"``,
        ``"robustness"`` (``gm``, ``pm``, ``dm``, ``ms``, ... of the loop) and ``"error"`` (why a
        rule gives no controller for this plant, else ``None``).

    Examples
    --------
    >>> rows = msp.tune_rules("2*e^-3s/(4s+1)")
    >>> amigo = next(r for r in rows if r["rule"] == "amigo" and r["controller"] == "pid")
    >>> round(amigo["robustness"]["ms"], 2), amigo["tuning"]["tuning"]["b"]
    (1.44, 0.0)
    """
    return list(_msp.tune_rules(_plant(plant, delay), **_scenario(scenario)))
