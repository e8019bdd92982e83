"""``twin study valve``: the thesis's valve test (§4.4.3) replicated on the twin's solenoid valve
(:mod:`twin.physics.solenoid`).

One valve between a set pressure and atmosphere, PWM at 16 ms, for several pressure drops; the
period-averaged flow, once the valve's cycle has settled, against the pressure drop; the inverse
of its slope is the twin's R(d), set beside eq. 4.4.2 at duties 30-100 % in 5 % steps. The valve
held open is R(100 %) by construction (its open conductance); every other duty is an outcome of
the coil, the plunger and the rig's water column. The twin's flow is proportional to the pressure
drop by the model's construction, not as a finding: the valve is a linear resistance scaled by its
opening, the column's inertance is linear too, and no pressure force acts on the plunger, so the flow
fraction a duty gives (simulated once per duty) holds at every drop. So its lines pass through zero;
the thesis's did not (it could not measure flows below 1e-6 m^3/s), and the answer says which of the
twin's points it could not have measured.
"""

from __future__ import annotations

import argparse
import math
import pathlib
from fractions import Fraction

import numpy as np

from twin.experiments.base import Experiment, Outcome
from twin.physics import solenoid
from twin.physics.params import NOMINAL_PARAMS, SolenoidParams, ValveTestRigParams
from viz.figures import plt

DUTIES = tuple(float(d) for d in range(30, 101, 5))  # %
TOLERANCE = 0.15  # the twin's R(d) within 15 % of eq. 4.4.2 from 35 % up
CHECKED_FROM = 35.0  # %
NOMINAL_SOLENOID = SolenoidParams()
NOMINAL_RIG = ValveTestRigParams()


def line_fit(x, y) -> tuple[Fraction, Fraction]:
    """The least-squares line through the points (``x``, ``y``): its slope and intercept, exactly, in rational
    arithmetic on the floats given. No BLAS kernel takes part (``np.polyfit`` went to OpenBLAS, whose kernels differ
    in the last bits), so a value rounded from these is the same on every machine."""
    xs, ys = [Fraction(float(v)) for v in x], [Fraction(float(v)) for v in y]
    x_mean, y_mean = sum(xs) / len(xs), sum(ys) / len(ys)
    slope = (sum((a - x_mean) * (b - y_mean) for a, b in zip(xs, ys, strict=True))
             / sum((a - x_mean) ** 2 for a in xs))
    return slope, y_mean - slope * x_mean


def replica(duty: float, *, params: SolenoidParams = NOMINAL_SOLENOID, rig: ValveTestRigParams = NOMINAL_RIG
            ) -> tuple[float, np.ndarray]:
    """(R in Pa s/m^3 from the slope, the mean flows (m^3/s) at each of the rig's pressure drops) at PWM
    ``duty`` %. The line's intercept is zero by construction (see the module docstring), so it is not kept."""
    valves = NOMINAL_PARAMS.valves
    fraction = solenoid.mean_flow_fraction(params, duty, period=valves.pwm_period, h=params.step,
                                           inertance_time=rig.inertance_time)
    drops = np.array(rig.pressure_drops)
    flows = fraction * drops / valves.open_resistance  # a linear valve: one fraction holds at every drop
    if fraction <= 0.0:
        return math.inf, flows
    slope, _ = line_fit(drops, flows)
    return float(1 / slope), flows


def emergent_dead_zone(params: SolenoidParams = NOMINAL_SOLENOID, rig: ValveTestRigParams = NOMINAL_RIG
                       ) -> float:
    """The shortest PWM duty (%, in 1 % steps) that passes any flow."""
    valves = NOMINAL_PARAMS.valves
    for duty in range(1, 101):
        if solenoid.mean_flow_fraction(params, duty, period=valves.pwm_period, h=params.step,
                                       inertance_time=rig.inertance_time) > 0.0:
            return float(duty)
    return math.inf


def valve_study(params: SolenoidParams = NOMINAL_SOLENOID, rig: ValveTestRigParams = NOMINAL_RIG) -> Outcome:
    valves = NOMINAL_PARAMS.valves
    rows, unmeasurable = [], []
    for duty in DUTIES:
        resistance, flows = replica(duty, params=params, rig=rig)
        rows.append({"duty_pct": duty, "resistance_eq442_pa_s_per_m3": float(valves.resistance(duty)),
                     "resistance_twin_pa_s_per_m3": resistance})
        unmeasurable += [(duty, drop) for drop, flow in zip(rig.pressure_drops, flows, strict=True)
                         if 0 < flow < rig.min_measurable_flow]
    checked = [r for r in rows if r["duty_pct"] >= CHECKED_FROM]
    ratios = [r["resistance_twin_pa_s_per_m3"] / r["resistance_eq442_pa_s_per_m3"] for r in checked]
    worst = max(range(len(checked)), key=lambda j: abs(ratios[j] - 1))
    fine = [d for d in range(int(CHECKED_FROM), 101)
            if abs(replica(float(d), params=params, rig=rig)[0] / valves.resistance(float(d)) - 1) > TOLERANCE]
    opening, closing = solenoid.delays(params, h=params.step)
    within = sum(abs(x - 1) <= TOLERANCE for x in ratios)
    answer = (f"Valve test replica (§4.4.3), PWM {valves.pwm_period * 1e3:g} ms, pressure drops "
              f"{', '.join(f'{d / 1e3:g}' for d in rig.pressure_drops)} kPa: the twin's R(d) is within "
              f"{TOLERANCE:.0%} of eq. 4.4.2 at {within} of {len(checked)} duties from {CHECKED_FROM:g} % to 100 % "
              f"(twin / eq. 4.4.2 from {min(ratios):.2f} to {max(ratios):.2f}; furthest at "
              f"{checked[worst]['duty_pct']:g} %). Between those steps, at 1 % steps, "
              + (f"{len(fine)} duties are outside {TOLERANCE:.0%} ({fine[0]}-{fine[-1]} %: off-times too short for the "
                 "valve to shut, so it stays open). " if fine else "none is outside it. ")
              + "R(100 %) is the open valve's resistance by construction. "
              f"Full pulse: opens {opening * 1e3:.1f} ms after the coil switches on, shuts {closing * 1e3:.1f} ms after "
              f"it switches off (thesis: 5 and 2 ms). Dead zone: no flow below {emergent_dead_zone(params, rig):g} % "
              f"(thesis: about 30 %). Flow is proportional to the pressure drop by the valve model's construction (a "
              "linear resistance scaled by the opening, no pressure force on the plunger), so the lines pass through "
              f"zero; {len(unmeasurable)} of the replica's points are below the "
              f"{rig.min_measurable_flow:.0e} m^3/s the thesis could measure"
              + (f" (duty {', '.join(sorted({f'{d:g} %' for d, _ in unmeasurable}))} at the lowest drops)."
                 if unmeasurable else "."))
    return Outcome(rows=rows, answer=answer)


def plot_valve(rows: list[dict], path: pathlib.Path) -> None:
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, height_ratios=(2, 1), constrained_layout=True)
    duty = [r["duty_pct"] for r in rows]
    eq = np.array([r["resistance_eq442_pa_s_per_m3"] for r in rows])
    twin = np.array([r["resistance_twin_pa_s_per_m3"] for r in rows])
    top.semilogy(duty, eq, "k-", label="eq. 4.4.2 (thesis's fit to its valve test)")
    top.semilogy(duty, twin, "o", color="C3", label="twin: solenoid valve, replica of the test")
    top.set_ylabel("R (Pa s/m^3)")
    top.legend(fontsize=8)
    bottom.plot(duty, twin / eq, "o-", color="C3")
    bottom.axhspan(1 - TOLERANCE, 1 + TOLERANCE, color="0.9", label=f"±{TOLERANCE:.0%}")
    bottom.axvline(CHECKED_FROM, color="0.6", ls=":")
    bottom.set_ylabel("twin / eq. 4.4.2")
    bottom.set_xlabel("PWM duty (%)")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    fig.savefig(path, dpi=90)
    plt.close(fig)


class ValveExperiment(Experiment):
    name = "valve"
    help = "the thesis's valve test (§4.4.3) on the twin's solenoid valve: R(d) against eq. 4.4.2"

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        return valve_study()

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_valve(outcome.rows, path)


EXPERIMENT = ValveExperiment()
