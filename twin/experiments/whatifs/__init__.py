"""``twin whatif NAME``: gravity, payload, supply and PWM questions, one module each, every one an
:class:`twin.experiments.base.Experiment` (a table, a plot and a short answer).

payload    tracking against tip payload, both orientations, until the joint no longer follows
lift       the heaviest payload lifted vertically against supply pressure
pwm        tracking against the valves' PWM period alone (SPEC §10)
gear-load  gear tooth forces against the Lewis safe loads
supply     the as-built supply line against an accumulator and a constant supply (SPEC §10)
pva-rate   FF + PVA updated inside the PWM period (SPEC §10), over the calibration ensemble
observer   a Kalman velocity/acceleration observer against eq. 5.2.2's (SPEC §10), over the ensemble
next-experiment  which rig experiment narrows the Chapter 6 prediction bands most per hour
smc-phi    sliding mode against its boundary layer phi on every measured sliding-mode cell (nothing else changes)
air        the T3 prediction against the chambers' free air, the fit's cost beside it (nothing else refitted)

A new what-if is a new module with an ``EXPERIMENT`` object, listed in ``WHATIFS``.
"""

from __future__ import annotations

from twin.experiments.whatifs import (
    air,
    gear_load,
    lift,
    next_experiment,
    observer,
    payload,
    pva_rate,
    pwm,
    smc_phi,
    supply,
)

WHATIFS = {module.EXPERIMENT.name: module.EXPERIMENT for module in (payload, lift, pwm, gear_load, supply, pva_rate,
                                                                    observer, next_experiment, smc_phi, air)}
