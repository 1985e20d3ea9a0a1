from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt
from typing_extensions import disjoint_base

__all__ = ["Controller", "Pid", "Plant", "DESIGN_KEYWORDS", "SCENARIO_FIELDS", "SCENARIO_KEYWORDS", "TUNE_KEYWORDS", "__version__", "autotune", "compare", "controllers", "identify", "margins", "parse_plant", "run", "simulate", "step", "step_info", "sweep", "tune", "tune_rules"]
__version__: str
SCENARIO_FIELDS: List[str]
SCENARIO_KEYWORDS: List[str]
DESIGN_KEYWORDS: List[str]
TUNE_KEYWORDS: List[str]

@final
class Plant:
    def __new__(cls, num: Sequence[float], den: Sequence[float], delay: float = 0.0) -> "Plant": ...
    @property
    def num(self) -> List[float]: ...
    @property
    def den(self) -> List[float]: ...
    @property
    def delay(self) -> float: ...
    @property
    def kind(self) -> str: ...
    @property
    def order(self) -> int: ...
    def __eq__(self, value: object, /) -> bool: ...

def parse_plant(expr: str) -> Plant: ...
def run(plant: Union[str, Plant], **scenario: Any) -> Dict[str, Any]: ...
def compare(
    plant: Union[str, Plant], controllers: Sequence[str], *, perturb: Any = None, **scenario: Any
) -> List[Dict[str, Any]]: ...
def tune(plant: Union[str, Plant], *, uncertainty: Any = None, **scenario: Any) -> Dict[str, Any]: ...
def tune_rules(plant: Union[str, Plant], **scenario: Any) -> List[Dict[str, Any]]: ...
def simulate(
    plant: Union[str, Plant], t: Any, r: Any, d: Any, d_out: Any, **scenario: Any
) -> Dict[str, Any]: ...
def step_info(
    t: Any, y: Any, yinit: Optional[float], yfinal: Optional[float], settling_threshold: float,
    rise_limits: Tuple[float, float],
) -> Dict[str, Any]: ...
def controllers() -> List[Dict[str, Any]]: ...
def autotune(
    plant: Union[str, Plant],
    *,
    relay_amplitude: float = 1.0,
    hysteresis: Optional[float] = None,
    bias: Optional[float] = None,
    noise: float = 0.0,
    seed: int = 0,
    model: Optional[str] = None,
    controller: Optional[str] = None,
    ts: Optional[float] = None,
    band: float = ...,
    duration: Optional[float] = None,
) -> Dict[str, Any]: ...
def step(
    plant: Union[str, Plant], *, ts: Optional[float] = None, duration: Optional[float] = None
) -> Dict[str, Any]: ...
def identify(
    t: npt.NDArray[np.float64], u: npt.NDArray[np.float64], y: npt.NDArray[np.float64], model: str = "fopdt"
) -> Dict[str, Any]: ...
def margins(
    plant: Union[str, Plant],
    *,
    discrete: bool = False,
    continuous: bool = False,
    uncertainty: Any = None,
    **scenario: Any,
) -> Dict[str, Any]: ...
def sweep(
    plant: Union[str, Plant],
    *,
    gain: Tuple[float, float] = ...,
    delay: Tuple[float, float] = ...,
    tau: Tuple[float, float] = ...,
    grid: int = 11,
    samples: int = 0,
    seed: int = 1,
    shard: Tuple[int, int] = ...,
    **scenario: Any,
) -> Dict[str, Any]: ...

@disjoint_base
class Controller:
    def __new__(
        cls,
        name: str,
        plant: Union[str, Plant],
        ts: float,
        params: Optional[Mapping[str, float]] = None,
        *,
        inner_plant: Union[str, Plant, None] = None,
        umin: float = ...,
        umax: float = ...,
        lambda_: Optional[float] = None,
        rule: Optional[str] = None,
        max_dead_time: float = 0.0,
    ) -> "Controller": ...
    def update(
        self, r: float, y: float, y2: Optional[float] = None, u_applied: Optional[float] = None
    ) -> float: ...
    def manual(self, u: float) -> None: ...
    def track(self, u: float) -> None: ...
    def auto(self) -> None: ...
    @property
    def mode(self) -> str: ...
    def set_dead_time(self, theta: float) -> None: ...
    def retune(self, **params: float) -> None: ...
    def ramp_dead_time(self, theta: float, rate: float) -> None: ...
    def set_setpoint_ramp(self, rate: float) -> None: ...
    @property
    def dead_time(self) -> Optional[float]: ...
    def update_many(
        self,
        r: npt.NDArray[np.float64],
        y: npt.NDArray[np.float64],
        y2: Optional[npt.NDArray[np.float64]] = None,
    ) -> npt.NDArray[np.float64]: ...
    def reset(self) -> None: ...
    @property
    def is_cascade(self) -> bool: ...
    def signal(self, name: str) -> float: ...
    @property
    def name(self) -> str: ...
    @property
    def ts(self) -> float: ...
    @property
    def params(self) -> Dict[str, float]: ...
    @property
    def signal_names(self) -> List[str]: ...
    @property
    def signals(self) -> Dict[str, float]: ...
    @property
    def fault(self) -> bool: ...

@final
class Pid:
    def __new__(
        cls,
        kp: float,
        ti: float = ...,
        td: float = 0.0,
        ts: float = 1.0,
        *,
        n: float = 10.0,
        b: float = 1.0,
        c: float = 1.0,
        umin: float = ...,
        umax: float = ...,
        anti_windup: str = "back-calculation",
        tt: Optional[float] = None,
        rate_limit: float = ...,
    ) -> "Pid": ...
    @staticmethod
    def parallel(
        kp: float,
        ki: float = 0.0,
        kd: float = 0.0,
        ts: float = 1.0,
        *,
        tf: Optional[float] = None,
        b: float = 1.0,
        c: float = 1.0,
        umin: float = ...,
        umax: float = ...,
        anti_windup: str = "back-calculation",
        tt: Optional[float] = None,
        rate_limit: float = ...,
    ) -> "Pid": ...
    def preset(self, u: float) -> None: ...
    def update(self, r: float, y: float) -> float: ...
    def update_tracking(self, r: float, y: float, u_actual: float) -> float: ...
    def update_many(self, r: npt.NDArray[np.float64], y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def reset(self) -> None: ...
    def set_manual(self) -> None: ...
    def set_manual_output(self, u: float) -> None: ...
    def set_auto(self) -> None: ...
    @property
    def p(self) -> float: ...
    @property
    def i(self) -> float: ...
    @property
    def d(self) -> float: ...
    @property
    def output(self) -> float: ...
    @property
    def fault(self) -> bool: ...
    @property
    def params(self) -> Dict[str, float]: ...
