"""The step order of one tick, written once: :class:`Ticker`.

Every loop that drives the joint advances it through a ``Ticker``: the batched
loop (:func:`twin.sim.simulation.simulate`, ``twin run`` and every sweep), the
dm_control environment (:mod:`twin.envs.environment`) and the live viewer
(:mod:`twin.envs.live`). Per 1 ms tick k (integer ticks, never a float clock),
for all n scenarios at once (arrays have a leading scenario axis)::

    MuJoCo state ──► sensors ──► observer ──► command ──► valves ──► hydraulics ──► physics step
       (qpos)       (Hall y,     (v_hat,      (controllers  (delays,   (implicit rack   (the caller's:
                     pressures,   a_hat)       if due, or    dead zone, step, friction,   Batch, mj_step,
                     noise)                    the agent's)  PWM)       forces -> ctrl)  dm_control)
       └──────────────── sense() ──────────┘  └ tick(command) ┘ └─────────────── act(duty) ──────────────┘

``sense()`` samples the sensors once per tick (the observer has state) and
keeps the measurement, so an agent can observe before it acts and the tick
then uses that same measurement; ``act(duty)`` senses first if nobody has, so
the order cannot be broken. The hydraulic "callback" runs here, not as a
process-global ``mjcb_control``, so two twins in one process cannot interfere;
it writes only ``ctrl``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from twin.sim.control import Measurement
from twin.sim.plant_state import PlantState


class Ticker:
    """Advances ``plant`` and the MuJoCo state behind the array views tick by tick.

    ``qpos`` (n, nq), ``qvel`` (n, nv), ``ctrl`` (n, nu), ``qfrc_passive`` and ``qfrc_bias`` (n, nv)
    are views of the simulations' state (for one model: ``data.qpos[None, :]`` ...); ``step(k)``
    advances the physics by one step at tick k.
    """

    def __init__(self, plant: PlantState, *, qpos: np.ndarray, qvel: np.ndarray, ctrl: np.ndarray,
                 qfrc_passive: np.ndarray, qfrc_bias: np.ndarray, rack_dof: int, step: Callable[[int], None]):
        self.plant = plant
        self.qpos, self.qvel, self.ctrl = qpos, qvel, ctrl
        self.qfrc_passive, self.qfrc_bias = qfrc_passive, qfrc_bias
        self.rack_dof = rack_dof
        self.step = step
        self.k = 0
        self._sensed: int | None = None  # the tick the kept measurement belongs to
        self.measurement: Measurement | None = None  # of the tick last sensed (after act: the tick just done)
        self.position = np.zeros(0)  # m, true rack A position (n,) read when tick k was sensed
        self.velocity = np.zeros(0)  # m/s

    def restart(self, k: int = 0) -> None:
        """Count ticks from ``k`` again (the live viewer's noise blocks); nothing is kept."""
        self.k, self._sensed, self.measurement = k, None, None

    def sense(self) -> Measurement:
        """The sensors and observer at tick k: sampled on the first call at k, kept for the others."""
        if self._sensed != self.k:
            self.position = self.qpos[:, self.rack_dof].copy()
            self.velocity = self.qvel[:, self.rack_dof].copy()
            self.measurement = self.plant.sense(self.k, self.position)
            self._sensed = self.k
        return self.measurement

    def act(self, duty: np.ndarray) -> None:
        """Valves and hydraulics with ``duty`` (%, (n,)) in force, the forces into ``ctrl``, the
        physics step; then tick k + 1."""
        self.sense()
        external = self.plant.external_force(self.qfrc_passive, self.qfrc_bias)
        self.ctrl[:, 0], self.ctrl[:, 1] = self.plant.actuate(self.k, duty, self.position, self.velocity, external)
        self.step(self.k)
        self.k += 1

    def tick(self, command: Callable[[int, Measurement], np.ndarray]) -> np.ndarray:
        """One whole tick: sense, ``duty = command(k, measurement)``, act. Returns the duty."""
        duty = command(self.k, self.sense())
        self.act(duty)
        return duty
