"""Every long command shows progress with a total, from the command line (issue: "Nothing half-written,
nothing lost, no surprises"); and ``whatif lift`` names the lowest pressure tried that lifts the thesis
payload, as its own rows say."""

from __future__ import annotations

import csv
import math
import re

import numpy as np
import pytest

from twin.cli import main

COUNT_WITH_TOTAL = re.compile(r"\| *(\d+)/(\d+) \[")
COUNT_WITHOUT_TOTAL = re.compile(r"(?<![/\d])([1-9]\d*)scenario \[")  # tqdm's "5scenario [00:01, ...]"


def _bar(err: str, label: str) -> list[tuple[int, int]]:
    """(count, total) of every render of the bar labelled ``label`` on stderr; none may count without a total."""
    renders = [r for r in re.split(r"[\r\n]", err) if r.startswith(f"{label}:")]
    assert renders, err
    assert not [r for r in renders if COUNT_WITHOUT_TOTAL.search(r)], renders
    assert all(COUNT_WITH_TOTAL.search(r) for r in renders), renders  # nor "0scenario" before it (until 2026-12-08)
    return [(int(m[1]), int(m[2])) for m in map(COUNT_WITH_TOTAL.search, renders) if m]


def _finished_at_its_total(err: str, label: str, total: int) -> None:
    """The bar had ``total`` from before its first scenario, never passed it, and ended there."""
    counts = _bar(err, label)
    assert counts[0] == (0, total), counts
    assert {t for _, t in counts} == {total}, counts
    assert counts[-1] == (total, total) and all(n <= total for n, _ in counts), counts


def _rows(path) -> list[dict]:
    with open(path) as handle:
        return list(csv.DictReader(handle))


@pytest.mark.slow  # over ~2.5 s on 2 cores (about 5 s)
def test_whatif_lift_counts_its_scenarios_and_names_the_lowest_pressure_that_lifts_the_payload(tmp_path, capsys):
    """228.8 kPa sits just under the lift limit of 13.5 g on the thesis plant (228.84 kPa, measured), though
    the bisected lift there reads 13.503 g: the answer must come from runs of the payload itself."""
    from twin.experiments.whatifs.lift import PAYLOAD_COLUMN, THESIS_PAYLOAD, _lifts

    out = tmp_path / "lift"
    assert main(["whatif", "lift", "--pressures", "200,228.8,228.9,300", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    rows = _rows(out / "lift.csv")
    pressures = [float(r["supply_kpa"]) for r in rows]
    assert pressures == [200.0, 228.8, 228.9, 300.0]

    # the total: the bare link and the payload at every pressure, then the bisection of those that lift the
    # link, halving 0 .. 1.5 x closed form + 1 mg until within 0.5 % of the closed form
    bisected = [float(r["lift_closed_form_g"]) for r in rows if float(r["lift_simulated_g"]) > 0]
    steps = max(math.ceil(math.log2((1.5 * c + 1.0) / (0.005 * c))) for c in bisected)
    _finished_at_its_total(captured.err, "lift", 2 * len(rows) + len(bisected) * steps)

    lifted = [r[PAYLOAD_COLUMN] == "true" for r in rows]
    lowest = pressures[lifted.index(True)]
    answer = (out / "lift.txt").read_text()
    assert f"13.5 g is lifted from {lowest:g} kPa, the lowest pressure tried that lifts it" in answer, answer
    below = pressures[lifted.index(True) - 1]
    assert f"({below:g} kPa does not)" in answer and answer.strip() in captured.out
    # and the rows are right: the payload itself, run again, is lifted at the named pressure and not below it
    again = _lifts(np.full(2, THESIS_PAYLOAD), np.array([below, lowest]) * 1e3, "thesis")
    assert list(again) == [False, True]
    assert lowest == 228.9  # where the old answer, read off the bisected lift, said 228.8


def test_whatif_lift_says_so_when_no_pressure_tried_lifts_the_payload(tmp_path, capsys):
    out = tmp_path / "lift"
    assert main(["whatif", "lift", "--pressures", "100,150", "--out", str(out)]) == 0
    assert "13.5 g is not lifted at any pressure tried (up to 150 kPa)." in (out / "lift.txt").read_text()
    assert [r["lifts_13.5g"] for r in _rows(out / "lift.csv")] == ["false", "false"]
    _finished_at_its_total(capsys.readouterr().err, "lift", 4)  # nothing lifts the bare link: no bisection


@pytest.mark.parametrize("study, args, total", [
    ("pwm", ["--periods", "8,16", "--seeds", "1"], 2 * 2 * 2 * 1),  # controllers x trajectories x periods x seeds
    ("payload", ["--payloads", "0", "--seeds", "1", "--workers", "1"], 2 * 1 * 2 * 1),  # x orientations
    pytest.param("supply", ["--seeds", "1"], 3 * 2 * 2 * 1, marks=pytest.mark.slow),  # supply models x ...
    pytest.param("gear-load", [], 3 * 4 * 2 * 2, marks=pytest.mark.slow),  # x trajectories x payloads x kPa
])
def test_every_whatif_counts_its_scenarios_against_a_total(tmp_path, capsys, study, args, total):
    assert main(["whatif", study, *args, "--out", str(tmp_path / study)]) == 0
    _finished_at_its_total(capsys.readouterr().err, study, total)


def test_a_resumed_whatif_payload_counts_what_was_done(tmp_path, capsys):
    argv = ["whatif", "payload", "--payloads", "0", "--seeds", "1", "--workers", "1", "--out", str(tmp_path / "p")]
    assert main(argv) == 0
    capsys.readouterr()
    assert main(argv) == 0  # every run is in payload-runs already
    counts = _bar(capsys.readouterr().err, "payload")
    assert counts[0] == (0, 4) and counts[-1] == (4, 4)


def test_bench_shows_one_bar_with_its_total_and_labels_each_stage(monkeypatch, capsys):
    """The measurements are stubbed to be instant (the sweep reports its scenarios as run_sweep does);
    the bar is the real one, on stderr."""
    from types import SimpleNamespace

    from tqdm.std import tqdm

    import twin.batch.sweep
    from twin.experiments import bench

    monkeypatch.setattr(bench, "run_many", lambda scenarios, **k: [SimpleNamespace(trace=SimpleNamespace(time=[0] * 3000))])
    monkeypatch.setattr(bench, "compile_joint", lambda: SimpleNamespace(model=None, timestep=1e-3))
    monkeypatch.setattr(bench, "mujoco", SimpleNamespace(MjData=lambda model: None, mj_step=lambda *a, **k: None))
    monkeypatch.setattr(bench, "_env_cost", lambda trajectory, duration, done: bench._fastest(lambda: None,
                                                                                             bench.REPEATS, done))

    def run_sweep(points, *, out, workers, progress):
        for start in range(0, len(points), 64):
            progress(len(points[start:start + 64]))

    monkeypatch.setattr(twin.batch.sweep, "run_sweep", run_sweep)
    assert main(["bench", "--batch", "3", "--workers", "2"]) == 0
    out, err = capsys.readouterr()
    assert "bare mj_step:" in out
    total = bench.planned_seconds(batch_size=3, workers=2)
    # 3 s T1 runs: a warm-up, 5 x 5 bare loops of 30 s, 4 x (single + 3-run batch + environment), 4 x 2 sweeps
    assert total == pytest.approx(3 + 25 * 30 + 4 * 3 * 5 + 8 * 1260)
    renders = [r for r in re.split(r"[\r\n]", err) if r.startswith("bench")]
    shown = f"/{tqdm.format_sizeof(total)} ["
    assert renders and all(shown in r for r in renders), renders
    assert "100%" in renders[-1] and f"{tqdm.format_sizeof(total)}{shown}" in renders[-1], renders[-1]
    stages = list(dict.fromkeys(re.findall(r"bench (\[\d/4\])", err)))
    assert stages == ["[1/4]", "[2/4]", "[3/4]", "[4/4]"]


def test_a_resumed_whatif_draws_what_was_done_before_its_first_batch(tmp_path, capsys):
    """run_sweep counts what a resumed run had done in one call, at once, and tqdm draws an update only after its
    mininterval: so until the first batch ended a resumed study showed 0 of N (found 2026-11-27). The sweep, the
    robustness study and the payload what-if now count through sweep.counting, which redraws at each count."""
    out = str(tmp_path / "p")
    assert main(["whatif", "payload", "--payloads", "0", "--seeds", "1", "--workers", "1", "--out", out]) == 0
    capsys.readouterr()
    assert main(["whatif", "payload", "--payloads", "0,6.5", "--seeds", "1", "--workers", "1", "--out", out]) == 0
    counts = _bar(capsys.readouterr().err, "payload")
    assert counts[0] == (0, 8) and counts[1] == (4, 8) and counts[-1] == (8, 8), counts
