"""``twin study``: the thesis's robustness protocol (Chapter 6) and its open-loop validation (§4.6).

robustness  SPEC §9: FF + PVA and sliding mode, T1 and T3, 0 / 6.5 / 13.5 g at the
            link tip, horizontal and vertical, seeds 0..4: 120 runs through the sweep
            engine (``twin.batch.sweep.run_sweep``: batched, on all cores, resumable from
            ``DIR/results.sqlite``). Tables in the thesis's form: T1's SSE per run
            and its range; RMSE per run, mean and std for T1 and T3. A run with a
            MuJoCo warning or an error is marked failed and left out of the
            statistics. No number here is tuned toward the held-back measurements.
openloop    SPEC §4.6: the duty ``45 % sin(2 pi t / 1.6 s)``, stepped every 16 ms,
            for 3 s, with soft motion limits on the measured rack position
            (:data:`SOFT_LIMITS`: duty 0 and the sine's sign reversed,
            ``controllers.open_loop.ReversingSine``), noise off, on the ``thesis``
            plant and on another; for each reversal of the commanded duty's sign,
            the delay until the joint's velocity takes the new sign
            (:func:`reversal_lags`).

Degrees, grams and milliseconds only in the rows, tables and answers.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from collections.abc import Callable, Sequence

import numpy as np

from twin.batch.grid import GridPoint, expand
from twin.batch.sweep import run_sweep
from twin.batch.tables import summarise, write_csv
from twin.exceptions import InvalidScenario
from twin.experiments.demo import LABELS
from twin.plants import PLANTS, plant

# --- robustness (SPEC §9) ---------------------------------------------------------------------------------------

ROBUSTNESS_CONTROLLERS = ("ffpva", "smc")
ROBUSTNESS_TRAJECTORIES = (1, 3)
ROBUSTNESS_PAYLOADS_G = (0.0, 6.5, 13.5)  # g at the link tip
ROBUSTNESS_ORIENTATIONS = ("horizontal", "vertical")
ROBUSTNESS_SEEDS = 5  # "five runs each"
RUN_COLUMNS = ("plant", "controller", "trajectory", "payload_g", "orientation", "seed", "status",
               "rmse_deg", "sse_deg", "max_error_deg", "warnings")
SUMMARY_COLUMNS = ("plant", "controller", "trajectory", "payload_g", "orientation", "runs", "failed",
                   "rmse_mean_deg", "rmse_std_deg", "rmse_min_deg", "rmse_max_deg",
                   "sse_min_deg", "sse_max_deg", "sse_range_deg", "max_error_deg")


def default_plant(fallback: str) -> str:
    """``as-built`` when that preset exists, else ``fallback``."""
    return "as-built" if PLANTS.get("as-built") is not None else fallback


@dataclasses.dataclass(frozen=True)
class RobustnessStudy:
    runs: list[dict]  # RUN_COLUMNS, one per scenario, in grid order (controller, trajectory, payload, orientation, seed)
    summary: list[dict]  # SUMMARY_COLUMNS, one per controller x trajectory x payload x orientation
    seeds: int

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.runs if r["status"] != "ok"]


def robustness_grid(*, plant_name: str, seeds: int = ROBUSTNESS_SEEDS,
                    trajectories: Sequence[int] = ROBUSTNESS_TRAJECTORIES) -> list[GridPoint]:
    """The Chapter 6 protocol: controllers x trajectories x payloads x orientations x seeds 0..seeds-1
    (120 points with the defaults), each checked by building its scenario."""
    plant(plant_name)  # an unknown name fails here, with the preset names
    return expand({"controller": list(ROBUSTNESS_CONTROLLERS), "trajectory": list(trajectories),
                   "payload": list(ROBUSTNESS_PAYLOADS_G), "orientation": list(ROBUSTNESS_ORIENTATIONS),
                   "plant": [plant_name], "seed": list(range(seeds))})


def _finite(value: float | None) -> float | None:
    return None if value is None or math.isnan(value) else value


def run_row(record: dict) -> dict:
    """A sweep record as a row of ``robustness_runs.csv``: failed when it raised a MuJoCo warning or an
    error, which ``warnings`` then names."""
    return {"plant": record["plant"], "controller": record["controller"], "trajectory": record["trajectory"],
            "payload_g": record["payload_g"], "orientation": record["orientation"], "seed": record["seed"],
            "status": record["status"], "rmse_deg": _finite(record["rmse_deg"]),
            "sse_deg": _finite(record["sse_deg"]), "max_error_deg": _finite(record["max_error_deg"]),
            "warnings": record["reason"] or ""}


def summary_rows(records: Sequence[dict]) -> list[dict]:
    """Per controller x trajectory x payload x orientation, over the runs that did not fail: RMSE
    mean, std (none from fewer than two runs), min, max; SSE min, max and range (the thesis's "±",
    max |SSE|; none for T3, which ends moving)."""
    rows = []
    for s in summarise(records):
        sse_min, sse_max = _finite(s["sse_min_deg"]), _finite(s["sse_max_deg"])
        rows.append({
            **{c: s[c] for c in SUMMARY_COLUMNS if c in s},
            **{c: _finite(s[c]) for c in ("rmse_mean_deg", "rmse_std_deg", "rmse_min_deg", "rmse_max_deg",
                                          "max_error_deg")},
            "sse_min_deg": sse_min, "sse_max_deg": sse_max,
            "sse_range_deg": None if sse_min is None else max(abs(sse_min), abs(sse_max)),
        })
        if s["runs"] - s["failed"] < 2:
            rows[-1]["rmse_std_deg"] = None  # no spread from one run
    return rows


def robustness_study(*, out: pathlib.Path, plant_name: str, seeds: int = ROBUSTNESS_SEEDS,
                     trajectories: Sequence[int] = ROBUSTNESS_TRAJECTORIES, workers: int | None = None,
                     progress: Callable[[int], None] | None = None) -> RobustnessStudy:
    """Run the protocol (what ``out/results.sqlite`` holds already is not run again) and tabulate it."""
    records = run_sweep(robustness_grid(plant_name=plant_name, seeds=seeds, trajectories=trajectories),
                        out=out, workers=workers, progress=progress).records
    return RobustnessStudy(runs=[run_row(r) for r in records], summary=summary_rows(records), seeds=seeds)


def write_robustness(study: RobustnessStudy, out: pathlib.Path) -> list[pathlib.Path]:
    """``robustness_runs.csv`` and ``robustness_summary.csv``; the plot is ``viz.study_plots``'s."""
    paths = [out / "robustness_runs.csv", out / "robustness_summary.csv"]
    write_csv(study.runs, RUN_COLUMNS, paths[0])
    write_csv(study.summary, SUMMARY_COLUMNS, paths[1])
    return paths


def _cell(row: dict, column: str) -> str:
    if row["status"] != "ok":
        return "failed"
    return "-" if row[column] is None else f"{row[column]:+.2f}" if column == "sse_deg" else f"{row[column]:.2f}"


def _per_run_table(study: RobustnessStudy, trajectory: int, column: str, title: str, tail: Sequence[str],
                   tail_of: Callable[[dict], Sequence[str]]) -> list[str]:
    groups = [s for s in study.summary if s["trajectory"] == trajectory]
    if not groups:
        return []
    lines = [title, f"{'controller':13} {'payload':>7} {'orientation':11} "
             + " ".join(f"{'run ' + str(i + 1):>7}" for i in range(study.seeds))
             + "".join(f" {h:>8}" for h in tail)]
    for s in groups:
        runs = [r for r in study.runs if all(r[k] == s[k] for k in ("controller", "trajectory", "payload_g",
                                                                     "orientation"))]
        lines.append(f"{LABELS[s['controller']]:13} {s['payload_g']:>5g} g {s['orientation']:11} "
                     + " ".join(f"{_cell(r, column):>7}" for r in runs)
                     + "".join(f" {t:>8}" for t in tail_of(s)))
    return lines + [""]


def _number(value: float | None, spec: str = ".2f") -> str:
    return "-" if value is None else format(value, spec)


def format_robustness(study: RobustnessStudy) -> str:
    """The thesis's tables: T1's SSE per run with its range; RMSE per run, mean and std for each trajectory."""
    plant_name = study.runs[0]["plant"] if study.runs else "?"
    lines = [f"Robustness study (SPEC §9) on the {plant_name} plant, degrees; 'failed' runs (MuJoCo warning "
             "or error) are left out of every statistic", ""]
    lines += _per_run_table(study, 1, "sse_deg", "T1: steady-state error per run and its range (± max |SSE|)",
                            ("range",), lambda s: (f"±{_number(s['sse_range_deg'])}",))
    for trajectory in sorted({s["trajectory"] for s in study.summary}):
        lines += _per_run_table(study, trajectory, "rmse_deg", f"T{trajectory}: RMSE per run, mean and std",
                                ("mean", "std"),
                                lambda s: (_number(s["rmse_mean_deg"]), _number(s["rmse_std_deg"])))
    failed = study.failed
    lines.append(f"{len(study.runs)} runs, {len(failed)} failed")
    lines += [f"failed: {LABELS[r['controller']]} T{r['trajectory']} {r['payload_g']:g} g {r['orientation']} "
              f"seed {r['seed']}: {r['warnings']}" for r in failed[:20]]
    return "\n".join(lines)


# --- open loop (SPEC §4.6) ---------------------------------------------------------------------------------------

OPENLOOP_AMPLITUDE = 45.0  # %
OPENLOOP_SINE_PERIOD = 1.6  # s
OPENLOOP_STEP = 16e-3  # s, the duty is stepped once per PWM period
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

    scenario = Scenario("ffpva", OPENLOOP_TRAJECTORY, plant=plant_name, noise=False)  # the name is unused
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
