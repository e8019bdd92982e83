"""The thesis's three position controllers (SPEC §6), behind one protocol.

``make_controller(name, ...)`` builds one by name; a new controller is one new
module plus one line in :data:`CONTROLLERS`.
"""

from __future__ import annotations

from controllers.feedforward import NominalModel
from controllers.ffpva import FeedForwardPVA, FeedForwardPVAGains
from controllers.pva import PVA, PVAGains
from controllers.smc import SlidingMode, SlidingModeGains
from twin.exceptions import InvalidScenario

CONTROLLERS = {"pva": PVA, "ffpva": FeedForwardPVA, "smc": SlidingMode}
GAIN_SETS = ("simulation", "experiment")


def make_controller(name: str, *, nominal: NominalModel, gain_set: str, tick: float):
    """A controller by name with the thesis's simulation or experiment gains.

    Its PWM-rate part runs once per ``nominal.valves.pwm_period``."""
    if name not in CONTROLLERS:
        raise InvalidScenario(f"unknown controller {name!r}: choose one of {', '.join(CONTROLLERS)}")
    if gain_set not in GAIN_SETS:
        raise InvalidScenario(f"unknown gain set {gain_set!r}: choose one of {', '.join(GAIN_SETS)}")
    return CONTROLLERS[name].thesis(nominal=nominal, gain_set=gain_set, tick=tick)


__all__ = ["CONTROLLERS", "GAIN_SETS", "NominalModel", "make_controller", "PVA", "PVAGains",
           "FeedForwardPVA", "FeedForwardPVAGains", "SlidingMode", "SlidingModeGains"]
