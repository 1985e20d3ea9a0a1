"""The keyword options of the module's functions, each read in one place by the
compiled module."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any, Dict, List, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np

from . import _msp
from ._msp import Controller, Estimator, Pid, Plant, __version__, controllers, parse_plant
from ._common import PlantLike

if sys.version_info >= (3, 11):
    from typing import Unpack
elif TYPE_CHECKING:
    from typing_extensions import Unpack


# (every ancestor and ``TypedDict`` are named as bases of the derived options: before 3.12 a
# TypedDict's ``__mro__`` omits its TypedDict bases, and the documentation tool reads it)
class TuneOptions(TypedDict, total=False):
    """The scenario keywords a tuning reads (:func:`tune`, and every study function): the
    fields of the library's ``Scenario`` under their Python names, checked against it by the
    tests. Each is documented at :func:`run`."""

    inner_plant: PlantLike
    ts: float
    lambda_: float
    rule: str
    target: str


class DesignOptions(TuneOptions, TypedDict, total=False):
    """The scenario keywords of a designed loop (:func:`margins`, :func:`sweep`): the tuning's,
    the models, the precision and the memory."""

    model: PlantLike
    inner_model: PlantLike
    float32: bool
    max_memory: int


class RunOptions(DesignOptions, TuneOptions, TypedDict, total=False):
    """The scenario keywords of a run (:func:`run`, :func:`compare`): the design's, the time
    line, the actuator and the operator."""

    duration: float
    setpoint: Union[float, str, Sequence[Union[float, str, Tuple[float, float]]]]
    disturbance: Union[str, Mapping[str, Any], Sequence[Union[str, Mapping[str, Any]]]]
    noise: float
    seed: int
    quantization: float
    umin: float
    umax: float
    substeps: int
    events: Union[str, Sequence[str]]
    actuator: Tuple[float, float]
    reset_feedback: bool
    setpoint_ramp: float
    adapt: Union[bool, Dict[str, Any]]
    monitor: bool
    loop_setpoint: Union[str, Sequence[str]]
    loop_disturbance: Union[str, Sequence[str]]
    disturbance_plant: Union[str, Sequence[Any]]
    disturbance_step: Union[str, Sequence[str]]
    channel_dead_time: Union[str, Sequence[str]]
    loop_event: Union[str, Sequence[str]]


#: The keywords of a matrix plant's run (the CLI's flags of the same names).
MATRIX_KEYWORDS = (
    "rule",
    "ts",
    "duration",
    "loop_setpoint",
    "loop_disturbance",
    "disturbance_plant",
    "disturbance_step",
    "channel_dead_time",
    "loop_event",
    "noise",
    "seed",
    "actuator",
)


class PidOptions(TypedDict, total=False):
    """The keywords both forms of :class:`Pid` take, read in one place by the compiled
    module (an unknown one is refused by name): the set-point weights ``b``, ``c`` (1), the
    limits ``umin``, ``umax`` (none), ``anti_windup`` (``"back-calculation"``), its tracking
    time ``tt`` (the form's default) and ``rate_limit`` (none). Each is documented at
    :class:`Pid`."""

    b: float
    c: float
    umin: float
    umax: float
    anti_windup: str
    tt: Optional[float]
    rate_limit: float


class RelayOptions(TypedDict, total=False):
    """The keywords of :func:`autotune` (each documented there), as the compiled module reads
    them (checked against it by the tests)."""

    relay_amplitude: float
    hysteresis: float
    bias: float
    noise: float
    seed: int
    model: str
    controller: str
    ts: float
    band: float
    duration: float
