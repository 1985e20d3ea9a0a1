"""msp: control of processes with long dead time.

Smith predictors and their modifications, PID tuning, and an exact
sampled-data simulator, with numpy arrays out::

    import msp
    res = msp.run("0.2/s*e^-7.4s")
    res.metrics["rise_time"], res.controller["params"]["kp"]
    fig = res.plot()
"""

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
from ._analysis import (
    _matrix,
    autotune,
    identify,
    margins,
    simulate,
    step,
    step_info,
    sweep,
    tradeoff,
    tune,
    tune_rules,
)
from ._schemes import (
    _SCHEME_CLASSES,
    AstromHangLim,
    DisturbanceEstimator,
    FilteredSmith,
    FilteredSmithUnstable,
    Fspcc,
    Gpcc,
    Huang,
    KaranDey,
    KayaAtherton,
    KayaCascade,
    MatausekMicic,
    PidLoop,
    PiLoop,
    SmithPredictor,
    Uma,
    WatanabeIto,
    _check_classes,
)


def _loop_list(v: Any) -> List[str]:
    if v is None:
        return []
    return [v] if isinstance(v, str) else [str(x) for x in v]


def _run_matrix(matrix: str, controller: Optional[str], params: Any, delay: Any,
                scenario: Mapping[str, Any]) -> MimoResult:
    if params or delay is not None:
        raise ValueError("a matrix plant's run takes no params or delay yet")
    unknown = sorted(set(scenario) - set(MATRIX_KEYWORDS))
    if unknown:
        raise ValueError(f"a matrix plant does not take {', '.join(unknown)} yet: its keywords are "
                         f"{', '.join(MATRIX_KEYWORDS)}")
    dp = scenario.get("disturbance_plant")
    if dp is not None and not isinstance(dp, str):
        dp = "[" + "; ".join(str(e) for e in dp) + "]"
    return MimoResult(_msp.run_matrix(
        matrix, controller, scenario.get("rule"), scenario.get("ts"), scenario.get("duration"),
        _loop_list(scenario.get("loop_setpoint")), _loop_list(scenario.get("loop_disturbance")),
        dp, _loop_list(scenario.get("disturbance_step")),
        _loop_list(scenario.get("channel_dead_time")), _loop_list(scenario.get("loop_event")),
        float(scenario.get("noise") or 0.0), int(scenario.get("seed") or 0),
        None if scenario.get("actuator") is None else tuple(scenario["actuator"])))


__all__ = [
    "AstromHangLim",
    "MATRIX_KEYWORDS",
    "MimoResult",
    "autotune",
    "Controller",
    "DisturbanceEstimator",
    "Estimator",
    "FilteredSmith",
    "FilteredSmithUnstable",
    "Fspcc",
    "Gpcc",
    "Huang",
    "KaranDey",
    "KayaAtherton",
    "KayaCascade",
    "Margins",
    "MatausekMicic",
    "Pid",
    "PidOptions",
    "PiLoop",
    "PidLoop",
    "Plant",
    "RelayOptions",
    "Result",
    "RunOptions",
    "DesignOptions",
    "TuneOptions",
    "SmithPredictor",
    "Uma",
    "WatanabeIto",
    "__version__",
    "compare",
    "controllers",
    "identify",
    "margins",
    "parse_plant",
    "run",
    "simulate",
    "step",
    "Step",
    "step_info",
    "sweep",
    "tradeoff",
    "Tradeoff",
    "tune",
    "tune_rules",
]


def run(
    plant: PlantLike,
    controller: Optional[str] = None,
    params: Optional[Mapping[str, float]] = None,
    *,
    delay: Optional[float] = None,
    **scenario: Unpack[RunOptions],
) -> Result:
    """Tune a controller for ``plant``, simulate the closed loop exactly, return a :class:`Result`.

    The simulation is exact for sampled data (the plant's ZOH equivalent at the controller's
    period, the dead time as samples and a fraction), as ``msp run`` does.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process: an expression (``"0.2/s*e^-7.4s"``), an :class:`Plant`, or a python-control
        transfer function whose dead time is ``delay``.
    controller : str, optional
        A name from :func:`controllers`; by default chosen by the plant's kind, as ``msp run``.
    params : dict, optional
        Overrides of tuned parameters or design values by report name (``{"kp": 0.05}``), as the
        CLI's ``--set``.
    delay : float, optional
        The dead time (s) of a python-control ``plant``.
    **scenario
        The keywords of :class:`RunOptions`, one per field of the scenario:
    model : str, Plant or control.TransferFunction, optional
        The controller's model of the plant (default: the plant itself).
    inner_plant, inner_model : str, Plant or control.TransferFunction, optional
        A cascade process (García et al. (2010) Fig. 1): the secondary process, whose output
        ``y2`` is measured and drives ``plant``, and the controller's model of it; the default
        controller is then ``fspcc``.
    ts : float, optional
        The sample period (s); chosen from the plant when absent.
    duration : float, optional
        The simulated time (s); chosen to cover settling when absent.
    setpoint : float, "V@T" or list of them or of (value, time), optional
        The set-point steps.
    disturbance : "input:V@T", dict or list of them, optional
        Dicts are a scenario file's structured form: ``location`` ("input", the default,
        "output", and "inner" for a cascade's secondary output; the paper's ``d2``/``d1``/``d0``
        are accepted too), ``value``, ``at``, ``shape`` ("step", "ramp", "sine") and ``freq`` (Hz).
    noise : float, optional
        The standard deviation of white measurement noise.
    seed : int, optional
        The noise generator's seed.
    quantization : float, optional
        The measurement's resolution (an ADC's step: ``span / 4096`` for 12 bits); the
        controller sees the noisy output rounded to it.
    umin, umax : float, optional
        The actuator's limits.
    lambda_ : float, optional
        The closed-loop time constant of the tuning rule (s).
    rule : str, optional
        A named tuning rule for ``pid``/``pi`` (``"imc"``, ``"simc"``, ``"amigo"``, ``"zn"``, ...).
    target : str, optional
        A design target the tuning's λ is solved for on the exact analysis, as MATLAB's
        ``pidtune`` options: ``"ms=1.4"``, ``"pm=60"`` (degrees), ``"gm=3"`` (or ``"gm=9.5dB"``),
        ``"dm=0.3θ"`` (a fraction of the dead time; ``"dm=2"`` in seconds), ``"wc=0.2"``
        (rad/s). The report's ``controller["target"]`` gives the λ and the figure reached; an
        unreachable target raises ``ValueError`` naming this scheme's range and the schemes
        that reach it. For ``"pi"``/``"pid"``, ``"wc=0.006,pm=60"`` designs the controller at
        the crossover with the phase margin, as ``pidtune(G, 'PI', wc)`` does (``lambda`` is
        then ``None`` and ``pm_achieved`` the sampled loop's).
    substeps : int, optional
        Plant outputs per controller period in the signals (smooth intersample curves).
    float32 : bool, optional
        The controller computes in ``float32`` as firmware does (designed in ``float64``; the
        plant stays exact), as the CLI's ``--float32``.
    max_memory : int, optional
        The memory the run may take in bytes (default 1 GiB), as the CLI's ``--max-memory``.
    events : list of str, optional
        What an operator does, as the CLI's ``--event``: ``"60:manual=0.3"``, ``"60:track=0.3"``,
        ``"120:auto"`` (bumpless), ``"60:dead-time=9"`` (the controller's model;
        ``"60:dead-time=9~0.05"`` moves it there at 0.05 s per s), ``"60:plant-dead-time=9"``,
        ``"60:plant-gain=4"``, ``"60:plant-lag=20"`` (the process changing; ``"60:plant-gain=4~0.01"``
        drifts it there at 0.01 per s, likewise dead time and lag), ``"60:kp=3"`` (the primary PID retuned, bumpless).
    actuator : (float, float), optional
        An actuator outside the controller: the plant receives the output clamped to
        ``(min, max)``; the result gets ``u_applied``.
    reset_feedback : bool, optional
        Feed the value the plant received back to the controller each sample (no windup
        against ``actuator``).
    setpoint_ramp : float, optional
        The controller's set point moves by at most this much per second (the recorded ``r`` is
        the schedule), as the CLI's ``--setpoint-ramp``.
    adapt : bool or dict, optional
        Adaptive dead-time compensation, as the CLI's ``--adapt``: the Smith predictor's FOPDT
        or IPDT model kept right by on-line identification (``msp`` crate's ``adapt``), its
        primary retuned at each change; the signals ``k_hat``, ``tau_hat``, ``theta_hat``
        (the estimate), ``evidence`` (for its dead time over the candidates that cannot be
        it: small is ambiguous) and ``k_model``, ``tau_model``, ``theta_model`` (the model in
        use).
        A dict sets ``delay=(min, max)`` (s), ``forgetting``, ``excitation``, ``min_change``,
        ``prefilter`` (s), ``dead_zone`` (multiples of the measured noise), ``bound`` (the
        factor of the commissioned gain and lag no estimate applied may pass, default 4),
        ``apply`` (False: a monitor only), ``alarm`` (the model error
        that raises the alarm, default 0.1) and ``background_design`` (a scheme rebuilt for
        each model designed between samples, as a device's background task would: each a
        sample later; per-sample controllers then call ``Controller.design()``).
    monitor : bool, optional
        The model-error monitor, as the CLI's ``--monitor``: the estimator watches the model in
        use and raises an alarm when the process no longer matches it (the signals
        ``mismatch``, the model's error against the process, and ``model_alarm``; the alarms in
        the report's ``adaptation`` log); without ``adapt`` nothing is applied.

    Without ``setpoint``, ``disturbance`` and ``duration`` the run is msp's default scenario: a
    unit set-point step, then a step load at the plant input once the response has settled.

    A multivariable plant (``"[g11, g12; g21, g22]"`` or a nested list of expressions) runs a
    scheme of ``msp run --plant "[…]"`` (``controller``: ``"pi"``, BLT's decentralized PI, the
    default; ``"smith"``, decentralized Smith predictors; ``"decoupled"``, an inverted
    decoupler with a Smith predictor in each loop) and returns a :class:`MimoResult`; its
    keywords are the CLI's flags (:data:`MATRIX_KEYWORDS`): ``ts``, ``duration``,
    ``loop_setpoint=["1:1@0", "2:1@50"]``, ``loop_disturbance=["1:input:0.1@80"]``,
    ``disturbance_plant="[d1; d2]"`` (or a list) with ``disturbance_step=["0.1@20"]``,
    ``channel_dead_time=["1,2=5@100"]``, ``loop_event=["2:50:manual=0.3", "2:80:auto"]``,
    ``noise`` with ``seed`` (every output) and ``actuator=(min, max)`` (every input).

    Returns
    -------
    Result
        The signals as numpy arrays and the run report (metrics, events, robustness...).

    Raises
    ------
    ValueError
        A plant expression that does not parse (with the column), a controller that cannot
        control the plant, a parameter out of range, or a run beyond ``max_memory``.

    Examples
    --------
    >>> res = msp.run("0.2/s*e^-7.4s")
    >>> res.controller["name"]
    'karan-dey'
    >>> [e["kind"] for e in res.events]
    ['setpoint', 'disturbance']
    >>> round(msp.run("0.2/s*e^-7.4s", setpoint=1.0).metrics["rise_time"], 2)
    2.02
    """
    matrix = _matrix(plant)
    if matrix is not None:
        return _run_matrix(matrix, controller, params, delay, scenario)  # type: ignore[return-value]
    raw = _msp.run(_plant(plant, delay), **_scenario(scenario, controller=controller, params=params))
    return Result(raw)


def compare(
    plant: PlantLike,
    controllers: Sequence[str],
    *,
    params: Optional[Mapping[str, float]] = None,
    perturb: Union[None, str, Mapping[str, float]] = None,
    delay: Optional[float] = None,
    **scenario: Unpack[RunOptions],
) -> List[Result]:
    """Run each controller on the same scenario, as ``msp compare`` does.

    Parameters
    ----------
    plant : str, Plant or control.TransferFunction
        The process, as :func:`run` takes it.
    controllers : list of str
        The schemes, by name (:func:`controllers`).
    params : dict, optional
        Overrides, as :func:`run`; keys ``"scheme.name"`` apply to one scheme only.
    perturb : str or dict, optional
        A change of the plant that every controller meets with the nominal model:
        ``"gain=+10%,delay=+10%"`` or ``{"gain": 0.1, "delay": 0.1, "tau": 0.0}``
        (``inner_gain``, ``inner_delay``, ``inner_tau`` for a cascade's secondary).
    delay : float, optional
        The dead time (s) of a python-control ``plant``.
    **scenario
        The keywords of :class:`RunOptions`, as :func:`run` takes them.

    Returns
    -------
    list of Result
        One per controller, in order, all at one common sample period (a matrix plant: one
        :class:`MimoResult` per scheme, as :func:`run` gives it).

    Raises
    ------
    ValueError
        As :func:`run`, and for an unknown controller or perturbation.

    Examples
    --------
    >>> runs = msp.compare("0.2/s*e^-7.4s", ["karan-dey", "pid"], perturb="delay=+10%", setpoint=1.0)
    >>> [r.controller["name"] for r in runs]
    ['karan-dey', 'pid']
    """
    matrix = _matrix(plant)
    if matrix is not None:
        if perturb is not None:
            raise ValueError("a matrix plant's compare takes no perturb yet")
        return [_run_matrix(matrix, c, params, delay, scenario)  # type: ignore[misc]
                for c in controllers]
    raw = _msp.compare(_plant(plant, delay), list(controllers),
                       perturb=dict(perturb) if isinstance(perturb, Mapping) else perturb,
                       **_scenario(scenario, params=params))
    return [Result(r) for r in raw]


def __dir__() -> List[str]:
    """The public API only (``__all__``), not the names the module uses inside."""
    return sorted(__all__)
