"""What the module's parts share: a plant as the compiled module takes it, and
the scenario's keywords checked once."""

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


PlantLike = Union[str, Plant, Any]


def _scenario(given: Mapping[str, Any], **named: Any) -> Dict[str, Any]:
    """The scenario keywords ``given`` (and those ``named`` in a study function's signature)
    for the compiled module, which reads each once (``_msp.SCENARIO_KEYWORDS``) and refuses
    any other: processes as expressions or ``Plant``, ``None`` left out."""
    out: Dict[str, Any] = {}
    for key, v in {**given, **named}.items():
        if v is None:
            continue
        if key in ("model", "inner_plant", "inner_model"):
            v = _plant(v)
        elif key == "params":
            v = dict(v)
        elif key == "actuator":
            pair = tuple(v)
            if len(pair) != 2:
                raise ValueError(f"actuator: a pair (min, max) has two values, not {len(pair)}")
            v = (float(pair[0]), float(pair[1]))
        out[key] = v
    return out


def _plant(plant: PlantLike, delay: Optional[float] = None) -> Union[str, Plant]:
    """An expression string or Plant; python-control TransferFunction (+ delay) accepted."""
    if isinstance(plant, tuple) and len(plant) == 2:
        plant, delay = plant
    if isinstance(plant, (str, Plant)):
        if delay is not None:
            raise ValueError("give the delay inside the expression, e.g. '1/(s+1)*e^-2s'")
        return plant
    num = getattr(plant, "num", None)
    den = getattr(plant, "den", None)
    if num is None or den is None:
        raise ValueError("a plant is an expression string, an msp.Plant or a python-control TransferFunction")
    try:
        ninputs = getattr(plant, "ninputs", 1)
        noutputs = getattr(plant, "noutputs", 1)
        if ninputs != 1 or noutputs != 1:
            raise ValueError("only SISO transfer functions are supported")
        n = np.atleast_1d(np.asarray(num[0][0], dtype=float))
        d = np.atleast_1d(np.asarray(den[0][0], dtype=float))
    except (TypeError, IndexError):
        n = np.atleast_1d(np.asarray(num, dtype=float))
        d = np.atleast_1d(np.asarray(den, dtype=float))
    if getattr(plant, "dt", 0) not in (0, None):
        raise ValueError("the plant must be a continuous-time transfer function")
    return Plant(list(n), list(d), float(delay or 0.0))
