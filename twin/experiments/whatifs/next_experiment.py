"""``twin whatif next-experiment``: which single experiment on the real joint would narrow the
twin's Chapter 6 predictions most, per hour of rig time (value of information).

The calibration ensemble holds the parameter sets that fit the published measurements about equally
well (they differ in the breakaway force and in the load friction, which only a loaded gear train
shows). Each candidate experiment is simulated on
every member, over several seeds (each seed is another joint: another static-friction map and
sensor noise), and reduced to one number, its virtual measurement:

``breakaway-map`` (SPEC §10)
    the joint at rest at several positions across the stroke; the pair V1 + V4 opened at 100 %
    duty; the supply pressure raised in steps of ``--pressure-step`` from 40 kPa until the joint
    moves (the Hall reading leaves its rest by more than :data:`MOVED`). Measurement: the mean over
    the positions of the lowest step that moved it, kPa. At each position the threshold is the rest
    limit over the bore area, max(F_s(y), F_c(y)) / A: the breakaway map, or eq. 4.5.7's Coulomb
    level where that is higher (at 2 of the 8 positions on the committed preset).
``loaded-breakaway-map``
    the same map with the joint on its side and the 13.5 g payload on the link (the Chapter 6
    vertical set-up): at each rest position the pair must lift the payload as well as break away,
    so the threshold is (max(F_s(y), F_c(y)) + (1 + mu_L) G(theta)) / A, with G the payload's and
    the link's gravity load at the rack and mu_L the load friction. Only a move upwards, against the
    payload, counts: a slip downwards would be the payload winning, not a breakaway (within the
    fitted box it does not happen: G is at most about 1 N, less than the breakaway plus what 40 kPa
    pushes). Measurement: as the map's.
``slow-sine``
    the thesis's open-loop reversing duty sine (§4.6), slower and at a low supply: 60 % amplitude,
    4 s period, 150 kPa, from mid-stroke for 6 s. Measurement: the distance the joint travelled
    (the Hall angle in 50 ms means, so that the sensor noise does not add up), degrees.

The refit: each member in turn is the "true" joint, one of its seeds the real rig's run. Every
member is weighed by the likelihood of that measurement under it, a normal density with the
member's mean over its other seeds and the spread that the seeds show within members (pooled;
the pressure sensor's 0.4 kPa and the Hall sensor's 0.02 mm are inside it). The ensemble being
the fit's sample of what the published data allow, this reweighting is the refit on the new
measurement. The band of each Chapter 6 prediction (T1 and T3, both controllers, 0 / 6.5 /
13.5 g, horizontal and vertical) is the weighted 10-90 % spread of the members' mean RMSE; its
width after the refit is averaged over every choice of true member and run (widths by the weighted
inverse distribution, :func:`weighted_band`). Rig time is an
assumption, stated in :data:`RIG_TIME`.
"""

from __future__ import annotations

import argparse
import math
import pathlib

import numpy as np

import twin.experiments.whatifs.ensemble as ensemble
from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.experiments.base import Experiment, Outcome
from twin.experiments.reference import ROBUSTNESS_CELLS
from twin.experiments.whatifs.common import progress_bar, refuse_oversized
from viz.figures import finish_panels, plt

COLUMNS = ("experiment", "cell", "band_width_before_deg", "band_width_after_deg", "rig_hours")
EXPERIMENTS = ("breakaway-map", "loaded-breakaway-map", "slow-sine")
MAPS = EXPERIMENTS[:2]  # the supply-pressure ladders: measured in Pa, their rig time counted in steps
LOADED_PAYLOAD = 13.5e-3  # kg at the link tip, vertical: the heaviest Chapter 6 payload (SPEC §9)
LADDER_START = 40e3  # Pa, the first supply setting tried
LADDER_TOP = 320e3  # Pa, above the 245 kPa where the real joint always broke away
MAP_ANGLES_DEG = tuple(np.linspace(20.0, 160.0, 8))  # rest positions, as the Hall sensor reads them
MOVED = 0.1e-3  # m of rack travel: five times the Hall noise bound
SINE = {"amplitude": 60.0, "sine_period": 4.0, "supply": 150e3, "start_deg": 90.0}
SINE_BIN = 0.05  # s
RIG_TIME = {  # hours; assumptions, not from the thesis
    "setup": 0.5,  # filling, bleeding and zeroing before either experiment
    "breakaway_step": 20.0 / 3600,  # set the regulator, wait for the supply to settle, open the pair, look
    "breakaway_reposition": 60.0 / 3600,  # move the joint to the next rest position
    "sine_run": 90.0 / 3600,  # one 6 s run and the reset before the next
    "turn_and_load": 0.25,  # the loaded map: turn the joint on its side, fix the payload to the link
}
SINE_RUNS = 5  # the thesis's five runs


def ladder(step: float) -> np.ndarray:
    """Supply settings tried, Pa: from LADDER_START up to LADDER_TOP in ``step``."""
    return LADDER_START + step * np.arange(int(math.floor((LADDER_TOP - LADDER_START) / step + 1e-9)) + 1)


def breakaway_batch(plant, cases: tuple, seeds: tuple) -> dict:
    """The breakaway map on ``plant`` for each seed: {("breakaway-map", seed): mean threshold, Pa} and the
    trials it took: {("breakaway-map-trials", seed): steps tried}. ``cases`` = ((step,),); any move counts."""
    return _ladder_map(plant, cases, seeds, name="breakaway-map", load={},
                       moved=lambda travel: np.max(np.abs(travel)) > MOVED)


def loaded_breakaway_batch(plant, cases: tuple, seeds: tuple) -> dict:
    """The same map with the joint vertical and :data:`LOADED_PAYLOAD` on the link, keyed
    "loaded-breakaway-map"; only a move upwards, against the payload, counts."""
    from twin.physics.model import Orientation

    return _ladder_map(plant, cases, seeds, name="loaded-breakaway-map",
                       load={"payload": LOADED_PAYLOAD, "orientation": Orientation.VERTICAL},
                       moved=lambda travel: np.max(travel) > MOVED)


def _ladder_map(plant, cases: tuple, seeds: tuple, *, name: str, load: dict, moved) -> dict:
    """{(name, seed): mean threshold over the rest positions, Pa; (name + "-trials", seed): steps tried}.
    ``load``: the scenarios' payload and orientation; ``moved(travel)``: whether a run's Hall travel from
    rest (m, (ticks,)) counts as a move. Bisection on the ladder finds the lowest step that moves the
    joint (motion is monotone in the supply), one batch per round over every seed and position."""
    from controllers.open_loop import OpenLoop
    from twin.sim.scenario import Scenario
    from twin.sim.simulation import simulate

    (step,) = cases[0]
    settings = ladder(step)
    r_s = plant.params.gears.spur_radius
    starts = np.radians(MAP_ANGLES_DEG) * r_s
    jobs = [(s, y) for s in seeds for y in starts]
    low = np.full(len(jobs), -1)  # highest index known not to move
    high = np.full(len(jobs), len(settings))  # lowest index known to move (len: not even the top)
    opener = OpenLoop(schedule=lambda t: 100.0, tick=plant.timestep)
    while np.any(high - low > 1):
        open_ = np.flatnonzero(high - low > 1)
        mid = (low[open_] + high[open_]) // 2
        scenarios = [Scenario(None, 2, plant=plant, seed=jobs[j][0], supply_pressure=float(settings[m]), **load)
                     for j, m in zip(open_, mid, strict=True)]
        results = simulate(scenarios, controllers=[opener] * len(scenarios), nthread=1,
                           start_positions=np.array([jobs[j][1] for j in open_]))
        for j, m, r in zip(open_, mid, results, strict=True):
            if moved(r.trace.measured_position - r.trace.measured_position[0]):
                high[j] = m
            else:
                low[j] = m
    top = settings[-1] + step  # never moved: censored at the next step
    threshold = np.array([settings[h] if h < len(settings) else top for h in high])
    out = {}
    for k, s in enumerate(seeds):
        mine = slice(k * len(starts), (k + 1) * len(starts))
        out[name, s] = float(np.mean(threshold[mine]))
        out[name + "-trials", s] = float(np.sum(high[mine] + 1))  # stepping up from the bottom, as on the rig
    return out


def sine_batch(plant, cases: tuple, seeds: tuple) -> dict:
    """The slow open-loop sine on ``plant`` for each seed: {("slow-sine", seed): travel, deg}."""
    from controllers.open_loop import ReversingSine
    from twin.sim.scenario import Scenario
    from twin.sim.simulation import simulate

    del cases
    r_s = plant.params.gears.spur_radius
    lower, upper = np.radians(10.0) * r_s, np.radians(170.0) * r_s
    sine = ReversingSine(lower=lower, upper=upper, tick=plant.timestep, amplitude=SINE["amplitude"],
                         sine_period=SINE["sine_period"])
    scenarios = [Scenario(None, 4, plant=plant, seed=s, supply_pressure=SINE["supply"]) for s in seeds]
    results = simulate(scenarios, controllers=[sine] * len(scenarios), nthread=1,
                       start_positions=np.full(len(seeds), np.radians(SINE["start_deg"]) * r_s))
    out, per_bin = {}, int(round(SINE_BIN / plant.timestep))
    for s, r in zip(seeds, results, strict=True):
        y = r.trace.measured_position
        means = y[: len(y) // per_bin * per_bin].reshape(-1, per_bin).mean(axis=1)
        out["slow-sine", s] = float(np.degrees(np.sum(np.abs(np.diff(means))) / r_s))
    return out


def experiment_batch(plant, cases: tuple, seeds: tuple) -> dict:
    return {**breakaway_batch(plant, cases, seeds), **loaded_breakaway_batch(plant, cases, seeds),
            **sine_batch(plant, cases, seeds)}


def weighted_band(values: np.ndarray, weights: np.ndarray) -> float:
    """Width of the weighted 10-90 % band of ``values``: the inverse of the weighted empirical
    distribution (the smallest value whose cumulative weight reaches q), so that a member holding
    nearly all the weight gives a band of nearly nothing. With equal weights on fewer than ten members it
    spans them all (1/8 > 10 %); on 11 it leaves out the lowest and the highest (1/11 < 10 %), so a refit that
    weights an extreme up can widen it."""
    order = np.argsort(values)
    v, w = np.asarray(values, dtype=float)[order], np.asarray(weights, dtype=float)[order]
    cdf = np.cumsum(w) / w.sum()
    low, high = (v[min(int(np.searchsorted(cdf, q - 1e-12)), len(v) - 1)] for q in (0.1, 0.9))
    return float(high - low)


def refit_widths(measurements: np.ndarray, predictions: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Band widths before and after the refit, per cell, and the likelihood's spread.

    ``measurements`` (members, seeds): a virtual measurement per member and run; ``predictions``
    (members, cells): each member's prediction. Every (member, seed) in turn is the truth; the
    weights are normal likelihoods about each member's mean (the true member's without that run),
    with the pooled within-member standard deviation."""
    members, seeds = measurements.shape
    sigma = float(np.sqrt(np.mean(np.var(measurements, axis=1, ddof=1))))
    sigma = max(sigma, 1e-12)
    before = np.array([weighted_band(predictions[:, c], np.ones(members)) for c in range(predictions.shape[1])])
    after = np.zeros(predictions.shape[1])
    overall = measurements.mean(axis=1)
    for t in range(members):
        for s in range(seeds):
            observed = measurements[t, s]
            means = overall.copy()
            means[t] = np.delete(measurements[t], s).mean()
            weights = np.exp(-0.5 * ((observed - means) / sigma) ** 2)
            after += [weighted_band(predictions[:, c], weights) for c in range(predictions.shape[1])]
    return before, after / (members * seeds), sigma


def rig_hours(trials_per_map: dict[str, float]) -> dict[str, float]:
    """Rig time of each experiment (hours), from :data:`RIG_TIME`; ``trials_per_map`` holds each map's
    mean number of pressure steps, the simulated ones."""
    def mapping(name: str) -> float:
        return (RIG_TIME["setup"] + trials_per_map[name] * RIG_TIME["breakaway_step"]
                + len(MAP_ANGLES_DEG) * RIG_TIME["breakaway_reposition"])

    return {"breakaway-map": mapping("breakaway-map"),
            "loaded-breakaway-map": mapping("loaded-breakaway-map") + RIG_TIME["turn_and_load"],
            "slow-sine": RIG_TIME["setup"] + SINE_RUNS * RIG_TIME["sine_run"]}


def cell_label(cell: tuple) -> str:
    c, t, g, o = cell
    return f"{c} T{t} {g:g} g {o}"


def next_experiment_study(*, seeds: int = 4, prediction_seeds: int = 3, pressure_step: float = 10e3,
                          members: int | None = None, workers: int = 2, bar=None) -> Outcome:
    count = ensemble.members_to_run(members)
    if count < 2:
        raise InvalidScenario("--members: the refit needs at least 2 ensemble members")
    seed_list = tuple(range(100, 100 + seeds))  # runs of the virtual rig: apart from the prediction's seeds
    if bar is not None:
        bar.reset(total=2 * count)
    step = (lambda: bar.update(1)) if bar is not None else None
    measured = ensemble.over_ensemble(experiment_batch, ((pressure_step,),), seeds=seed_list, workers=workers,
                                      members=count, progress=step)
    predicted_seeds = tuple(range(prediction_seeds))
    predicted = ensemble.over_ensemble(ensemble.cells_batch, ROBUSTNESS_CELLS, seeds=predicted_seeds,
                                       workers=workers, members=count, progress=step)
    predictions = np.array([ensemble.member_means(predicted, cell, predicted_seeds) for cell in ROBUSTNESS_CELLS]).T
    trials = {name: float(np.mean([runs[name + "-trials", s] for runs in measured for s in seed_list]))
              for name in MAPS}
    hours = rig_hours(trials)
    rows, summary = [], {}
    for name in EXPERIMENTS:
        values = np.array([[runs[name, s] for s in seed_list] for runs in measured])
        before, after, sigma = refit_widths(values, predictions)
        summary[name] = {"before": before, "after": after, "sigma": sigma, "values": values}
        rows += [dict(zip(COLUMNS, (name, cell_label(cell), float(b), float(a), hours[name]), strict=True))
                 for cell, b, a in zip(ROBUSTNESS_CELLS, before, after, strict=True)]
    answer = _answer(summary, hours, members=count, seeds=seeds, prediction_seeds=prediction_seeds,
                     pressure_step=pressure_step, trials=trials)
    return Outcome(rows, answer, detail=summary)


def _answer(summary: dict, hours: dict, *, members: int, seeds: int, prediction_seeds: int, pressure_step: float,
            trials: dict[str, float]) -> str:
    lines = [f"{members} calibration ensemble members, {seeds} virtual rig runs each; Chapter 6 predictions from "
             f"{prediction_seeds} seeds per member. Band = 10-90 % of the members' mean RMSE (weighted inverse distribution: with equal weights, all members if fewer than ten; from ten, not the highest, and from eleven, not the lowest either)."]
    score = {}
    for name in EXPERIMENTS:
        s = summary[name]
        before, after = s["before"], s["after"]
        kept = float(np.sum(after) / np.sum(before)) if np.sum(before) > 0 else 1.0
        score[name] = (1.0 - kept) / hours[name]
        unit, scale = ("kPa", 1e-3) if name in MAPS else ("deg", 1.0)
        member_means = s["values"].mean(axis=1) * scale
        widest = int(np.argmax(before))
        order = np.sort(s["values"].mean(axis=1))
        groups = 1 + int(np.sum(np.diff(order) > 2 * s["sigma"]))  # members it tells apart: gaps over 2 sigma
        lines.append(
            f"{name}: measurement {member_means.min():.1f}-{member_means.max():.1f} {unit} across members, spread "
            f"within a member {s['sigma'] * scale:.1f} {unit}, so it tells the {len(order)} members apart in "
            f"{groups} group{'s' if groups > 1 else ''}; bands narrow to {kept:.0%} of their width in sum "
            f"(widest cell {cell_label(ROBUSTNESS_CELLS[widest])}: {before[widest]:.2f} -> "
            f"{after[widest]:.2f} deg); rig time {hours[name]:.1f} h; narrowing {score[name]:.2f} per hour.")
    best = max(score, key=score.get)
    if round(score[best], 2) > 0:  # as the lines above print it: 0.00 per hour narrows nothing worth saying
        lines.append(f"Answer: run the {best} experiment next: it narrows the predictions most per hour of rig time.")
    else:
        lines.append("Answer: none of these experiments narrows the predictions here by 0.01 per hour of rig time or "
                     "more, so none is worth its rig time by this measure; more members or seeds may tell them apart.")
    lines.append(f"Assumed: supply steps of {pressure_step / 1e3:g} kPa from {LADDER_START / 1e3:g} kPa (the "
                 f"air-over-water supply set by its air regulator; not finer), {len(MAP_ANGLES_DEG)} rest positions "
                 f"20-160 deg ({LOADED_PAYLOAD * 1e3:g} g on the link, vertical, for the loaded map), "
                 f"{trials['breakaway-map']:.0f} and {trials['loaded-breakaway-map']:.0f} steps per map on average; "
                 f"rig time: {RIG_TIME['setup']:g} h to set up (+{RIG_TIME['turn_and_load']:g} h to turn the joint "
                 f"on its side and fix the payload), "
                 f"{RIG_TIME['breakaway_step'] * 3600:g} s a pressure step, {RIG_TIME['breakaway_reposition'] * 3600:g} s "
                 f"to move to the next rest position, {RIG_TIME['sine_run'] * 3600:g} s a sine run ({SINE_RUNS} runs); the "
                 f"ensemble's "
                 f"members are the only joints considered possible (a refit by reweighting, not a new search).")
    return "\n".join(lines)


def plot_next_experiment(outcome: Outcome, path: pathlib.Path) -> None:
    summary = outcome.detail
    cells = [cell_label(c) for c in ROBUSTNESS_CELLS]
    fig, ax = plt.subplots(figsize=(12, 4.8), constrained_layout=True)
    x = np.arange(len(cells))
    first = summary[EXPERIMENTS[0]]["before"]
    width = 0.2
    ax.bar(x - 1.5 * width, first, width, color="0.6", label="before (calibration ensemble)")
    colours = {"breakaway-map": "tab:green", "loaded-breakaway-map": "tab:blue", "slow-sine": "tab:orange"}
    for k, name in enumerate(EXPERIMENTS):
        ax.bar(x + (k - 0.5) * width, summary[name]["after"], width, color=colours[name],
               label=f"after the {name} experiment")
    ax.set_xticks(x, cells, rotation=70, ha="right", fontsize=7)
    ax.set_ylabel("width of the 10-90 % band (deg)")
    ax.set_title("Chapter 6 prediction bands before and after refitting on one more experiment", fontsize=9)
    finish_panels(fig, [ax], path)


class NextExperimentWhatIf(Experiment):
    name = "next-experiment"
    help = "which experiment on the real joint narrows the Chapter 6 predictions most per hour (as-built)"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        ensemble.add_ensemble_arguments(parser, seeds=4, least=2)  # check() says why
        parser.add_argument("--prediction-seeds", type=arguments.seed_count, default=3, metavar="N",
                            help="seeds per Chapter 6 cell and member for the predictions (default 3)")
        parser.add_argument("--pressure-step", type=arguments.kpa_number, default=10.0, metavar="KPA",
                            help="supply pressure step of the breakaway map, kPa (default 10)")

    def check(self, args: argparse.Namespace) -> None:
        ensemble.check_members(args.members)
        if args.members is not None and args.members < 2:
            raise InvalidScenario("--members: the refit needs at least 2 ensemble members")
        if args.seeds < 2:
            raise InvalidScenario("--seeds: the spread within a member needs at least 2 seeds")
        if not (math.isfinite(args.pressure_step) and 1.0 <= args.pressure_step <= 100.0):
            raise InvalidScenario(f"--pressure-step: 1-100 kPa, got {args.pressure_step:.10g}")
        members = ensemble.members_to_run(args.members)
        rounds = math.ceil(math.log2(len(ladder(args.pressure_step * 1e3)) + 1))  # a map's bisection, at most
        per_seed = len(MAPS) * len(MAP_ANGLES_DEG) * rounds + 1  # the two maps' positions each round, the sine
        refuse_oversized(members * (args.seeds * per_seed + args.prediction_seeds * len(ROBUSTNESS_CELLS)),
                         "--seeds x --prediction-seeds x --members", at_most=True)

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        with progress_bar(self.name) as bar:
            return next_experiment_study(seeds=args.seeds, prediction_seeds=args.prediction_seeds,
                                         pressure_step=args.pressure_step * 1e3, members=args.members, bar=bar)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_next_experiment(outcome, path)


EXPERIMENT = NextExperimentWhatIf()
