"""``twin study openloop``: the thesis's open-loop validation (SPEC §4.6).

The duty ``45 % sin(2 pi t / 1.6 s)``, stepped every PWM period (16 ms), for 3 s, with soft
motion limits on the measured rack position (:data:`SOFT_LIMITS`: duty 0 and the sine's sign
reversed, ``controllers.open_loop.ReversingSine``), noise off, on the ``thesis-deadzone`` plant
and on another; for each reversal of the commanded duty's sign, the delay until the joint's
velocity takes the new sign (:func:`reversal_lags`). Milliseconds and degrees only in the rows
and answer.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import pathlib
from collections.abc import Sequence

import numpy as np

from twin.batch.tables import write_csv
from twin.exceptions import InvalidScenario
from twin.experiments.base import Experiment, Outcome
from twin.experiments.studies.robustness import default_plant
from twin.physics.params import NOMINAL_PARAMS
from twin.plants import plant
from viz.figures import finish_panels, plt

OPENLOOP_AMPLITUDE = 45.0  # %
OPENLOOP_SINE_PERIOD = 1.6  # s
OPENLOOP_STEP = NOMINAL_PARAMS.valves.pwm_period  # s, the duty is stepped once per PWM period
OPENLOOP_TRAJECTORY = 1  # only its start (30 deg, y = 2.49 mm) and duration (3 s) are used
# Soft limits on the measured rack position, m: inside the friction fit (2-14.5 mm) with room for the
# ~1 mm a fast joint overshoots in the 16 ms before the next duty step: 30.1 and 162.4 deg.
SOFT_LIMITS = (2.5e-3, 13.5e-3)
LAG_THRESHOLD = math.radians(0.5)  # rad/s: below this the joint counts as not moving


@dataclasses.dataclass(frozen=True)
class Reversal:
    time: float  # s, first duty step with the new sign
    direction: int  # +1 or -1, the new sign
    lag: float  # s, until the velocity has the new sign; nan if not before the next reversal or the end
    cause: str = ""  # "sine" (the sine's own zero) or "limit" (a soft limit), where known


@dataclasses.dataclass(frozen=True)
class OpenLoopRun:
    plant: str
    time: np.ndarray  # s, (T,)
    duty: np.ndarray  # %, (T,), the command in force
    angle: np.ndarray  # rad, (T,), the output shaft
    reversals: tuple[Reversal, ...]
    warnings: tuple[str, ...]

    @property
    def mean_lag(self) -> float:
        """s, the mean lag over the reversals the joint followed (nan where it followed none)."""
        lags = [r.lag for r in self.reversals if not math.isnan(r.lag)]
        return float(np.mean(lags)) if lags else math.nan


@dataclasses.dataclass(frozen=True)
class OpenLoopStudy:
    runs: tuple[OpenLoopRun, OpenLoopRun]  # the thesis model first, then the chosen plant
    rows: list[dict]  # openloop.csv
    answer: str  # the lag table


def reversal_lags(time: np.ndarray, duty: np.ndarray, velocity: np.ndarray, *, threshold: float,
                  duty_tolerance: float = 1e-9) -> list[Reversal]:
    """For each reversal of ``duty``'s sign (zeros in between do not count as a sign), the delay until
    ``velocity`` has the new sign and a magnitude above ``threshold``. Arrays (T,); a duty below
    ``duty_tolerance`` in magnitude is zero."""
    sign = np.where(np.abs(duty) > duty_tolerance, np.sign(duty), 0.0)
    moving = np.where(np.abs(velocity) > threshold, np.sign(velocity), 0.0)
    nonzero = np.flatnonzero(sign)
    starts = [int(k) for previous, k in zip(nonzero[:-1], nonzero[1:], strict=True) if sign[k] != sign[previous]]
    reversals = []
    for i, k in enumerate(starts):
        end = starts[i + 1] if i + 1 < len(starts) else len(time)
        hits = np.flatnonzero(moving[k:end] == sign[k])
        lag = float(time[k + hits[0]] - time[k]) if hits.size else math.nan
        reversals.append(Reversal(time=float(time[k]), direction=int(sign[k]), lag=lag))
    return reversals


def openloop_controller(tick: float):
    """The §4.6 duty with :data:`SOFT_LIMITS`, as a controller of the twin's protocol."""
    from controllers.open_loop import ReversingSine

    return ReversingSine(lower=SOFT_LIMITS[0], upper=SOFT_LIMITS[1], tick=tick, amplitude=OPENLOOP_AMPLITUDE,
                         sine_period=OPENLOOP_SINE_PERIOD, period=OPENLOOP_STEP)


def openloop_run(plant_name: str) -> OpenLoopRun:
    """The §4.6 input on ``plant_name`` from T1's start, noise off, with its reversals and lags."""
    from twin.sim.scenario import Scenario
    from twin.sim.simulation import simulate

    scenario = Scenario(None, OPENLOOP_TRAJECTORY, plant=plant_name, noise=False)
    result = simulate([scenario], controllers=[openloop_controller(scenario.preset.timestep)])[0]
    tr = result.trace
    velocity = np.diff(tr.angle, prepend=tr.angle[0]) / scenario.preset.timestep  # rad/s, reached at each tick
    reversals = [dataclasses.replace(r, cause=_cause(r.time)) for r in
                 reversal_lags(tr.time, tr.duty, velocity, threshold=LAG_THRESHOLD)]
    return OpenLoopRun(plant=plant_name, time=tr.time, duty=tr.duty, angle=tr.angle, reversals=tuple(reversals),
                       warnings=result.warnings)


def _cause(time: float) -> str:
    """Why the command reversed at ``time`` (s): the sine's own sign changed since the step before, or
    (it did not) a soft limit flipped it."""
    before, now = (np.sin(2 * np.pi * t / OPENLOOP_SINE_PERIOD) for t in (time - OPENLOOP_STEP, time))
    return "sine" if before * now <= 1e-12 else "limit"


def _ms(value: float) -> str:
    return "-" if math.isnan(value) else f"{round(value * 1e3):d}"


def paired_reversals(first: Sequence[Reversal], second: Sequence[Reversal], *,
                     window: float) -> list[tuple[Reversal | None, Reversal | None]]:
    """Both runs' reversals in time order, a reversal of ``first`` paired with one of ``second`` within
    ``window`` (s) of it that turns the same way (the same step of the command); the others alone."""
    unused = list(second)
    pairs: list[tuple[Reversal | None, Reversal | None]] = []
    for r in first:
        match = next((m for m in unused if abs(m.time - r.time) <= window and m.direction == r.direction), None)
        if match is not None:
            unused.remove(match)
        pairs.append((r, match))
    pairs += [(None, m) for m in unused]
    return sorted(pairs, key=lambda pair: min(r.time for r in pair if r is not None))


def format_lags(runs: Sequence[OpenLoopRun]) -> str:
    """The lag table: every reversal of either run in time order; where both runs' commands reversed at
    the same step, on one line with the lag difference (second run minus first)."""
    reference, chosen = runs
    step = reference.time[1] - reference.time[0]
    lower, upper = (math.degrees(y / plant(reference.plant).params.gears.spur_radius) for y in SOFT_LIMITS)
    lines = [f"Open loop (SPEC §4.6): duty {OPENLOOP_AMPLITUDE:g} % sin(2 pi t / {OPENLOOP_SINE_PERIOD:g} s), "
             f"stepped every {OPENLOOP_STEP * 1e3:g} ms, {len(reference.time) * step:g} s from "
             f"{math.degrees(reference.angle[0]):.1f} deg, noise off; soft limits y = {SOFT_LIMITS[0] * 1e3:g} and "
             f"{SOFT_LIMITS[1] * 1e3:g} mm ({lower:.1f} and {upper:.1f} deg): duty 0 and the sine reversed.",
             "Lag: from each reversal of the commanded duty's sign (at the sine's zero, or at a soft limit) to "
             f"the joint's velocity taking the new sign (|velocity| > {math.degrees(LAG_THRESHOLD):g} deg/s); "
             "'-': that run did not reverse there, or did not move before its next reversal.",
             f"{'t (s)':>6} {'cause':>5} {reference.plant + ' lag ms':>20} {chosen.plant + ' lag ms':>20} "
             f"{'difference ms':>14}   (+/-: the direction the command turned to)"]
    for a, b in paired_reversals(reference.reversals, chosen.reversals, window=OPENLOOP_STEP / 2):
        r = a if a is not None else b
        cells = ["-" if x is None else f"{_ms(x.lag)} ({'+' if x.direction > 0 else '-'})" for x in (a, b)]
        lags = [math.nan if x is None else x.lag for x in (a, b)]
        lines.append(f"{r.time:>6.3f} {r.cause:>5} {cells[0]:>20} {cells[1]:>20} {_ms(lags[1] - lags[0]):>14}")
    for run in runs:
        for cause in ("sine", "limit"):
            lags = [r.lag for r in run.reversals if r.cause == cause and not math.isnan(r.lag)]
            shown = f"{np.mean(lags) * 1e3:.0f} ms ({len(lags)})" if lags else "-"
            lines.append(f"{run.plant}: mean lag at {cause} reversals {shown}")
        lines += [f"{run.plant}: warning: {w}" for w in run.warnings]
    return "\n".join(lines)


def openloop_study(*, plant_name: str, reference_name: str = "thesis-deadzone") -> OpenLoopStudy:
    """The §4.6 input on the thesis model (eq. 4.4.1 with §4.6's 30 % dead zone: ``thesis-deadzone``)
    and on ``plant_name`` (run once if they are the same)."""
    reference = openloop_run(reference_name)
    runs = (reference, reference if plant_name == reference_name else openloop_run(plant_name))
    if not np.array_equal(runs[0].time, runs[1].time):
        raise InvalidScenario(f"the open-loop study compares plants tick by tick: {reference_name} and "
                              f"{plant_name} have different physics timesteps")
    rows = []
    for k, t in enumerate(runs[0].time):
        row = {"t_s": round(float(t), 9)}
        for run in runs:
            row[f"duty_{run.plant}_pct"] = float(run.duty[k])
            row[f"angle_{run.plant}_deg"] = math.degrees(run.angle[k])
        rows.append(row)
    return OpenLoopStudy(runs=runs, rows=rows, answer=format_lags(runs))


def write_openloop(study: OpenLoopStudy, out: pathlib.Path) -> pathlib.Path:
    """``openloop.csv``: t_s, then the duty (%) and angle (deg) of each plant (each plant's own duty: the
    soft limits act on its own measured position)."""
    path = out / "openloop.csv"
    write_csv(study.rows, list(study.rows[0]), path)
    return path


def plot_openloop(study: OpenLoopStudy, path: pathlib.Path) -> None:
    """Angle and duty against time for both plants, soft limits dotted, each reversal of the commanded
    duty marked, so the lag between the plants at each reversal shows."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True, height_ratios=(2, 1),
                                      constrained_layout=True)
    for index, run in enumerate(study.runs):
        color = f"C{index}"
        top.plot(run.time, np.degrees(run.angle), color=color, label=f"{run.plant}")
        bottom.step(run.time, run.duty, where="post", color=color, label=f"{run.plant}")
        for r in run.reversals:
            top.axvline(r.time, color=color, lw=0.6, ls=":")
            if not math.isnan(r.lag):
                top.annotate(f"{r.lag * 1e3:.0f} ms", (r.time + r.lag, np.degrees(np.interp(r.time + r.lag, run.time,
                                                                                              run.angle))),
                             xytext=(4, -12 if index else 6), textcoords="offset points", fontsize=7, color=color)
    radius = plant(study.runs[0].plant).params.gears.spur_radius
    for y in SOFT_LIMITS:
        top.axhline(math.degrees(y / radius), color="0.5", ls="--", lw=0.8)
    top.set_ylabel("output angle (deg)")
    top.set_title("open-loop validation (SPEC §4.6); dotted: reversals of the duty's sign, "
                  "dashed: soft limits; labels: lag", fontsize=9)
    bottom.set_ylabel("duty (%)")
    bottom.set_xlabel("time (s)")
    finish_panels(fig, (top, bottom), path)


class OpenLoopExperiment(Experiment):
    name = "openloop"
    help = "sine duty with soft limits, thesis model against a plant (SPEC §4)"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--plant", default=None, metavar="NAME", help="default: as-built if present, else thesis-pwm")

    def check(self, args: argparse.Namespace) -> None:
        args.plant = default_plant("thesis-pwm") if args.plant is None else args.plant
        plant(args.plant)

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        study = openloop_study(plant_name=args.plant)
        return Outcome(rows=study.rows, answer=study.answer, failed=sum(bool(run.warnings) for run in study.runs),
                       detail=study)

    def file_names(self) -> tuple[str, ...]:
        return ("openloop.csv", "openloop.png")

    def write(self, outcome: Outcome, out: pathlib.Path) -> list[pathlib.Path]:
        return [write_openloop(outcome.detail, out)]

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_openloop(outcome.detail, path)


EXPERIMENT = OpenLoopExperiment()
