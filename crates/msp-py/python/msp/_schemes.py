"""The registry's schemes as per-sample controller classes."""

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


class _Scheme(Controller):
    """A registry scheme as a per-sample controller; internal signals read as attributes."""

    scheme: str = ""

    def __new__(cls, plant: PlantLike, ts: float, params: Optional[Mapping[str, float]] = None, *,
                delay: Optional[float] = None, inner_plant: Optional[PlantLike] = None,
                umin: float = float("-inf"), umax: float = float("inf"),
                lambda_: Optional[float] = None, max_dead_time: float = 0.0,
                adapt: Union[bool, Mapping[str, Any], None] = None) -> "_Scheme":
        ip = _plant(inner_plant) if inner_plant is not None else None
        obj = super().__new__(cls, cls.scheme, _plant(plant, delay), ts,  # type: ignore[arg-type]
                              dict(params) if params else None, inner_plant=ip, umin=umin, umax=umax,
                              lambda_=lambda_, max_dead_time=max_dead_time, adapt=adapt)
        return obj  # type: ignore[return-value]

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        pass

    def __getattr__(self, name: str) -> float:
        """Internal signals (``sp.ym``) and parameters (``sp.kp``, read-only) by name."""
        if name in Controller.signal_names.__get__(self):  # type: ignore[attr-defined]
            return self.signal(name)
        params = Controller.params.__get__(self)  # type: ignore[attr-defined]
        if name in params:
            return float(params[name])
        raise AttributeError(f"{type(self).__name__} has no signal or parameter {name!r}")


class PidLoop(_Scheme):
    """Plain PI/PID feedback tuned for the plant (scheme ``pid``)."""

    scheme = "pid"


class PiLoop(_Scheme):
    """Plain PI feedback tuned for the plant, ``td = 0`` (scheme ``pi``)."""

    scheme = "pi"


class SmithPredictor(_Scheme):
    """The classic Smith predictor with Kaya's tuning (scheme ``smith``)."""

    scheme = "smith"


class FilteredSmith(_Scheme):
    """The Smith predictor with a filter on the model error (scheme ``filtered-smith``)."""

    scheme = "filtered-smith"


class Huang(_Scheme):
    """The Smith predictor with Huang's approximate inverse of dead time (scheme ``huang``)."""

    scheme = "huang"


class WatanabeIto(_Scheme):
    """Watanabe–Ito's predictor for integrating plants (scheme ``watanabe-ito``)."""

    scheme = "watanabe-ito"


class AstromHangLim(_Scheme):
    """Åström–Hang–Lim's predictor for integrating plants (scheme ``astrom-hang-lim``)."""

    scheme = "astrom-hang-lim"


class MatausekMicic(_Scheme):
    """Matausek–Micic's predictor for integrating plants (scheme ``matausek-micic``)."""

    scheme = "matausek-micic"


class KayaAtherton(_Scheme):
    """Kaya–Atherton's PI-PD Smith predictor (scheme ``kaya-atherton``)."""

    scheme = "kaya-atherton"


class KaranDey(_Scheme):
    """The Karan–Dey modified Smith predictor for integrating plants (scheme ``karan-dey``)."""

    scheme = "karan-dey"


class FilteredSmithUnstable(_Scheme):
    """The filtered Smith predictor for unstable, integrating and stable plants (scheme ``fsp``)."""

    scheme = "fsp"


class DisturbanceEstimator(_Scheme):
    """The Smith predictor with a disturbance estimator, cases 1–6 (scheme ``disturbance-estimator``)."""

    scheme = "disturbance-estimator"


class Fspcc(_Scheme):
    """Cascade: the filtered Smith predictor outside an IMC inner loop (scheme ``fspcc``);
    build with ``inner_plant=`` and call ``update(r, y, y2)``."""

    scheme = "fspcc"


class Gpcc(_Scheme):
    """Cascade: the generalized predictor outside an IMC inner loop (scheme ``gpcc``)."""

    scheme = "gpcc"


class Uma(_Scheme):
    """Cascade competitor: Uma et al. 2009 (scheme ``uma``; set ``kpd``, ``kid``, ``kdd``)."""

    scheme = "uma"


class KayaCascade(_Scheme):
    """Cascade competitor: Kaya et al. 2008 (scheme ``kaya-cascade``)."""

    scheme = "kaya-cascade"


_SCHEME_CLASSES = (PidLoop, PiLoop, SmithPredictor, FilteredSmith, Huang, WatanabeIto, AstromHangLim, MatausekMicic,
                   KayaAtherton, KaranDey, DisturbanceEstimator, FilteredSmithUnstable, Fspcc, Gpcc, Uma,
                   KayaCascade)


def _check_classes() -> List[str]:
    """Registry schemes without a class here (kept empty by the test suite)."""
    have = {c.scheme for c in _SCHEME_CLASSES}
    return [c["name"] for c in controllers() if c["name"] not in have]
