"""One run of the joint: what to simulate, checked on construction."""

from __future__ import annotations

import dataclasses
import math

from twin.exceptions import InvalidScenario
from twin.model import MAX_PAYLOAD, Orientation
from twin.plants import Plant, plant

CONTROLLER_NAMES = ("pva", "ffpva", "smc")
TRAJECTORY_NUMBERS = (1, 2, 3, 4)


@dataclasses.dataclass(frozen=True)
class Scenario:
    controller: str  # "pva", "ffpva" or "smc"
    trajectory: int  # 1..4
    payload: float = 0.0  # kg at the link tip
    orientation: Orientation = Orientation.HORIZONTAL
    plant: str | Plant = "thesis"  # a preset name, or a Plant for what-ifs and tests
    seed: int = 0
    noise: bool = True  # the thesis's sensor noise (§5)
    supply_pressure: float | None = None  # Pa gauge; None: the plant's

    def __post_init__(self) -> None:
        if self.controller not in CONTROLLER_NAMES:
            raise InvalidScenario(f"unknown controller {self.controller!r}: choose one of {', '.join(CONTROLLER_NAMES)}")
        if self.trajectory not in TRAJECTORY_NUMBERS:
            raise InvalidScenario(f"unknown trajectory {self.trajectory!r}: choose 1, 2, 3 or 4")
        if not isinstance(self.payload, (int, float)) or not math.isfinite(self.payload) or not 0 <= self.payload <= MAX_PAYLOAD:
            raise InvalidScenario(f"payload must be between 0 and {MAX_PAYLOAD * 1e3:g} g, got {self.payload!r} kg")
        if not isinstance(self.orientation, Orientation):
            raise InvalidScenario(f"orientation must be an Orientation, got {self.orientation!r}")
        preset = self.preset
        if not isinstance(self.seed, int) or self.seed < 0:
            raise InvalidScenario(f"seed must be a non-negative integer, got {self.seed!r}")
        if self.supply_pressure is not None:
            rated = preset.params.cylinder.rated_pressure
            if not math.isfinite(self.supply_pressure) or not 0 < self.supply_pressure <= rated:
                raise InvalidScenario(
                    f"supply pressure must be in (0, {rated / 1e3:g}] kPa (cylinder rating), "
                    f"got {self.supply_pressure / 1e3:g} kPa")

    @property
    def preset(self) -> Plant:
        return self.plant if isinstance(self.plant, Plant) else plant(self.plant)

    @property
    def plant_name(self) -> str:
        return self.preset.name

    @property
    def supply(self) -> float:
        """Supply pressure in Pa."""
        if self.supply_pressure is not None:
            return self.supply_pressure
        return self.preset.params.supply.pressure
