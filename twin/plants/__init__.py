"""Named plant presets: a parameter set, a valve model and the gain set the
controllers use on it.

``thesis``
    What the thesis simulated (§8, "friction model assumed perfect"): the
    plant is the controllers' model. Valve: ``averaged`` eq. 4.4.2 at every
    duty above 0 % (the feed-forward inverts eq. 4.4.2 down to small duties,
    so a plant equal to that model has no dead zone), with the 5 ms opening and
    2 ms closing delays. Force loss: eq. 4.5.5 with eq. 4.5.7 only (no separate
    stiction, which eq. 4.5.5 does not contain). Constant 300 kPa supply,
    incompressible water, sealed chambers lock the joint. Simulation gains.
``thesis-deadzone``
    The same with the real valve's 30 % dead zone (§3): commands below 30 %
    leave the valve shut. A sensitivity variant, not a reproduction target.
``thesis-continuous``
    The ``thesis`` plant with a continuous duty (no 1 ms switching tick): what
    an ideal averaged valve would do. A sensitivity variant.
``thesis-pwm``
    The same with the time-resolved PWM valve: each valve shut or fully open,
    16 ms period, delays and 30 % dead zone.
``as-built``
    The joint as built (:mod:`twin.plants.as_built`): the thesis plant plus every
    effect the thesis blames for its experiments' larger errors, as physics, on
    the physical solenoid valve, with the few parameters the thesis does not give
    fitted by ``twin calibrate``.
``as-built~K``
    Member K of the calibration ensemble (``as-built~0`` has the fitted values):
    parameter sets that fit the measurements about as well as the fitted one.
    Not listed; asked for by name, by the studies that report bands.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, MutableMapping

from twin.exceptions import InvalidScenario, TwinError
from twin.plants import as_built
from twin.plants.preset import THESIS_PARAMS, THESIS_PLANTS, Plant

ENSEMBLE_PREFIX = "as-built~"  # as-built~K: member K of the calibration ensemble


class PlantRegistry(MutableMapping):
    """Name -> :class:`Plant`. The ``thesis*`` presets are plain values; ``as-built`` is read from its
    calibration file on first use, so importing the twin (or running a ``thesis`` plant) never reads
    it. ``as-built`` is listed while its file exists; a file that cannot be read is a one-line
    :class:`InvalidScenario` when the preset is asked for (``twin calibrate --install`` remakes it)."""

    def __init__(self, plants: dict[str, Plant], lazy: dict[str, tuple[Callable[[], bool], Callable[[], Plant]]]):
        self._plants = dict(plants)
        self._lazy = dict(lazy)  # name -> (is it there, build it)

    def __getitem__(self, name: str) -> Plant:
        if name not in self._plants and isinstance(name, str) and name.startswith(ENSEMBLE_PREFIX):
            return self._member(name)
        if name not in self._plants:
            if name not in self._lazy or not self._lazy[name][0]():
                raise KeyError(name)
            try:
                self._plants[name] = self._lazy[name][1]()
            except TwinError as error:
                raise InvalidScenario(f"no {name} plant: {error}") from None
        return self._plants[name]

    def _member(self, name: str) -> Plant:
        """``as-built~K``: the calibration ensemble's member K (read from the calibration file, not listed)."""
        index = name[len(ENSEMBLE_PREFIX):]
        if not index.isdigit() or not as_built.CALIBRATION_FILE.exists():
            raise KeyError(name)
        try:
            members = as_built.ensemble_plants()
        except TwinError as error:
            raise InvalidScenario(f"no {name} plant: {error}") from None
        if int(index) >= len(members):
            raise KeyError(name)
        self._plants.update({m.name: m for m in members if m.name not in self._plants})
        return self._plants[name]

    def __contains__(self, name: object) -> bool:
        """Listed: loaded, or a lazy preset whose source is there (not loaded by asking); also an
        ensemble member that the calibration file has."""
        if isinstance(name, str) and name.startswith(ENSEMBLE_PREFIX) and name not in self._plants:
            try:
                self._member(name)
            except (KeyError, InvalidScenario):
                return False
            return True
        return name in self._plants or (name in self._lazy and self._lazy[name][0]())

    def __iter__(self) -> Iterator[str]:
        yield from (name for name in self._plants if not name.startswith(ENSEMBLE_PREFIX))
        yield from (name for name, (present, _) in self._lazy.items() if name not in self._plants and present())

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def __setitem__(self, name: str, preset: Plant) -> None:
        self._plants[name] = preset

    def __delitem__(self, name: str) -> None:
        if name not in self._plants and name not in self._lazy:
            raise KeyError(name)
        self._plants.pop(name, None)
        self._lazy.pop(name, None)

    def __repr__(self) -> str:
        """As a dict of the presets that load (a broken calibration file drops ``as-built``)."""
        loaded = {}
        for name in self:
            try:
                loaded[name] = self[name]
            except InvalidScenario:
                pass
        return repr(loaded)


PLANTS = PlantRegistry(THESIS_PLANTS, {"as-built": (lambda: as_built.CALIBRATION_FILE.exists(), as_built.as_built_plant)})


def plant(name: str) -> Plant:
    if name not in PLANTS:
        raise InvalidScenario(f"unknown plant {name!r}: choose one of {', '.join(PLANTS)}")
    return PLANTS[name]


__all__ = ["ENSEMBLE_PREFIX", "PLANTS", "THESIS_PARAMS", "Plant", "PlantRegistry", "plant"]
