"""``twin validate --out DIR``: every published comparison the twin can be held to, in one run, and
the blind prediction of the Chapter 6 T3 cells over the calibration ensemble.

Compared (``validation.csv``, one row per cell):

==============================  ============  =======================================================
source                          plant         tolerance
==============================  ============  =======================================================
chapter 5 simulation            thesis        |twin - thesis| <= 0.35 deg (the reproduction test's)
chapter 5 experiment            as-built      twin mean within 20 % of the measured mean
chapter 6 T1                    as-built      within 20 %
... T1 SSE range (both)         as-built      within +-0.5 deg of the measured range
4.4.3 valve test                solenoid      R(d) within 15 % of eq. 4.4.2 (duties 35-100 %)
4.4.3 valve delays              solenoid      within 1 ms of 5 ms opening / 2 ms closing
4.6 open-loop lag               as-built      the real joint lagged the thesis's model at each reversal
==============================  ============  =======================================================

Every closed-loop cell runs the thesis's five runs (seeds 0-4); the verdicts judge those. Every
measured cell also runs on :data:`FRESH_SEEDS` (``seeds.csv``, :func:`seed_rows`): forty noise seeds that
no step of the calibration ran, to show which verdicts are the draw of five runs. The prediction (``prediction.csv``)
runs the T3 cells (FF + PVA and sliding mode, 0 / 6.5 / 13.5 g, horizontal and vertical) on the
committed preset and on every member of the calibration ensemble (:func:`ensemble_values`), five
runs each: ``twin_mean`` is the committed preset's mean RMSE, the band the 10 / 50 / 90 %
percentiles of the members' five-run means, ``stalled_runs`` the runs of all members that did not
follow the trajectory (an error above :data:`STALL_ERROR_DEG` at some point). Nothing here is tuned
toward the held-back T3 measurements, which the twin does not have.

The code is a package, one room a role, each importing only the rooms before it:

==============  ==============================================================================================
``common``      the seeds, the tolerances and the verdicts on them, the files' columns, the fresh seeds, and
                how the report names a fitted parameter (:data:`PARAMETER_TEXT`)
``comparisons`` the published comparisons, run (simulations, measured cells, valve, full-duty speeds, open loop)
``motion``      how the controllers move the joint: sliding mode's parts, the opening lag, the pulse cycle,
                where in T1 a payload costs
``ensemble``    the T3 prediction over the ensemble; each member's orders and leads
``run``         :func:`validate` and its :class:`Validation`
``text``        small pieces of the report's wording (numbers, lists, cell names, a parameter's value)
``readings``    every miss and its reading (``misses.csv``)
``members``     the members' table and ``members.csv``
``markdown``    ``validation.md``
``figures``     the figures
``experiment``  the command (:data:`EXPERIMENT`)
==============  ==============================================================================================

Every public name of every room is imported here, so ``from twin.experiments.validate import X`` finds it;
a private helper is imported from its room. A room reads a shared constant (``SEEDS`` and the like) as its own
global, so a test that patches one patches it on the room whose function reads it, not on this package, where
the patch would change nothing.
"""

from __future__ import annotations

from twin.experiments.validate.common import (
    DELAY_TOLERANCE,
    EFFECT_COLUMNS,
    EFFECT_SIGNIFICANCE,
    FRESH_GROUPS,
    FRESH_SEEDS,
    MEMBER_COLUMNS,
    PARAMETER_TEXT,
    PREDICTION_CELLS,
    PREDICTION_COLUMNS,
    PREDICTION_MEMBER_COLUMNS,
    RMSE_TOLERANCE,
    SEED_COLUMNS,
    SEEDS,
    SIMULATION_TOLERANCE_DEG,
    SPREAD_CONFIDENCE,
    SSE_TOLERANCE_DEG,
    STALL_ERROR_DEG,
    VALIDATION_COLUMNS,
    rmse_within,
    sse_within,
    stalled_runs,
)
from twin.experiments.validate.comparisons import (
    BROKE_AWAY,
    FULL_DUTY_PLANTS,
    FULL_DUTY_TURN,
    UNJUDGED_VALVE_ROW,
    full_duty_rows,
    full_duty_runs,
    max_error_rows,
    measured_rows,
    openloop_rows,
    payload_effects,
    ratio_se,
    seed_rows,
    simulation_rows,
    spread_interval,
    valve_rows,
    window_speed,
)
from twin.experiments.validate.ensemble import (
    controller_order,
    known_orders,
    lead_counts,
    member_leads,
    member_means,
    member_orders,
    prediction,
    prediction_member_rows,
    prediction_rows,
)
from twin.experiments.validate.experiment import (
    EXPERIMENT,
    ValidateExperiment,
)
from twin.experiments.validate.figures import (
    figure_effects,
    figure_prediction,
    figure_pulses,
    figure_seeds,
    figure_validation,
)
from twin.experiments.validate.markdown import (
    report,
)
from twin.experiments.validate.members import (
    member_cells_within,
    member_rows,
)
from twin.experiments.validate.motion import (
    SLOW_TRAJECTORIES,
    NoClosedForm,
    discharge_open,
    opening_command,
    opening_lag,
    opening_starts,
    opening_ticks,
    payload_phases,
    pulse_cycle,
    pulse_statistics,
    ramp_opening_lags,
    sliding_mode_parts,
)
from twin.experiments.validate.readings import (
    MISS_COLUMNS,
    READINGS,
    misses,
)
from twin.experiments.validate.run import (
    Validation,
    validate,
)

__all__ = [
    "BROKE_AWAY",
    "DELAY_TOLERANCE",
    "EFFECT_COLUMNS",
    "EFFECT_SIGNIFICANCE",
    "EXPERIMENT",
    "FRESH_GROUPS",
    "FRESH_SEEDS",
    "FULL_DUTY_PLANTS",
    "FULL_DUTY_TURN",
    "MEMBER_COLUMNS",
    "MISS_COLUMNS",
    "NoClosedForm",
    "PARAMETER_TEXT",
    "PREDICTION_CELLS",
    "PREDICTION_COLUMNS",
    "PREDICTION_MEMBER_COLUMNS",
    "READINGS",
    "RMSE_TOLERANCE",
    "SEEDS",
    "SEED_COLUMNS",
    "SIMULATION_TOLERANCE_DEG",
    "SLOW_TRAJECTORIES",
    "SPREAD_CONFIDENCE",
    "SSE_TOLERANCE_DEG",
    "STALL_ERROR_DEG",
    "UNJUDGED_VALVE_ROW",
    "VALIDATION_COLUMNS",
    "ValidateExperiment",
    "Validation",
    "controller_order",
    "discharge_open",
    "figure_effects",
    "figure_prediction",
    "figure_pulses",
    "figure_seeds",
    "figure_validation",
    "full_duty_rows",
    "full_duty_runs",
    "known_orders",
    "lead_counts",
    "max_error_rows",
    "measured_rows",
    "member_cells_within",
    "member_leads",
    "member_means",
    "member_orders",
    "member_rows",
    "misses",
    "opening_command",
    "opening_lag",
    "opening_starts",
    "opening_ticks",
    "openloop_rows",
    "payload_effects",
    "payload_phases",
    "prediction",
    "prediction_member_rows",
    "prediction_rows",
    "pulse_cycle",
    "pulse_statistics",
    "ramp_opening_lags",
    "ratio_se",
    "report",
    "rmse_within",
    "seed_rows",
    "simulation_rows",
    "sliding_mode_parts",
    "spread_interval",
    "sse_within",
    "stalled_runs",
    "validate",
    "valve_rows",
    "window_speed",
]
