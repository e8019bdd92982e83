"""The profile-likelihood trials (examples/trial_profile_likelihood/, trial_profile_orders): their kept files are
what their text and docs/investigations.md quote, they run again to the last bit, and they refuse bad input."""

from __future__ import annotations

import json
import re

import pytest
from trial_scripts import ROOT, StubEvaluator, load_trial


@pytest.mark.parametrize(("argv", "said"), [
    ([], "give --at VALUE ... (a profile now) or --check FILE (a kept one run again), one of them"),
    (["--at", "0.4", "--check", "x.json"], "one of them"),
    (["--at", "0.4", "0.61"], "--at 0.61: load_friction must lie in its box, 0-0.6"),
    (["--parameter", "air_fraction", "--at", "0.09"], "--at 0.09: air_fraction must lie in its box, 0-0.08"),
    (["--at", "0.4", "--evaluations", "6"], "--evaluations 6: the first simplex alone needs 7"),
    (["--at", "0.4", "--out", "kept.json"], "kept.json is there already: give another --out"),
    (["--at", "0.4", "--out", "nowhere/x.json"], "nowhere is not a folder"),
    (["--parameter", "friction", "--at", "0.4"], "invalid choice: 'friction'"),
    (["--check", "missing.json"], "--check missing.json: cannot read it as JSON (FileNotFoundError)"),
    (["--check", "broken.json"], "--check broken.json: cannot read it as JSON (JSONDecodeError)"),
    (["--check", "kept.json"], "--check kept.json: not a kept profile trial file (no results as the trial writes them)"),
    (["--check", "kept.json", "--out", "y.json"], "--out keeps a profile run now (--at); --check writes nothing"),
    (["--at", "0.4", "--calibration", "missing.json"], "--calibration missing.json: cannot read it as JSON"),
    (["--at", "0.4", "--calibration", "kept.json"], "--calibration kept.json: not a calibration file with an ensemble"),
    (["--at", "0.4", "--out", "x.json"], "x.json.part is there already: give another --out"),
    (["--at", "0.4", "--start", "kept.json", "x"], "--start kept.json x: AT must be a number"),
    (["--at", "0.4", "--start", "missing.json", "0.5"], "--start missing.json: cannot read it as JSON"),
    (["--at", "0.4", "--start", "kept.json", "0.5"], "--start kept.json: no kept result at 0.5"),
    (["--at", "0.4", "--start", "start.json", "0.5", "--out", "new.json"],
     "--start start.json: its result at 0.5 has not the fitted values and a finite cost"),
    (["--at", "0.4", "--start", "start.json", "0.6"], "its result at 0.6 has not the fitted values and a finite cost"),
    (["--at", "0.4", "--start", "start.json", "0.7"], "its result at 0.7 has not the fitted values and a finite cost"),
    (["--at", "0.4", "--start", "start.json", "0.8"], "its result at 0.8 has load_friction outside its box, 0-0.6"),
    (["--at", "0.4", "--start", "start.json", "0.9"], "--start start.json: 2 kept results at 0.9, so which to start"),
    (["--at", "0.4", "--start", "broken.json", "0.5"], "--start broken.json: cannot read it as JSON"),
    (["--at", "0.4", "--start", "null.json", "0.5"], "--start null.json: no kept result at 0.5"),
    (["--check", "kept.json", "--start", "start.json", "0.5"], "--start starts a profile run now (--at)"),
])
def test_the_profile_trial_refuses_bad_input_before_it_runs(capsys, monkeypatch, tmp_path, argv, said):
    """A value outside the parameter's box, a budget under the first simplex, an --out that is there already or in no
    folder or given with --check, --at with --check or neither, a --check, --calibration or --start file that is
    missing, not JSON or not of its kind, and a --start value that is not a number or not kept: one-line errors,
    before any evaluation (a run here fails at once) and with no file written."""
    from twin.experiments import calibrate

    def no_run(*args, **kwargs):
        raise AssertionError("the trial started its runs")

    monkeypatch.setattr(calibrate, "Evaluator", no_run)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "kept.json").write_text("{}")
    (tmp_path / "broken.json").write_text("{")
    (tmp_path / "x.json.part").write_text("")  # a part kept by a run before
    fitted = {"stiction": 1.5, "air_fraction": 0.04, "ccw_coulomb_scale": 1.1, "leak_conductance": 2e-14,
              "load_friction": 0.3, "observer_gain": 400.0, "initial_pressure_fraction": 0.5}
    (tmp_path / "start.json").write_text(json.dumps({"results": [
        {"at": 0.5, "values": {"stiction": 1.5}, "cost": 0.6},  # not every fitted parameter
        {"at": 0.6, "values": {**fitted, "air_fraction": "x"}, "cost": 0.6},  # a value not a number
        {"at": 0.7, "values": fitted, "cost": float("nan")},  # no finite cost
        {"at": 0.8, "values": {**fitted, "load_friction": 0.7}, "cost": 0.6},  # outside the box
        {"at": 0.9, "values": fitted, "cost": 0.6}, {"at": 0.9, "values": fitted, "cost": 0.7}]}))  # two at one value
    (tmp_path / "null.json").write_text('{"results": null}')
    with pytest.raises(SystemExit) as stop:
        load_trial("trial_profile_likelihood").main(argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and said in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.json", "kept.json", "null.json", "start.json",
                                                          "x.json.part"]


def test_the_profile_trials_check_exits_1_when_a_kept_number_is_not_run_again(capsys, monkeypatch, tmp_path):
    """--check says which kept results it does not get again, and exits 1 (a kept cost one bit off here; the runs
    are stubbed: the cells' cost and the T3 cells are what the kept file says but for that)."""
    import json

    kept = json.loads((ROOT / "examples" / "trial_profile_likelihood" / "load_friction.json").read_text())
    original = {r["at"]: {**r} for r in kept["results"]}  # copies: the edit below is the file's only
    kept["results"] = kept["results"][:2]
    kept["results"][1]["cost"] += 1e-15
    path = tmp_path / "kept.json"
    path.write_text(json.dumps(kept))
    trial = load_trial("trial_profile_likelihood")
    monkeypatch.setattr(trial.calibrate, "Evaluator", StubEvaluator)
    monkeypatch.setattr(trial.calibrate, "cost", lambda values: original[values["load_friction"]]["cost"])
    monkeypatch.setattr(trial, "t3_cells", lambda evaluator, values: [
        c["twin_mean"] for c in original[values["load_friction"]]["t3"]])
    with pytest.raises(SystemExit) as stop:
        trial.main(["--check", str(path)])
    lines = capsys.readouterr().out.splitlines()
    assert stop.value.code == 1
    assert lines[1].endswith("as kept: True; T3 cells as kept: True")
    assert lines[2].endswith("as kept: False; T3 cells as kept: True")


# Each kept profile, by its file in examples/trial_profile_likelihood/: its preset, its values in the order run, which
# were under the cut, and the 13.5 g vertical T3 cells (FF + PVA / sliding mode) as printed and as
# docs/investigations.md quotes them. The load friction ran on the twelfth refit (stop 46), the others on the
# thirteenth (stop 47); the two have the same cut. Those in longer/ are longer searches (48 evaluations a value, not
# 24) from a kept refit, on the thirteenth (stop 48); those in continued/ go on from where four of them stopped over
# the cut (stop 49; 96 evaluations for the load friction, 48 for the others: BUDGETS).
PROFILES = {
    "load_friction": ("6bb9e9258023", [0.40, 0.45, 0.50, 0.10, 0.05], [True, True, False, False, True],
                      ["4.28 / 4.09", "4.87 / 4.50", "5.51 / 4.90", "3.11 / 2.79", "3.09 / 2.75"]),
    "stiction": ("13aadbb61885", [2.1, 2.35, 2.55, 1.0], [False, False, False, True],
                 ["11.06 / 8.34", "16.14 / 13.34", "26.65 / 26.61", "3.61 / 3.42"]),
    "leak_conductance": ("13aadbb61885", [1e-14, 5e-15, 0.0, 3e-14], [True, True, False, True],
                         ["3.36 / 3.38", "3.59 / 3.38", "3.70 / 3.50", "4.16 / 3.81"]),
    "air_fraction": ("13aadbb61885", [0.02, 0.01, 0.065, 0.08], [True, False, True, False],
                     ["3.78 / 3.94", "4.97 / 4.84", "3.91 / 3.56", "4.26 / 3.68"]),
    "observer_gain": ("13aadbb61885", [250.0, 150.0, 700.0, 900.0], [False, False, False, False],
                      ["3.56 / 3.49", "3.31 / 3.32", "4.21 / 3.95", "4.34 / 3.92"]),
    "longer/load_friction_high": ("13aadbb61885", [0.50, 0.55, 0.60], [True, False, False],
                                  ["5.51 / 4.91", "6.20 / 5.59", "7.25 / 6.59"]),
    "longer/load_friction_0.10": ("13aadbb61885", [0.10], [True], ["3.16 / 2.80"]),
    "longer/load_friction_0": ("13aadbb61885", [0.0], [False], ["3.09 / 2.74"]),
    "longer/air_fraction_0.08": ("13aadbb61885", [0.08], [True], ["4.21 / 3.60"]),
    "longer/observer_gain_250": ("13aadbb61885", [250.0], [True], ["3.37 / 3.45"]),
    "longer/observer_gain_700": ("13aadbb61885", [700.0], [False], ["4.13 / 3.93"]),
    "longer/stiction_2.10": ("13aadbb61885", [2.10], [False], ["3.03 / 2.87"]),
    "continued/load_friction_0.55": ("13aadbb61885", [0.55], [True], ["6.27 / 5.62"]),
    "continued/load_friction_0.60": ("13aadbb61885", [0.60], [False], ["7.23 / 6.61"]),
    "continued/observer_gain_700": ("13aadbb61885", [700.0], [False], ["4.15 / 3.87"]),
    "continued/stiction_2.10": ("13aadbb61885", [2.10], [False], ["3.03 / 2.87"]),
}
# Each kept profile's evaluations a value, by its folder, or by its name where that differs.
BUDGETS = {"": 24, "longer": 48, "continued": 48, "continued/load_friction_0.55": 96,
           "continued/load_friction_0.60": 96}
# The longer searches' starts: each file's --start (a kept file and the value of its result the first value starts
# from).
LONGER_STARTS = {
    "longer/load_friction_high": ("load_friction", 0.50),  # the search at 0.50 that stopped over the cut, continued
    "longer/load_friction_0.10": ("load_friction", 0.10),
    "longer/load_friction_0": ("load_friction", 0.05),  # the box's bottom, from the nearest kept refit
    "longer/air_fraction_0.08": ("air_fraction", 0.08),
    "longer/observer_gain_250": ("observer_gain", 250.0),
    "longer/observer_gain_700": ("observer_gain", 700.0),
    "longer/stiction_2.10": ("load_friction", 0.05),  # another start: the breakaway at 2.10 N with little load friction
    "continued/load_friction_0.55": ("longer/load_friction_high", 0.55),  # each goes on from where one stopped
    "continued/load_friction_0.60": ("longer/load_friction_high", 0.60),
    "continued/observer_gain_700": ("longer/observer_gain_700", 700.0),
    "continued/stiction_2.10": ("longer/stiction_2.10", 2.10),
}


def _kept_profile(name: str) -> tuple[dict, str]:
    folder = ROOT / "examples" / "trial_profile_likelihood"
    return json.loads((folder / f"{name}.json").read_text()), (folder / f"{name}.txt").read_text()


def _vertical_13_5(result: dict) -> str:
    """A kept result's 13.5 g vertical T3 cells as the docs quote them: "FF + PVA / sliding mode", in deg."""
    ffpva, smc = [t["twin_mean"] for t in result["t3"] if t["payload_g"] == 13.5 and t["orientation"] == "vertical"]
    return f"{ffpva:.2f} / {smc:.2f}"


@pytest.mark.parametrize("name", list(PROFILES))
def test_the_profile_trials_kept_files_are_what_their_text_and_the_docs_quote(name):
    """Each kept profile: run on its preset (its digest and the cut of the twelfth and thirteenth refits), complete,
    the values in the order run, each result the lowest of its own evaluations (its BUDGETS a value), and the
    printed costs, cells within 20 %, twelve T3 cells and leads those of the results, which docs/investigations.md
    quotes."""
    from twin.experiments.validate import lead_counts
    from twin.plants.as_built import TWELFTH_REFIT_FILE, calibration_cost_line, preset_digest

    preset, at, under, vertical = PROFILES[name]
    kept, printed = _kept_profile(name)
    budget = BUDGETS.get(name, BUDGETS[name.rpartition("/")[0]])
    parameter = kept["results"][0]["parameter"]
    assert kept["preset"] == preset
    assert preset_digest(TWELFTH_REFIT_FILE) == "6bb9e9258023"
    assert kept["cut"] == sum(calibration_cost_line(TWELFTH_REFIT_FILE)) == 0.6468583228172117
    assert kept["complete"] and kept["evaluations_per_value"] == budget
    assert len(kept["evaluations"]) == budget * len(at)
    assert [r["parameter"] for r in kept["results"]] == [parameter] * len(at)
    assert name.split("/")[-1].startswith(parameter)
    assert [r["at"] for r in kept["results"]] == at
    assert [r["under_cut"] for r in kept["results"]] == under
    assert all(r["under_cut"] == (r["cost"] <= kept["cut"]) for r in kept["results"])
    for r in kept["results"]:  # each value's result is the lowest of its own evaluations
        own = [e["cost"] for e in kept["evaluations"] if e["at"] == r["at"]]
        assert len(own) == budget and r["cost"] == min(own) and r["values"][parameter] == r["at"]
    costs = [float(c) for c in re.findall(r"^  cost (\d\.\d+) \(", printed, re.M)]
    assert costs == [round(r["cost"], 4) for r in kept["results"]]
    shown = re.findall(r"^    T3 (\w+) +13\.5 g vertical +(\d+\.\d\d) ", printed, re.M)
    assert [f"{a[1]} / {b[1]}" for a, b in zip(shown[::2], shown[1::2], strict=True)] == vertical
    assert [_vertical_13_5(r) for r in kept["results"]] == vertical
    # The rest of what each value prints: the cells within 20 %, all twelve T3 cells, the lead.
    within = [int(n) for n in re.findall(r"^  cost .*; (\d+) of 21 measured RMSE cells within 20 %", printed, re.M)]
    assert within == [r["measured_rmse_cells_within"] for r in kept["results"]]
    cells = re.findall(r"^    T3 (\w+) +([\d.]+) g (\w+) +(\d+\.\d\d) ", printed, re.M)
    assert cells == [(t["controller"], f"{t['payload_g']:g}", t["orientation"], f"{t['twin_mean']:.2f}")
                     for r in kept["results"] for t in r["t3"]]
    ahead = [int(n) for n in re.findall(r"^    sliding mode ahead in (\d) of 6 T3 cells", printed, re.M)]
    assert ahead == [lead_counts([{k: t[k] for k in ("controller", "payload_g", "orientation")} for t in r["t3"]],
                                 [t["twin_mean"] for t in r["t3"]])[0].get("smc", 0) for r in kept["results"]]


@pytest.mark.parametrize("name", list(LONGER_STARTS))
def test_each_longer_search_starts_from_the_kept_refit_it_names_and_first_gets_its_cost_again(name):
    """A longer search's first value starts from the kept result its --start names (the values, that value's held
    one replaced), and its first evaluation, that set itself, costs what the kept file says to the last bit: the
    search goes on from where the kept one stopped (or from the other start it names)."""
    source, at = LONGER_STARTS[name]
    kept, printed = _kept_profile(name)
    before = {r["at"]: r for r in _kept_profile(source)[0]["results"]}[at]
    first = kept["results"][0]
    assert kept["start"] == [f"examples/trial_profile_likelihood/{source}.json", at]
    assert first["start"] == before["values"] and first["start_cost"] == before["cost"]
    assert kept["evaluations"][0]["values"] == {**before["values"], first["parameter"]: first["at"]}
    if before["values"][first["parameter"]] == first["at"]:  # the same set: its cost again, bit for bit
        assert kept["evaluations"][0]["cost"] == before["cost"]
    for before_it, result in zip(kept["results"][:-1], kept["results"][1:], strict=True):  # later: from the one before
        assert result["start"] == before_it["values"] and result["start_cost"] == before_it["cost"]
    said = re.fullmatch(rf".*: from the set at \S+ \(cost {before['cost']:.4f}, (\S+) (\S+)\)", printed.splitlines()[1])
    assert said and said[1] == f"examples/trial_profile_likelihood/{source}.json" and float(said[2]) == at


@pytest.mark.slow  # about 1 min on 2 cores: the 13 members' T3 cells, then 7 parameter sets on the fit's cells
def test_a_run_from_a_kept_start_makes_the_kept_longer_searchs_first_evaluations_again(capsys, monkeypatch, tmp_path):
    """The --start run path: run as the kept 0.10 N/N longer search was (from the checkout's root, --start given as
    then), over its first simplex only, it prints the kept text's first two lines (but for the budget) and makes its
    first seven evaluations again, values and costs to the last bit."""
    kept, printed = _kept_profile("longer/load_friction_0.10")
    monkeypatch.chdir(ROOT)
    load_trial("trial_profile_likelihood").main(["--parameter", "load_friction", "--at", "0.10", "--evaluations", "7",
                                            "--start", "examples/trial_profile_likelihood/load_friction.json",
                                            "0.10", "--out", str(tmp_path / "short.json")])
    head = capsys.readouterr().out.splitlines()[:2]
    assert head == [printed.splitlines()[0].replace("over 48 evaluations", "over 7 evaluations"),
                    printed.splitlines()[1]]
    short = json.loads((tmp_path / "short.json").read_text())
    assert short["start"] == kept["start"] and short["results"][0]["start"] == kept["results"][0]["start"]
    assert short["evaluations"] == kept["evaluations"][:7]


@pytest.mark.parametrize(("heading", "rows"), [
    ("## Longer searches where a refit stopped near the cut", [f"longer/{n}" for n in (
        "load_friction_high", "load_friction_0.10", "load_friction_0", "air_fraction_0.08", "observer_gain_250",
        "observer_gain_700", "stiction_2.10")]),
    ("## Searches continued where four stopped over the cut", [f"continued/{n}" for n in (
        "load_friction_0.55", "load_friction_0.60", "observer_gain_700", "stiction_2.10")]),
])
def test_investigations_md_quotes_the_longer_searches_as_kept(heading, rows):
    """docs/investigations.md's stop-48 and stop-49 sections give each search's cost (4 places) and 13.5 g vertical
    T3 cells as the kept files hold them, in the order its first table lists them."""
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    section = text[text.index(heading):]
    section = section[:section.index("\n## ")]
    first = section[section.index("\n| parameter"):]
    table = [line for line in first[:first.index("\n\n")].splitlines()[3:]]
    quoted = [(re.search(r"(\d\.\d{4})", row)[1], re.search(r"(\d+\.\d\d / \d+\.\d\d)", row)[1]) for row in table]
    kept = [(f"{r['cost']:.4f}", _vertical_13_5(r)) for name in rows for r in _kept_profile(name)[0]["results"]]
    assert quoted == kept and len(quoted) == len(kept) >= len(rows)


@pytest.mark.slow  # about 30 s on 2 cores each: one to five parameter sets on the fit's 21 cells x 10 seeds, T3's 12 x 5
@pytest.mark.parametrize("name", list(PROFILES))
def test_the_profile_trials_kept_results_run_again_to_the_last_bit(capsys, name):
    try:  # exit 1 on a mismatch: the lines below then say which
        load_trial("trial_profile_likelihood").main(["--check", str(ROOT / "examples" / "trial_profile_likelihood" /
                                                                  f"{name}.json")])
        code = 0
    except SystemExit as stop:
        code = stop.code
    lines = capsys.readouterr().out.splitlines()
    preset, at, _, _ = PROFILES[name]
    parameter = _kept_profile(name)[0]["results"][0]["parameter"]
    assert code == 0, lines
    assert lines[0].endswith(f"preset {preset}, {len(at)} values of {parameter}")
    assert [float(line.split(":")[0]) for line in lines[1:]] == at
    assert all(line.endswith("as kept: True; T3 cells as kept: True") for line in lines[1:]), lines


def test_the_profile_trial_names_its_calibration_from_the_checkouts_root(tmp_path):
    """A kept file names a calibration inside the checkout from its root (not the absolute path of the machine it ran
    on), and one outside it as given."""
    from twin.plants.as_built import CALIBRATION_FILE, TWELFTH_REFIT_FILE

    trial = load_trial("trial_profile_likelihood")
    assert trial.shown(CALIBRATION_FILE) == "twin/plants/data/as_built.json"
    assert trial.shown(ROOT / "twin" / "plants" / "data" / ".." / "data" / "twelfth_refit.json") == (
        "twin/plants/data/twelfth_refit.json") == trial.shown(TWELFTH_REFIT_FILE)
    assert trial.shown(tmp_path / "mine.json") == str(tmp_path / "mine.json")


@pytest.mark.slow  # about 20, 8 and 2 s on 2 cores: nine, four and one parameter sets on 11 Chapter 5 cells x 5 seeds
@pytest.mark.parametrize("folder", ["", "longer/", "continued/"])
def test_the_profile_orders_trial_prints_what_it_kept(capsys, folder):
    """Its output on the five kept files (by default), on the seven longer searches' kept files and on the four
    continued searches' (each given in name order), as kept beside them."""
    kept = ROOT / "examples" / "trial_profile_likelihood" / folder
    load_trial("trial_profile_orders").main([str(p) for p in sorted(kept.glob("*.json"))] if folder else [])
    assert capsys.readouterr().out == (kept / "orders.txt").read_text()


@pytest.mark.parametrize(("text", "said"), [
    (None, "cannot read it as JSON (FileNotFoundError)"),
    ("{", "cannot read it as JSON (JSONDecodeError)"),
    ("[]", "not a kept profile trial file"),
    ('{"results": [{"at": 1}], "complete": true}', "not a kept profile trial file"),
    ('{"results": [], "complete": false}', "a stopped profile run (not complete)"),
    ('{"results": [{"parameter": "air_fraction", "at": 0.02, "cost": 0.6, "under_cut": true, "values": {}, "t3": []}],'
     ' "complete": true}', "not a kept profile trial file"),
])
def test_the_profile_orders_trial_refuses_a_file_it_cannot_use_before_it_runs(capsys, monkeypatch, tmp_path, text,
                                                                            said):
    from twin.experiments import calibrate

    def no_run(*args, **kwargs):
        raise AssertionError("the trial started its runs")

    monkeypatch.setattr(calibrate, "Evaluator", no_run)
    path = tmp_path / "kept.json"
    if text is not None:
        path.write_text(text)
    with pytest.raises(SystemExit) as stop:
        load_trial("trial_profile_orders").main([str(path)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and f"{path}: {said}" in err and "Traceback" not in err


@pytest.mark.parametrize(("text", "said"), [
    ("{", "cannot read it as JSON (JSONDecodeError)"),
    ('{"results": [{"at": 1}], "complete": true}', "not a kept profile trial file (no results as the trial writes"),
    ('{"results": [], "complete": false}', "a stopped profile run (not complete): run it whole first"),
    ("KEPT_NO_EVALUATIONS", "not a kept profile trial file (no results as the trial writes"),
    ("KEPT_NAN_COST", "not a kept profile trial file (no results as the trial writes"),
])
def test_the_three_trials_that_read_kept_profile_files_refuse_one_in_the_same_words(capsys, monkeypatch, tmp_path,
                                                                                  text, said):
    """The orders trial, the fresh-seed trial and the profile trial's --check read a kept profile file through one
    reader (examples/kept_profiles.py), so each refuses a file that is not one with the same reason, in one line,
    before any run (--check takes a stopped run's results, so a stopped run is refused by the other two only)."""
    import copy

    from twin.experiments import calibrate

    def no_run(*args, **kwargs):
        raise AssertionError("the trial started its runs")

    good = json.loads((ROOT / "examples" / "trial_profile_likelihood" / "continued" / "stiction_2.10.json").read_text())
    broken = copy.deepcopy(good)
    if text == "KEPT_NO_EVALUATIONS":
        del broken["evaluations"]
    elif text == "KEPT_NAN_COST":
        broken["results"][0]["cost"] = float("nan")
    monkeypatch.setattr(calibrate, "Evaluator", no_run)
    folder = tmp_path / "kept"
    folder.mkdir()
    path = folder / "run.json"
    path.write_text(json.dumps(broken) if text.startswith("KEPT_") else text)
    fresh = load_trial("trial_fresh_seed_costs")
    monkeypatch.setattr(fresh, "KEPT", folder)
    runs = [(load_trial("trial_profile_orders").main, [str(path)], f"{path}: {said}"),
            (fresh.main, [], f"run.json: {said}"),
            (load_trial("trial_profile_likelihood").main, ["--check", str(path)], f"--check {path}: {said}")]
    for main, argv, words in runs[:2] if "stopped" in said else runs:
        with pytest.raises(SystemExit) as stop:
            main(argv)
        err = capsys.readouterr().err
        assert stop.value.code == 2 and words in err and "Traceback" not in err, (argv, err)


def test_the_profile_trials_check_refuses_a_kept_file_that_names_no_preset(capsys, monkeypatch, tmp_path):
    from twin.experiments import calibrate

    def no_run(*args, **kwargs):
        raise AssertionError("the trial started its runs")

    kept = json.loads((ROOT / "examples" / "trial_profile_likelihood" / "continued" / "stiction_2.10.json").read_text())
    del kept["preset"]
    path = tmp_path / "run.json"
    path.write_text(json.dumps(kept))
    monkeypatch.setattr(calibrate, "Evaluator", no_run)
    with pytest.raises(SystemExit) as stop:
        load_trial("trial_profile_likelihood").main(["--check", str(path)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and f"--check {path}: names no preset, so what it ran on is not known" in err


def test_the_profile_orders_kept_text_pairs_each_reversed_t3_lead_with_a_wrong_chapter_5_order():
    """What docs/investigations.md reads from orders.txt: every refit under the cut with the measured Chapter 5
    order on all four trajectories has sliding mode ahead in all six T3 cells, and every one with FF + PVA ahead in
    a T3 cell gets one or more trajectories' order wrong: nine refits of stop 46-47, five with the order right on all
    four, four of the longer searches (stop 48), one with it right on all four, and the one continued search under
    the cut (stop 49), with sliding mode ahead in five cells and T1's order wrong."""
    found = {}
    for folder in ("", "longer/", "continued/"):
        lines = (ROOT / "examples" / "trial_profile_likelihood" / folder / "orders.txt").read_text().splitlines()
        found[folder] = [(int(a), int(b)) for a, b in (
            re.search(r"order right on (\d) of 4.*ahead in (\d) of 6", line).groups()
            for line in lines if line.startswith("  "))]
    assert [len(f) for f in found.values()] == [9, 4, 1]
    assert [sum(right == 4 for right, _ in f) for f in found.values()] == [5, 1, 0]
    both = found[""] + found["longer/"] + found["continued/"]
    assert all(ahead == 6 for right, ahead in both if right == 4)
    assert sorted(ahead for right, ahead in both if ahead < 6) == [0, 2, 3, 4, 5]
    assert all(right < 4 for right, ahead in both if ahead < 6)
