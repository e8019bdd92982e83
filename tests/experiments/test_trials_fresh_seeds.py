"""The fresh-seed trials (examples/trial_fresh_seed_costs/, trial_band_on_fresh_seeds): their kept costs, bands,
splits and readings on seeds no step of the calibration ran are what docs/investigations.md and docs/prediction.md
quote, they run again to the last bit, and they refuse bad input."""

from __future__ import annotations

import json
import re

import pytest
from trial_scripts import ROOT, StubEvaluator, doc_text, load_trial

# The fresh-seed trial's kept runs: on seeds 40-79 (stop 49, its reading written before it ran), then on 40-119
# (decided after seeing that one, taking its costs on 40-79 and running 80-119), by the number of their seed sets.
FRESH = {"costs": 4, "costs_40-119": 8}


def _fresh(name: str) -> tuple[dict, str]:
    folder = ROOT / "examples" / "trial_fresh_seed_costs"
    return json.loads((folder / f"{name}.json").read_text()), (folder / f"{name}.txt").read_text()


@pytest.mark.parametrize("name", list(FRESH))
def test_the_fresh_seed_trials_kept_costs_are_every_kept_set_read_by_its_fixed_rule(name):
    """The kept fresh-seed costs: complete, on seeds from 40 in sets of ten, the committed file's 13 members (member
    0 the committed preset) then every kept profile result in the trial's order, each set's mean, paired difference to
    member 0, its standard error and reading recomputed from its costs, and the printed text the kept numbers. The
    longer run's costs on 40-79 are the first run's."""
    import math

    from twin.plants.as_built import (
        CALIBRATION_FILE,
        calibration_cost_line,
        ensemble_costs,
        ensemble_values,
        preset_digest,
    )

    trial = load_trial("trial_fresh_seed_costs")
    kept, printed = _fresh(name)
    count = FRESH[name]
    members = ensemble_values(CALIBRATION_FILE)
    profile_results = [r for path in trial.kept_files() for r in json.loads(path.read_text())["results"]]
    assert kept["complete"] and kept["preset"] == preset_digest(CALIBRATION_FILE) == "13aadbb61885"
    assert kept["noise"] == calibration_cost_line(CALIBRATION_FILE)[1]
    assert kept["fresh_seed_sets"] == [list(range(s, s + 10)) for s in range(40, 40 + 10 * count, 10)]
    if count > 4:
        assert kept["reused"] == "examples/trial_fresh_seed_costs/costs.json"
        assert [s["fresh_costs"][:4] for s in kept["sets"]] == [s["fresh_costs"] for s in _fresh("costs")[0]["sets"]]
    sets = kept["sets"]
    assert len(sets) == len(members) + len(profile_results) == 13 + 34
    assert [s["values"] for s in sets] == members + [r["values"] for r in profile_results]
    assert [s["kept_cost"] for s in sets[len(members):]] == [r["cost"] for r in profile_results]
    assert [s["kept_cost"] for s in sets[:len(members)]] == ensemble_costs(CALIBRATION_FILE)
    base = sets[0]["fresh_costs"]
    assert sets[0]["reading"] == "the best" and sets[0]["kept_cost"] == calibration_cost_line(CALIBRATION_FILE)[0]
    for s in sets:
        differences = [a - b for a, b in zip(s["fresh_costs"], base, strict=True)]
        mean = sum(differences) / count
        error = math.sqrt(sum((d - mean) ** 2 for d in differences) / (count - 1) / count)
        assert len(s["fresh_costs"]) == count
        assert s["mean"] == pytest.approx(sum(s["fresh_costs"]) / count, abs=1e-12)
        assert s["difference"] == pytest.approx(mean, abs=1e-12) and s["standard_error"] == pytest.approx(error)
        if s is not sets[0]:
            assert s["reading"] == trial.reading(s["difference"], s["standard_error"], kept["noise"])
    lines = [line for line in printed.splitlines() if line.startswith("  ")]
    assert [line.split(":")[0].strip() for line in lines] == [s["set"] for s in sets]
    assert [re.search(r"mean (\d\.\d{4}); ([+-]\d\.\d{4}) ± (\d\.\d{4}): (.+)$", line).groups() for line in lines] == [
        (f"{s['mean']:.4f}", f"{s['difference']:+.4f}", f"{s['standard_error']:.4f}", s["reading"]) for s in sets]


@pytest.mark.parametrize(("readings", "said"), [
    ((0.13, 0.05, 0.1229), "worse"),  # over two standard errors and the noise
    ((0.13, 0.07, 0.1229), "not told apart"),  # over the noise, not two standard errors
    ((0.11, 0.01, 0.1229), "not told apart"),  # over two standard errors, not the noise
    ((-0.13, 0.05, 0.1229), "better"),
    ((-0.11, 0.01, 0.1229), "not told apart"),
])
def test_the_fresh_seed_trials_reading_needs_both_the_noise_and_two_standard_errors(readings, said):
    assert load_trial("trial_fresh_seed_costs").reading(*readings) == said


@pytest.mark.parametrize(("args", "reuse", "said"), [
    ([], None, "stopped/run.json: a stopped profile run (not complete): run it whole first"),
    (["--workers", "0"], None, "--workers 0: at least 1"),
    (["--out", "THERE"], None, "is there already: give another --out"),
    (["--seed-sets", "1"], None, "--seed-sets 1: from 2 (a standard error needs two) to 16"),
    (["--reuse", "REUSE"], "{", "cannot read it as JSON (JSONDecodeError)"),
    (["--reuse", "REUSE"], '{"sets": [], "complete": false, "fresh_seed_sets": []}',
     "not a complete kept fresh-seed trial file"),
    (["--reuse", "REUSE"], '{"sets": [], "complete": true, "fresh_seed_sets": [], "preset": "6bb9e9258023"}',
     "run on preset 6bb9e9258023, not the committed 13aadbb61885"),
    (["--reuse", "REUSE", "--seed-sets", "2"], '{"sets": [], "complete": true, "preset": "13aadbb61885", '
     '"fresh_seed_sets": [[50, 51, 52, 53, 54, 55, 56, 57, 58, 59]]}', "its seed sets are not the first of this run's 2"),
])
def test_the_fresh_seed_trial_refuses_bad_input_before_it_runs(capsys, monkeypatch, tmp_path, args, reuse, said):
    """In one line, before any run or file: a kept profile file that is not a complete run, too few seed sets, and a
    --reuse file that is not a complete kept fresh-seed run on the committed preset and this run's first seed sets."""
    from twin.experiments import calibrate

    def no_run(*args, **kwargs):
        raise AssertionError("the trial started its runs")

    trial = load_trial("trial_fresh_seed_costs")
    monkeypatch.setattr(calibrate, "Evaluator", no_run)
    kept = tmp_path / "kept"
    if not args:  # the profile files the trial reads, one of them a stopped run
        monkeypatch.setattr(trial, "KEPT", kept)
        (kept / "stopped").mkdir(parents=True)
        (kept / "stopped" / "run.json").write_text('{"results": [], "complete": false}')
    if reuse is not None:
        (tmp_path / "reuse.json").write_text(reuse)
    (tmp_path / "there.json").write_text("kept")
    argv = [{"REUSE": str(tmp_path / "reuse.json"), "THERE": str(tmp_path / "there.json")}.get(a, a) for a in args]
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(SystemExit) as stop:
        trial.main([*argv, "--out", str(tmp_path / "costs.json")] if "--out" not in args else argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and said in err and "Traceback" not in err
    assert len(err.strip().splitlines()[-1]) < 200 and sorted(tmp_path.rglob("*")) == before


@pytest.mark.slow  # about 80 s on 2 cores: two parameter sets on the fit's 21 cells x 80 seeds
def test_the_fresh_seed_trials_kept_costs_run_again_to_the_last_bit():
    """Member 0's fresh costs and the last kept set's on seeds 40-119 (as the longer run kept them), run again, to the
    last bit."""
    from twin.experiments import calibrate

    trial = load_trial("trial_fresh_seed_costs")
    kept, _ = _fresh("costs_40-119")
    with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=2) as evaluator:
        for s in (kept["sets"][0], kept["sets"][-1]):
            assert trial.fresh_costs(evaluator, s["values"], 8) == s["fresh_costs"], s["set"]


def test_the_fresh_seed_trial_prints_the_kept_roughness(capsys):
    """--roughness (no runs) prints the kept roughness.txt, and docs/investigations.md quotes its first and last bins'
    medians and the first's 90th percentile."""
    load_trial("trial_fresh_seed_costs").main(["--roughness"])
    printed = capsys.readouterr().out
    assert printed == (ROOT / "examples" / "trial_fresh_seed_costs" / "roughness.txt").read_text()
    bins = re.findall(r"of the box: \d+ pairs, median (\d\.\d{3}), 90th percentile (\d\.\d{3})", printed)
    text = doc_text("investigations.md")
    assert f"differ in cost by {bins[0][0]} (median; 90th percentile {bins[0][1]})" in text
    assert f"10-20 % apart ({bins[-1][0]};" in text


def test_the_band_trial_prints_what_it_kept(capsys):
    """It runs nothing: its output on the kept fresh-seed run (seeds 40-119) is band.txt as kept, and it says how
    many distinct sets each reading keeps: 36 not shown worse than member 0, as docs/investigations.md's stop-49
    table counts them (13 members, 11 refits under the cut and 12 over it not read worse on 40-119), and 15 not
    shown worse than member 4, the lowest on those seeds, by the rule recomputed here from the kept costs."""
    import math

    import numpy as np

    load_trial("trial_band_on_fresh_seeds").main([])
    printed = capsys.readouterr().out
    assert printed == (ROOT / "examples" / "trial_fresh_seed_costs" / "band.txt").read_text()
    assert ("44 distinct sets; against member 0 (the best on the fit's seeds) 36 not shown worse, 29 not behind, 15 not"
            " shown worse than member 4 (the lowest on these seeds") in printed.splitlines()[0]
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    table = text[text.index("| sets (distinct) | on seeds 40-79"):].split("\n\n")[0].splitlines()[2:]
    counts = [re.findall(r"(\d+) / (\d+) / (\d+)", row)[1] for row in table]  # on seeds 40-119
    assert len(counts) == 3 and 1 + sum(int(told) + int(better) for _, told, better in counts) == 36  # 1: the best
    costs, _ = _fresh("costs_40-119")
    distinct = {json.dumps(s["values"], sort_keys=True): s for s in reversed(costs["sets"])}.values()
    lowest = min(distinct, key=lambda s: sum(s["fresh_costs"]))
    assert lowest["set"] == "member 4"
    near = 0
    for s in distinct:
        d = np.subtract(s["fresh_costs"], lowest["fresh_costs"])
        error = d.std(ddof=1) / math.sqrt(len(d)) if s is not lowest else 0.0
        near += not (d.mean() > 2 * error and d.mean() > costs["noise"])
    assert near == 15


def test_the_band_trials_split_prints_what_it_kept_and_its_overlap_recomputed(capsys):
    """--split runs nothing: its output on the kept run is band_split.txt as kept (band.txt first), and its overlaps,
    references and counts of sets kept in every draw are recomputed here from the kept costs for draws of four, two
    and one seed sets, by the rule written out again."""
    import itertools
    import math

    import numpy as np

    load_trial("trial_band_on_fresh_seeds").main(["--split"])
    printed = capsys.readouterr().out
    kept = (ROOT / "examples" / "trial_fresh_seed_costs" / "band_split.txt").read_text()
    assert printed == kept
    assert kept.startswith((ROOT / "examples" / "trial_fresh_seed_costs" / "band.txt").read_text())
    costs, _ = _fresh("costs_40-119")
    distinct = {json.dumps(s["values"], sort_keys=True): s for s in reversed(costs["sets"])}
    table = np.array([s["fresh_costs"] for s in distinct.values()])  # (sets, 8)
    noise = costs["noise"]

    def kept_on(draw):
        c = table[:, list(draw)]
        best = int(np.argmin(c.mean(axis=1)))
        if len(draw) == 1:
            return best, {i for i in range(len(c)) if c[i, 0] <= c[best, 0] + noise}
        d = c - c[best]
        error = d.std(axis=1, ddof=1) / math.sqrt(len(draw))
        return best, {i for i in range(len(c)) if i == best or not (d[i].mean() > 2 * error[i] and d[i].mean() > noise)}

    expected = {4: ("0.52", "0.38", "0.71", 23, 35, (4, 20, 20)), 2: ("0.47", "0.15", "0.80", 55, 210, (3, 12, 29)),
                1: ("0.34", "0.10", "0.65", 3, 28, (2, 18, 24))}
    for size, (share, low, high, same, pairs, (every, none, some)) in expected.items():
        chosen = list(itertools.combinations(range(8), size))
        disjoint = [(a, b) for i, a in enumerate(chosen) for b in chosen[i + 1:] if not set(a) & set(b)]
        assert len(disjoint) == pairs
        found = [(kept_on(a), kept_on(b)) for a, b in disjoint]
        overlap = [len(x & y) / len(x | y) for (_, x), (_, y) in found]
        assert f"{np.median(overlap):.2f}" == share and f"{min(overlap):.2f}" == low and f"{max(overlap):.2f}" == high
        assert sum(ra == rb for (ra, _), (rb, _) in found) == same
        draws = {d: kept_on(d)[1] for pair in disjoint for d in pair}
        times = [sum(i in k for k in draws.values()) for i in range(len(table))]
        assert (times.count(len(draws)), times.count(0), sum(0 < t < len(draws) for t in times)) == (every, none, some)
        line = next(x for x in kept.splitlines() if x.startswith(f"  draws of {size} seed set"))
        assert (f"of the 44, {every} kept in every draw, {none} in none, {some} in some; two disjoint draws share "
                f"{share} of the sets either keeps (median; {low}-{high}); the same reference in {same} of {pairs}") in line


def test_the_docs_quote_the_band_trials_split():
    """The stop-51 section's table, counts and 13.5 g vertical numbers are band_split.txt's, and so are
    prediction.md's."""
    printed = (ROOT / "examples" / "trial_fresh_seed_costs" / "band_split.txt").read_text()
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    section = text[text.index("## Would re-ranking on fresh seeds settle"):].split("\n## ")[0]
    flat = " ".join(section.split())
    rows = re.findall(r"^  draws of (\d) seed sets? \((\d+) seeds; \d+ draws, (\d+) disjoint pairs; kept: .*?\): kept "
                      r"(\d+)-(\d+) sets \(median ([\d.]+)\); of the 44, (\d+) kept in every draw, (\d+) in none, (\d+) in "
                      r"some; two disjoint draws share ([\d.]+) of the sets either keeps \(median; ([\d.]+)-([\d.]+)\); the "
                      r"same reference in (\d+) of", printed, re.M)
    assert [r[0] for r in rows] == ["4", "2", "1"]
    for _, seeds, pairs, low, high, median, every, none, some, share, least, most, same in rows:
        assert f"| {seeds} | " in section
        assert (f"| {low}-{high} (median {median}) | {every} / {none} / {some} | {share} ({least}-{most}) | {same} of "
                f"{pairs} |") in section, seeds
    assert f"{rows[0][8]} of the 44 sets are kept by some draws of 40" in flat
    assert "references: member 4 58, member 12 12" in printed and "(member 4 in 58 of the 70 draws" in flat
    block = printed[printed.index("  draws of 4"):printed.index("  draws of 2")]
    moving = re.search(r"the highest in (\d+) of 12 cells, the lowest in (\d+)", block).groups()
    assert f"in {moving[0]} of the 12 cells, and their lowest in {moving[1]}" in flat
    cells = re.findall(r"^    (FF \+ PVA|sliding mode) +([\d.]+) g (\w+) *: lowest ([\d.]+)-([\d.]+) \(moves ([\d.]+)\), "
                       r"highest ([\d.]+)-([\d.]+) \(moves ([\d.]+)\) over the draws, the registered band ([\d.]+) wide; "
                       r"the highest is (.+)'s in (\d+) of 70; without it ([\d.]+)-([\d.]+)$", block, re.M)
    assert len(cells) == 12
    others = [c for c in cells if not (c[1] == "13.5" and c[2] == "vertical")]
    assert f"(the highest {min(c[8] for c in others)}-{max(c[8] for c in others)}, the lowest " \
        f"{min(c[5] for c in others)}-{max(c[5] for c in others)})" in flat
    assert "(0.06-0.18 wide there)" in flat and (min(c[9] for c in others), max(c[9] for c in others)) == ("0.06", "0.18")
    (ff, smc) = [c for c in cells if c[1] == "13.5" and c[2] == "vertical"]
    assert ff[10] == smc[10] == "stiction.json stiction 2.1" and ff[11] == smc[11]
    assert f"highest is {ff[6]}-{ff[7]} deg (FF + PVA) and {smc[6]}-{smc[7]} (sliding mode)" in flat
    assert f"stop 47's breakaway refit at 2.1 N in {ff[11]} of the 70" in flat
    assert f"Without it the highest is still {ff[12]}-{ff[13]} and {smc[12]}-{smc[13]}" in flat
    assert f"registered band ({ff[9]} and {smc[9]} wide)" in flat
    assert f"The lowest moves less: {ff[3]}-{ff[4]} and {smc[3]}-{smc[4]}." in flat
    prediction = doc_text("prediction.md")
    assert f"about half the same sets ({rows[0][9]}, median), and today's cut on ten seeds a third ({rows[2][9]})" \
        in prediction
    assert f"by more than the registered band is wide in {moving[0]} of the 12 cells" in prediction
    assert (f"tops run {ff[6]}-{ff[7]} / {smc[6]}-{smc[7]} deg, set in {ff[11]} of 70 draws by the one set that "
            f"stalls, and {ff[12]}-{ff[13]} / {smc[12]}-{smc[13]} without it") in prediction


def test_the_band_trials_split_says_so_when_only_the_highest_set_is_ever_kept():
    """A set far below the rest is every draw's reference and its only kept set: no range without it, said in words."""
    from twin.plants.as_built import CALIBRATION_FILE, ensemble_values

    trial = load_trial("trial_band_on_fresh_seeds")
    low, high = ensemble_values(CALIBRATION_FILE)[:2]  # two parameter sets the fit's own choice can tell apart
    sets = [{"set": "low", "values": low, "fresh_costs": [0.1, 0.11, 0.12, 0.1]},
            {"set": "high", "values": high, "fresh_costs": [2.0, 2.1, 2.2, 2.0]}]
    t3 = {"low": [1.0] * 12, "high": [2.0] * 12}
    lines = trial.split_test(sets, t3, 0.1, [[40], [41], [42], [43]], [0.5] * 12)
    cells = [line for line in lines if line.startswith("    ") and " g " in line]
    assert len(cells) == 24  # four seed sets: draws of two (six draws) and of one (four); none of four
    assert all(line.endswith(f"the highest is low's in {n} of {n}; without it no set is kept")
               for line, n in zip(cells, [6] * 12 + [4] * 12, strict=True))
    assert "of the 2, 1 kept in every draw, 1 in none, 0 in some" in lines[0]


def test_the_band_trials_draws_pair_each_two_disjoint_draws_once():
    trial = load_trial("trial_band_on_fresh_seeds")
    assert trial.draws(4, 2) == [((0, 1), (2, 3)), ((0, 2), (1, 3)), ((0, 3), (1, 2))]
    assert trial.draws(3, 2) == []
    assert len(trial.draws(8, 4)) == 35 and len(trial.draws(8, 2)) == 210 and len(trial.draws(8, 1)) == 28


@pytest.mark.slow  # about 70 s on 2 cores: 36 parameter sets on T3's 12 cells x 5 seeds
def test_the_band_trials_stalls_run_again_to_what_it_kept(capsys):
    """--stalls runs the 36 sets not shown worse again on T3: its output is band_stalls.txt as kept, every mean is the
    one on record, and only stop 47's breakaway refit at 2.1 N stalls (in the 13.5 g vertical cells)."""
    load_trial("trial_band_on_fresh_seeds").main(["--stalls"])
    printed = capsys.readouterr().out
    assert printed == (ROOT / "examples" / "trial_fresh_seed_costs" / "band_stalls.txt").read_text()
    assert "the range over the 35 sets with no stall in any cell; means as on record: all" in printed
    stalls = [line for line in printed.splitlines() if re.search(r": [1-9]\d* of 180 runs", line)]
    assert len(stalls) == 2 and all("13.5 g vertical" in line and "(stiction.json stiction 2.1 (" in line
                                    for line in stalls)


def test_investigations_md_quotes_the_band_trials_kept_output():
    """The stop-50 section's table rows (the registered band, the members' range and the ranges not shown worse than
    member 0 and than member 4), its summary numbers and the stalls are band.txt's and band_stalls.txt's, and so are
    prediction.md's."""
    printed = (ROOT / "examples" / "trial_fresh_seed_costs" / "band.txt").read_text()
    stalls = (ROOT / "examples" / "trial_fresh_seed_costs" / "band_stalls.txt").read_text()
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    section = text[text.index("## How much wider the T3 spread is"):]
    section = section[:section.index("\n## ")].replace("**", "")
    flat = " ".join(section.split())
    cells = re.findall(r"^  (FF \+ PVA|sliding mode) +([\d.]+) g (\w+) *: preset [\d.]+, band ([\d.-]+), members "
                       r"([\d.-]+)\n    not shown worse: ([\d.-]+), ([\d.]+)x .*\n.*\n    not shown worse than member 4: "
                       r"([\d.-]+), ", printed, flags=re.M)
    assert len(cells) == 12
    table = [f"| {g} g {o}, {c} | {band} | {members} | {worse} | {four} |"
             for c, g, o, band, members, worse, _, four in cells]
    assert len([row for row in table if row in section]) == 4 and section.count("\n| ") == 1 + 4  # header, 4 rows
    by = {(c, g, o): times for c, g, o, *_, times, _ in cells}
    assert f"FF + PVA's 13.5 g vertical cell ({by['FF + PVA', '13.5', 'vertical']}x)" in flat
    assert (f"sliding mode's 0 g vertical ({by['sliding mode', '0', 'vertical']}x) and 13.5 g vertical "
            f"({by['sliding mode', '13.5', 'vertical']}x)") in flat
    summary = {line.split(":")[0]: line for line in printed.splitlines() if not line.startswith(" ")}
    median = {name: re.search(r"its range ([\d.]+)x the members' \(median of the cells; ([\d.]+)x-([\d.]+)x\)",
                              line).groups() for name, line in summary.items() if "its range" in line}
    zero, behind, four = (median[k] for k in ("not shown worse", "not behind", "not shown worse than member 4"))
    assert f"is {zero[0]} times the members' (median of the 12 cells, range against range; {zero[1]}x to {zero[2]}x)" in flat
    assert f'"Not behind" hardly narrows it ({behind[0]}x; {behind[1]}x to {behind[2]}x)' in flat
    assert f"about the members' range ({four[0]}x; {four[1]}x to {four[2]}x)" in flat
    leads = {k: re.search(r"on (\d+) of (\d+) sets, FF \+ PVA ahead in one or more on (\d+)", line).groups()
             for k, line in summary.items() if "its range" in line}
    assert leads["not shown worse"] == ("27", "36", "9") and leads["not behind"][1:] == ("29", "7")
    assert leads["not shown worse than member 4"][1:] == ("15", "1")
    assert ("on 27 of the 36 sets not shown worse than member 0; FF + PVA is ahead in one or more on 9 (on 7 of the 29 "
            "not behind, on 1 of the 15 not shown worse than member 4)") in flat
    assert stalls.startswith(printed)  # --stalls prints the same, then the stalls
    counted = dict(re.findall(r"^  (FF \+ PVA|sliding mode) +13\.5 g vertical *: (\d+) of 180 runs", stalls, flags=re.M))
    assert sum(int(n) for n in re.findall(r": (\d+) of 180 runs", stalls)) == int(counted["FF + PVA"]) + int(
        counted["sliding mode"])  # no stall elsewhere
    assert (f"it stalls in {counted['FF + PVA']} of its 5 FF + PVA runs and {counted['sliding mode']} of its 5 "
            "sliding-mode runs; no other of the 36 stalls in any cell") in flat
    steady = dict(re.findall(r"^  (FF \+ PVA|sliding mode) +13\.5 g vertical *: .*with no stall ([\d.-]+), ", stalls,
                             flags=re.M))
    assert f"13.5 g vertical cells span {steady['FF + PVA']} and {steady['sliding mode']} deg" in flat
    prediction = doc_text("prediction.md")
    assert (f"it stalls in {int(counted['FF + PVA']) + int(counted['sliding mode'])} of its 10 runs of the 13.5 g "
            "vertical cells") in prediction
    v0 = [(c[5], c[4], c[7]) for c in cells if c[1:3] == ("13.5", "vertical")]  # FF + PVA, then sliding mode
    assert (f"each T3 cell's range is {zero[0]} times the members' (median of the 12 cells; {zero[1]}x to {zero[2]}x)"
            f", widest at FF + PVA's 13.5 g vertical cell ({v0[0][0]} deg against the members' {v0[0][1]})"
            ) in prediction
    assert f"({four[0]}x; 13.5 g vertical {v0[0][2]} / {v0[1][2]})" in prediction


def test_the_band_trials_sets_are_the_registered_prediction_and_the_kept_profile_results():
    """What it reads agrees with what it is read beside: the registered band and preset recomputed from the
    registered members' means; members 1 and 2 (the load friction's 0.05 and 0.45 N/N refits, stop 46) have the T3
    means their kept profile results hold, to the members' file's twelve digits."""
    import argparse

    import numpy as np

    trial = load_trial("trial_band_on_fresh_seeds")
    rows, members = trial.registered()
    kept = trial.kept_t3(argparse.ArgumentParser())
    assert len(members) == 13 and len(rows) == 12
    for i, row in enumerate(rows):
        column = [m[i] for m in members.values()]
        assert float(row["twin_mean"]) == members[0][i]
        for q in (10, 50, 90):
            assert float(row[f"band_p{q}"]) == pytest.approx(float(np.percentile(column, q)), rel=1e-10, abs=0)
    assert members[1] == pytest.approx(kept["load_friction.json load_friction 0.05"][1], rel=1e-11, abs=0)
    assert members[2] == pytest.approx(kept["load_friction.json load_friction 0.45"][1], rel=1e-11, abs=0)


def test_the_band_trial_refuses_no_workers(capsys):
    with pytest.raises(SystemExit) as stop:
        load_trial("trial_band_on_fresh_seeds").main(["--stalls", "--workers", "0"])
    assert stop.value.code == 2 and "--workers 0: at least 1" in capsys.readouterr().err


@pytest.mark.parametrize(("text", "said"), [
    (None, "cannot read it as JSON (FileNotFoundError)"),
    ('{"sets": [], "complete": false}', "not a complete kept fresh-seed trial file"),
    ("NO_SEED_SETS", "not a complete kept fresh-seed trial file"),
    ("ONE_SEED_SET", "not a complete kept fresh-seed trial file"),
    ("NULL_DIFFERENCE", "not a complete kept fresh-seed trial file"),
    ("NUMBER_LABEL", "not a complete kept fresh-seed trial file"),
    ("OTHER_PRESET", "run on preset 6bb9e9258023, not the committed 13aadbb61885"),
    ("OTHER_MEMBER", "its members are not the committed file's"),
    ("OTHER_PROFILE_VALUES", "stiction.json stiction 2.1 has other values than its kept profile result"),
    ("UNKNOWN_SET", "no T3 cells on record for nowhere.json load_friction 0.3"),
])
def test_the_band_trial_refuses_a_costs_file_it_cannot_read_beside_the_prediction(capsys, tmp_path, text, said):
    """In one line, no traceback: a costs file that is not a complete kept fresh-seed run (keys missing or of the
    wrong kind), run on another preset, with other members, with a profile set's values not the kept ones, or with a
    set whose T3 cells are not on record."""
    costs, _ = _fresh("costs_40-119")
    by = {s["set"]: s for s in costs["sets"]}
    if text == "NO_SEED_SETS":
        del costs["fresh_seed_sets"]
    elif text == "ONE_SEED_SET":  # no standard error to read a difference by
        costs["fresh_seed_sets"] = costs["fresh_seed_sets"][:1]
        for row in costs["sets"]:
            row["fresh_costs"] = row["fresh_costs"][:1]
    elif text == "NULL_DIFFERENCE":
        costs["sets"][5]["difference"] = None
    elif text == "NUMBER_LABEL":
        costs["sets"][5]["set"] = 5
    elif text == "OTHER_PRESET":
        costs["preset"] = "6bb9e9258023"
    elif text == "OTHER_MEMBER":
        costs["sets"][3]["values"] = {**costs["sets"][3]["values"], "load_friction": 0.31}
    elif text == "OTHER_PROFILE_VALUES":
        row = by["stiction.json stiction 2.1"]
        row["values"] = {**row["values"], "load_friction": 0.31}
    elif text == "UNKNOWN_SET":
        costs["sets"].append({**costs["sets"][-1], "set": "nowhere.json load_friction 0.3"})
    path = tmp_path / "costs.json"
    if text is not None:
        path.write_text(text if text.startswith("{") else json.dumps(costs))
    with pytest.raises(SystemExit) as stop:
        load_trial("trial_band_on_fresh_seeds").main(["--costs", str(path)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and f"--costs {path}: {said}" in err and "Traceback" not in err


def test_the_band_trial_refuses_a_kept_profile_file_it_cannot_read(capsys, monkeypatch, tmp_path):
    """A kept profile file that is not a complete run: one line naming it, as the other trials that read them say."""
    trial = load_trial("trial_band_on_fresh_seeds")
    folder = tmp_path / "kept"
    folder.mkdir()
    (folder / "broken.json").write_text("{")
    monkeypatch.setattr(trial.kept_profiles, "KEPT", folder)
    with pytest.raises(SystemExit) as stop:
        trial.main([])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "broken.json: cannot read it as JSON (JSONDecodeError)" in err
    assert "Traceback" not in err


def test_investigations_md_counts_the_fresh_seed_readings_as_kept():
    """docs/investigations.md's stop-49 table: the distinct sets' readings on 40-79 and on 40-119, by members (but
    member 0, the best), profile refits under the cut on the fit's seeds and those over it, as the kept files give
    them."""
    from twin.plants.as_built import CALIBRATION_FILE, calibration_cost_line

    cut = sum(calibration_cost_line(CALIBRATION_FILE))
    columns = []
    for name in FRESH:
        distinct: dict[tuple, dict] = {}
        for s in _fresh(name)[0]["sets"]:
            distinct.setdefault(tuple(sorted(s["values"].items())), s)
        groups = {"members": [], "under": [], "over": []}
        for s in list(distinct.values())[1:]:
            group = "members" if s["set"].startswith("member") else "under" if s["kept_cost"] <= cut else "over"
            groups[group].append(s["reading"])
        columns.append({g: " / ".join(str(r.count(k)) for k in ("worse", "not told apart", "better"))
                        for g, r in groups.items()})
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    section = text[text.index("## Searches continued where four stopped over the cut"):]
    rows = {line.split(" | ")[0]: line.split(" | ")[1:] for line in section.splitlines()
            if line.startswith("| 1")}
    assert rows["| 13 members (member 0 the best)"][0] == columns[0]["members"]
    assert rows["| 13 members (member 0 the best)"][1].startswith(columns[1]["members"])
    assert rows["| 12 profile refits under the cut"] == [columns[0]["under"], columns[1]["under"] + " |"]
    assert rows["| 19 profile refits over the cut"] == [columns[0]["over"], columns[1]["over"] + " |"]


def test_the_fresh_seed_trial_reuses_a_kept_cost_only_for_the_set_key_and_values(capsys, monkeypatch, tmp_path):
    """--reuse hands a set the kept costs of the row with its label and the same values, and none to a row whose
    values differ or a set the file does not hold; those run every seed set. A set kept twice (here three: two
    members that are also profile results, and a longer search's result that its continued search kept again) runs
    once, and its second row takes the first's costs."""
    from twin.experiments import calibrate

    trial = load_trial("trial_fresh_seed_costs")
    kept, _ = _fresh("costs")
    other = {**kept["sets"][1]["values"], "air_fraction": 0.05}
    rows = [kept["sets"][0], {**kept["sets"][1], "values": other}]  # member 0 as kept; member 1 with other values
    (tmp_path / "reuse.json").write_text(json.dumps({**kept, "sets": rows}))
    given = {}

    def fresh(evaluator, values, count, known):
        given[len(given)] = list(known)
        return list(known) + [float(len(given))] * (count - len(known))  # each run's own costs

    monkeypatch.setattr(calibrate, "Evaluator", StubEvaluator)
    monkeypatch.setattr(trial, "fresh_costs", fresh)
    trial.main(["--seed-sets", "6", "--reuse", str(tmp_path / "reuse.json"), "--out", str(tmp_path / "out.json")])
    capsys.readouterr()
    assert given[0] == kept["sets"][0]["fresh_costs"] and given[1] == [] and given[2] == []
    distinct = {json.dumps(s["values"], sort_keys=True) for s in kept["sets"]}
    assert len(given) == len(distinct) == len(kept["sets"]) - 3 and all(given[i] == [] for i in range(1, len(given)))
    out = json.loads((tmp_path / "out.json").read_text())
    assert out["complete"] and out["reused"] == str(tmp_path / "reuse.json")
    assert out["sets"][0]["fresh_costs"] == kept["sets"][0]["fresh_costs"] + [1.0, 1.0]
    by = {s["set"]: s["fresh_costs"] for s in out["sets"]}
    assert by["load_friction.json load_friction 0.05"] == by["member 1"] == [2.0] * 6
    assert by["load_friction.json load_friction 0.45"] == by["member 2"] == [3.0] * 6
    assert by["continued/stiction_2.10.json stiction 2.1"] == by["longer/stiction_2.10.json stiction 2.1"]
    assert len({tuple(c) for c in by.values()}) == len(distinct)


def test_investigations_md_quotes_the_fresh_seed_numbers_as_kept():
    """The stop-49 section's numbers from the fresh-seed runs: the best's costs, the median and range of the cost's
    rise from seeds 0-9 to 40-119 over the distinct sets, member 4's cost, and the differences it quotes."""
    import statistics

    four, _ = _fresh("costs")
    eight, _ = _fresh("costs_40-119")
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    section = " ".join(text[text.index("## Searches continued where four stopped over the cut"):].split())
    section = section[:section.index(" ## ")]
    best = eight["sets"][0]
    assert f"costs {best['kept_cost']:.3f} there, {four['sets'][0]['mean']:.3f} on 40-79 and {best['mean']:.3f}" in section
    distinct = {tuple(sorted(s["values"].items())): s for s in reversed(eight["sets"])}.values()
    rise = [s["mean"] - s["kept_cost"] for s in distinct]
    assert len(rise) == 44
    assert f"0.17 above the one on 0-9 (median; {min(rise):.2f} to +{max(rise):.2f})" in section
    assert round(statistics.median(rise), 2) == 0.17
    by = {s["set"]: s for s in eight["sets"]}
    by4 = {s["set"]: s for s in four["sets"]}
    assert f"({by['member 4']['mean']:.3f} on 40-119" in section and by["member 4"]["reading"] == "better"

    def pm(s):
        return f"{s['difference']:+.3f} ± {s['standard_error']:.3f}"

    for quoted in (pm(by4["longer/observer_gain_250.json observer_gain 250"]),
                   pm(by["longer/observer_gain_250.json observer_gain 250"]),
                   pm(by["stiction.json stiction 2.1"]), pm(by["longer/stiction_2.10.json stiction 2.1"]),
                   pm(by["longer/load_friction_high.json load_friction 0.6"]),
                   pm(by["continued/load_friction_0.55.json load_friction 0.55"]),
                   pm(by["air_fraction.json air_fraction 0.02"])):
        assert quoted in section, quoted
    assert f"on 40-119 it costs {by['continued/load_friction_0.55.json load_friction 0.55']['mean']:.4f} against " \
        f"the start's {by['longer/load_friction_high.json load_friction 0.55']['mean']:.4f}" in section
