"""One run of the joint: what to simulate, checked on construction."""

from __future__ import annotations

import dataclasses
import math
import numbers

import numpy as np

from twin.exceptions import InvalidScenario
from twin.physics.model import PAYLOAD_RANGE, Orientation, payload_allowed
from twin.plants import Plant, plant

CONTROLLER_NAMES = ("pva", "ffpva", "smc")
CONTROLLER_LABELS = {"pva": "PVA + DZC", "ffpva": "FF + PVA", "smc": "sliding mode"}  # for tables and plots
MODEL_BASED_CONTROLLERS = ("ffpva", "smc")  # the two with the feed-forward model (§6)
TRAJECTORY_NUMBERS = (1, 2, 3, 4)
MAX_SEED = 2**63 - 1  # the largest noise seed a run's results can be stored with (SQLite's INTEGER)


def _shown(value, scale: float, unit: str) -> str:
    """``value`` for an error message, in ``unit`` (``value * scale``, ten digits: a value just past a bound
    does not read as the bound); text, a truth value or an int past a float's range as given, shortened."""
    try:
        if not isinstance(value, bool | np.bool_):
            return f"{value * scale:.10g} {unit}"
    except (TypeError, OverflowError):
        pass
    given = repr(value)
    return given if len(given) <= 24 else given[:20] + "..."


def _finite(value) -> bool:
    """A finite real number, not a truth value (True == 1) nor text; an int past a float's range is not finite."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # 10**400
        return False


@dataclasses.dataclass(frozen=True)
class Scenario:
    controller: str | None  # "pva", "ffpva" or "smc"; None where the caller brings its own (open loop, lift)
    trajectory: int  # 1..4
    payload: float = 0.0  # kg at the link tip
    orientation: Orientation = Orientation.HORIZONTAL
    plant: str | Plant = "thesis"  # a preset name, or a Plant for what-ifs and tests
    seed: int = 0
    noise: bool = True  # the thesis's sensor noise (§5)
    supply_pressure: float | None = None  # Pa gauge; None: the plant's
    pwm_period: float | None = None  # s; None: the plant's (16 ms); a whole number of ticks

    def __post_init__(self) -> None:
        if self.controller is not None and self.controller not in CONTROLLER_NAMES:
            raise InvalidScenario(f"unknown controller {self.controller!r}: choose one of {', '.join(CONTROLLER_NAMES)}")
        if isinstance(self.trajectory, bool) or not isinstance(self.trajectory, numbers.Integral) \
                or self.trajectory not in TRAJECTORY_NUMBERS:  # True == 1 and 1.0 == 1: not trajectories
            raise InvalidScenario(f"unknown trajectory {self.trajectory!r}: choose 1, 2, 3 or 4")
        if not _finite(self.payload) or not payload_allowed(self.payload):
            raise InvalidScenario(f"payload must be {PAYLOAD_RANGE}, got {_shown(self.payload, 1e3, 'g')}")
        if not isinstance(self.orientation, Orientation):
            raise InvalidScenario(f"orientation must be an Orientation, got {self.orientation!r}")
        if self.pwm_period is not None:
            base = self.plant if isinstance(self.plant, Plant) else plant(self.plant)
            ticks = self.pwm_period / base.timestep if _finite(self.pwm_period) else math.nan
            if not ticks > 0 or abs(ticks - round(ticks)) > 1e-9 or not 4 <= round(ticks) <= 100:
                raise InvalidScenario(f"PWM period must be a whole number of {base.timestep * 1e3:g} ms ticks "
                                      f"between 4 and 100 ticks, got {_shown(self.pwm_period, 1e3, 'ms')}")
        preset = self.preset
        if not isinstance(self.seed, numbers.Integral) or isinstance(self.seed, bool) or not 0 <= self.seed <= MAX_SEED:
            raise InvalidScenario(f"seed must be an integer from 0 to 2^63 - 1, got {self.seed!r}")
        if not isinstance(self.noise, bool | np.bool_):  # "off" is truthy: it would run with the noise on
            raise InvalidScenario(f"noise must be True or False, got {self.noise!r}")
        object.__setattr__(self, "noise", bool(self.noise))  # NumPy's True is no JSON
        if self.supply_pressure is not None:
            rated = preset.params.cylinder.rated_pressure
            if not _finite(self.supply_pressure) or not 0 < self.supply_pressure <= rated:
                raise InvalidScenario(f"supply pressure must be in (0, {rated / 1e3:g}] kPa (cylinder rating), "
                                      f"got {_shown(self.supply_pressure, 1e-3, 'kPa')}")

    @property
    def preset(self) -> Plant:
        """The plant this scenario runs, with its PWM period applied."""
        base = self.plant if isinstance(self.plant, Plant) else plant(self.plant)
        if self.pwm_period is None or self.pwm_period == base.params.valves.pwm_period:
            return base
        valves = dataclasses.replace(base.params.valves, pwm_period=self.pwm_period)
        return dataclasses.replace(base, params=dataclasses.replace(base.params, valves=valves))

    @property
    def plant_name(self) -> str:
        return self.preset.name

    @property
    def supply(self) -> float:
        """Supply pressure in Pa."""
        if self.supply_pressure is not None:
            return self.supply_pressure
        return self.preset.params.supply.pressure
