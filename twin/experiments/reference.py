"""The thesis's published results (SPEC §8), in degrees, for comparison tables."""

from __future__ import annotations

from twin.physics.model import THESIS_PAYLOADS
from twin.plants.as_built import BREAKAWAY_TEST_PRESSURE, SLOWEST_FULL_DUTY_SPEED

# Simulated RMSE per trajectory T1..T4 and SSE of T1 (§8, "Simulation").
THESIS_SIMULATED_RMSE_DEG = {
    "ffpva": {1: 0.52, 2: 0.83, 3: 0.91, 4: 0.80},
    "smc": {1: 0.86, 2: 0.99, 3: 1.26, 4: 0.94},
}
THESIS_SIMULATED_SSE_T1_DEG = {"ffpva": 0.35, "smc": 0.53}
THESIS_SIMULATED_T4_REST_ERRORS_DEG = {"ffpva": (0.35, 1.21, -1.39, 0.40), "smc": (0.53, -0.58, 0.39, -0.17)}

# Experiment, horizontal, no payload: mean RMSE and std over 5 runs (§8).
THESIS_EXPERIMENT_RMSE_DEG = {
    "pva": {1: (4.20, 0.76), 2: (2.93, 0.65), 3: (3.00, 0.50)},
    "ffpva": {1: (1.40, 0.06), 2: (2.08, 0.21), 3: (2.09, 0.12), 4: (1.95, 0.16)},
    "smc": {1: (1.19, 0.11), 2: (1.55, 0.25), 3: (1.69, 0.09), 4: (1.82, 0.17)},
}
# Experiment T1 steady-state error range (+-, deg) over the 5 runs (§8).
THESIS_EXPERIMENT_SSE_T1_RANGE_DEG = {"pva": 0.41, "ffpva": 0.77, "smc": 0.85}
# Experiment, the largest |error| (deg, §8's "max error" column), as the thesis rounds and gives it: one
# number per controller and trajectory, not a mean over the runs. PVA + DZC on T1 only; FF + PVA 5 on
# T1-T3 and 8 on T4; sliding mode 5 on T1 (after which it held within ±2.5).
THESIS_EXPERIMENT_MAX_ERROR_DEG = {"pva": {1: 13.5}, "ffpva": {1: 5.0, 2: 5.0, 3: 5.0, 4: 8.0}, "smc": {1: 5.0}}

# The force-loss runs (§4.5.1): the joint started from rest with both valves of the pair at 100 % duty, both
# ways, at supply pressures from 245 to 575 kPa, and its rack ran at 0.03 to 0.12 m/s (the range, given to a
# digit or two). That the slowest came at the lowest pressure and the
# fastest at the highest is *inferred*. (supply Pa gauge, rack speed m/s, which end of the range).
# The slow end, and the digit both ends are printed to (FULL_DUTY_SPEED_DIGIT), also bound the as-built CCW
# friction (twin.plants.as_built.CCW_SCALE_BOUND), so they live there.
THESIS_FULL_DUTY_SPEEDS = ((BREAKAWAY_TEST_PRESSURE, SLOWEST_FULL_DUTY_SPEED, "slowest"), (575e3, 0.12, "fastest"))

# The robustness study's tip payloads (§9), g: none, then the thesis's two.
THESIS_PAYLOADS_G = (0.0, *(round(m * 1e3, 9) for m in THESIS_PAYLOADS))

# The robustness study's cells (Chapter 6, §9): (controller, trajectory, payload g, orientation), T1 and T3.
ROBUSTNESS_CELLS = tuple((c, t, g, o) for c in ("ffpva", "smc") for t in (1, 3) for o in ("horizontal", "vertical")
                         for g in THESIS_PAYLOADS_G)

# The robustness study (Chapter 6, §9), measured, T1 only: (controller, orientation) -> payload g ->
# (mean RMSE of 5 runs, std, SSE range +- max |SSE|). Every run lifted its payload and tracked (none
# stalled). The T3 cells are held back for a blind prediction and are not in the twin.
THESIS_ROBUSTNESS_T1_DEG = {
    ("ffpva", "horizontal"): {0.0: (1.40, 0.06, 0.77), 6.5: (1.69, 0.24, 1.17), 13.5: (1.75, 0.25, 1.19)},
    ("ffpva", "vertical"): {0.0: (1.63, 0.22, 1.08), 6.5: (1.72, 0.18, 0.81), 13.5: (4.55, 0.45, 0.57)},
    ("smc", "horizontal"): {0.0: (1.19, 0.11, 0.85), 6.5: (1.31, 0.13, 0.84), 13.5: (1.22, 0.17, 0.42)},
    ("smc", "vertical"): {0.0: (1.57, 0.20, 0.86), 6.5: (1.51, 0.13, 0.68), 13.5: (3.48, 0.48, 0.90)},
}
