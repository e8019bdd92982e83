"""Model-inverting feed-forward (eqs. 5.3.2 - 5.3.3).

For the desired motion (y_d, v_d, a_d) moving in direction s = sgn(v_d), the
discharge-valve resistance that produces it is

    R4 = [P_ws A - s (M a_d + F_l(y_d, v_d)) - R1 A^2 |v_d|] / (A^2 |v_d|)

and the duty follows by inverting eq. 4.4.2, d = (R4 / 1.8372e14)^(-1/2.1706).
For s > 0 this is eq. 5.3.2 as printed; eq. 5.3.4 as printed drops A and writes
v_d for a_d, so the consistent form above is used (*resolution*). u_FF = 0 when
v_d = 0; when the motion needs more than an open valve (R4 <= R(100 %)) the
duty saturates at 100 %. Moving towards 0 deg (s < 0) uses the other valve
pair, which the model takes as identical (*resolution*: the thesis gives one
R(d) for all four valves).

The nominal model uses the thesis's P_ws = 300 kPa, fixed (feeding back the
measured supply re-injected its oscillations, §6), and the thesis's lumped mass
M = 32.9 g. The multibody train actually weighs 43.5 g referred to the rack
(SPEC §2 note); the difference is M a_d <= 0.5 mN here against P_ws A = 3.8 N.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from twin.physics import friction
from twin.physics.params import NOMINAL_PARAMS, FrictionParams, JointParams, ValveParams


@dataclasses.dataclass(frozen=True)
class NominalModel:
    """The controllers' model of the joint (SI)."""

    supply_pressure: float  # Pa
    mass: float  # kg, referred to the rack
    bore_area: float  # m^2
    valves: ValveParams
    friction: FrictionParams

    @classmethod
    def thesis(cls, params: JointParams = NOMINAL_PARAMS) -> NominalModel:
        return cls(supply_pressure=NOMINAL_PARAMS.supply.pressure, mass=params.masses.thesis_total_mass,
                   bore_area=params.cylinder.bore_area, valves=params.valves, friction=params.friction)


def feedforward_duty(model: NominalModel, position: np.ndarray, velocity: np.ndarray,
                     acceleration: np.ndarray) -> np.ndarray:
    """Signed feed-forward duty in % for the desired motion; arrays (n,)."""
    area = model.bore_area
    direction = np.sign(velocity)
    speed = np.abs(velocity)
    loss = friction.force_loss(model.friction, position, velocity)
    supply_resistance = model.valves.open_resistance
    numerator = (model.supply_pressure * area - direction * (model.mass * acceleration + loss)
                 - supply_resistance * area**2 * speed)
    with np.errstate(divide="ignore", invalid="ignore"):
        resistance = numerator / (area**2 * speed)
        duty = np.where(resistance > model.valves.open_resistance,
                        model.valves.duty_for_resistance(np.maximum(resistance, 1.0)), 100.0)
    return np.where(speed > 0, direction * duty, 0.0)
