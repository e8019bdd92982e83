"""Errors raised by the twin; every one derives from :class:`TwinError`."""


class TwinError(Exception):
    """Base class of every error the twin raises on purpose."""


class InvalidParameter(TwinError, ValueError):
    """A physical parameter is outside its meaningful range."""


class InvalidScenario(TwinError, ValueError):
    """A scenario names an unknown part or holds an out-of-range value."""


class InvalidController(TwinError, ValueError):
    """A controller was configured inconsistently (e.g. a bad update period)."""


class SimulationFailed(TwinError, RuntimeError):
    """MuJoCo raised an error or the state diverged."""


class InvalidAction(TwinError, ValueError):
    """An environment was given an action it cannot apply (not a finite number)."""
