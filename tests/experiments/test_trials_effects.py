"""The committed trial scripts that each read one effect or choice on a kept preset, nothing refitted: they still print
what the docs quote (mostly docs/as-built.md, docs/investigations.md, docs/prediction.md). They are trial_payload_effect
and trial_payload_cost_effects (what a payload costs), trial_pva_t1 (PVA + DZC on T1), trial_one_joint (five runs on
one joint), trial_load_friction_edge, trial_t1_start, trial_t2_t3_choices, trial_chapter6_supply,
trial_actuation_delay, trial_smc_compensation, trial_chamber_buildup (softer or leakier chambers),
trial_initial_pressure (where the chambers' pressure starts), trial_smc_lead, trial_subtick_coil (pulses that end at
their exact duty), trial_t4_order (T4's order on each member), trial_vertical_hold (FF + PVA T1 on its side),
trial_t1_direction (T1 the other way), trial_t1_hold (T1's length) and trial_lag_relation (T1 from T2 and T3)."""

from __future__ import annotations

import re

import pytest
from trial_scripts import ROOT, doc_text, load_trial


@pytest.mark.slow  # about 25 s on 2 cores: twelve T1 cells, 40 seeds each
def test_trial_payload_effect_prints_what_as_built_md_quotes(capsys):
    load_trial("trial_payload_effect").main()
    rows = {" ".join(line.split()[:4]): line.split() for line in capsys.readouterr().out.splitlines()[1:]}
    # controller, grams, "g", orientation -> RMSE, move, hold 1.0-1.5 s, hold 1.5-3 s, ratios, error at 1.0 s
    flat = rows["ffpva 0.0 g horizontal"]
    assert flat[4:7] == ["1.64", "2.15", "2.27"] and flat[9:] == ["1.00", "-1.20", "±", "2.21"]
    assert rows["ffpva 6.5 g horizontal"][4:7] == ["1.42", "2.28", "1.13"]
    assert [rows[f"ffpva {k}"][9] for k in ("6.5 g horizontal", "13.5 g horizontal", "0.0 g vertical",
                                             "6.5 g vertical", "13.5 g vertical")] == ["1.06", "1.19", "0.95", "1.15",
                                                                                       "2.97"]
    assert rows["ffpva 0.0 g vertical"][10:] == ["-1.09", "±", "1.19"]


@pytest.mark.slow  # about 15 s on 2 cores: PVA + DZC on T1-T3, ten seeds, six variants; sliding mode T2, T3
def test_trial_pva_t1_prints_what_as_built_md_quotes(capsys):
    load_trial("trial_pva_t1").main()
    out = capsys.readouterr().out.splitlines()
    split = next(i for i, line in enumerate(out) if line.startswith("sliding mode, seeds 0-9"))
    assert out[split - 1].endswith("as committed 0.000, opens from 20 % 0.072, opens from 22 % 0.054")
    pva = {line[:28].strip(): line[28:].strip() for line in out[1:split - 1]}
    smc = {line[:28].strip(): line[28:].strip() for line in out[split + 1:]}
    assert pva["K_p 80,000 %/m"].startswith("T1 1.83 ± 0.15 (largest 7.6) move 2.87 hold 0.96")
    assert "SSE ranges ±0.35 / ±0.66 | T2 2.71 ± 0.12 (largest 6.3) | T3 2.91 ± 0.07" in pva["K_p 80,000 %/m"]
    assert pva["K_p 240,000 %/m"].startswith("T1 3.51 ± 0.62 (largest 9.7) move 3.28 hold 3.69")
    assert "SSE ranges ±5.48 / ±6.24 | T2 3.06 ± 0.16 (largest 9.3) | T3 3.11 ± 0.07" in pva["K_p 240,000 %/m"]
    assert "SSE ranges ±4.76 / ±1.31" in pva["K_p 160,000 %/m"]
    assert "duty at openings 62 % (median)" in pva["K_p 80,000 %/m"]
    assert pva["valve opens from 20 %"].startswith("T1 1.63 ± 0.10")
    assert pva["valve opens from 22 %"].startswith("T1 1.69 ± 0.07")
    assert smc == {"as committed": "T2 2.26 | T3 2.29", "valve opens from 20 %": "T2 2.16 | T3 2.19",
                   "valve opens from 22 %": "T2 2.16 | T3 2.24"}


@pytest.mark.slow  # about 4 min on 2 cores: 21 cells x 40 seeds three ways, then T1 and T3 with the noise scaled
def test_trial_one_joint_prints_what_as_built_md_quotes(capsys):
    load_trial("trial_one_joint").main()
    out = capsys.readouterr().out
    assert "std in the rig's 90 % interval: a map per run 11 of 21, a map per group 10 of 21, no map 11 of 21" in out
    rows = {" ".join(line.split()[:5]): line.split()[8:] for line in out.splitlines() if line.startswith(("ffpva T1",
                                                                                                         "smc T1"))}
    # per way: ratio, pooled std, (in/out)
    assert rows["ffpva T1 0 g horizontal"] == ["x1.17", "0.27", "(out)", "x1.18", "0.22", "(out)", "x1.17", "0.28",
                                               "(out)"]
    assert rows["smc T1 0 g horizontal"] == ["x1.23", "0.27", "(out)", "x1.23", "0.23", "(in)", "x1.26", "0.28",
                                             "(out)"]
    assert "noise x1: ffpva 1.64 ± 0.27, error at 1.0 s -1.20 ± 2.21 | smc 1.46 ± 0.27," in out
    assert "noise x0.25: ffpva 2.06 ± 0.24, error at 1.0 s +2.58 ± 3.11 | smc 1.65 ± 0.39," in out
    assert "noise x0.05: ffpva 2.23 ± 0.02, error at 1.0 s +4.49 ± 0.04 | smc 1.82 ± 0.53," in out
    assert ("noise x0.5: ffpva T1 0 g H 1.82 | ffpva T3 0 g H 2.16 | ffpva T3 13.5 g V 3.50 | smc T1 0 g H 1.48 | "
            "smc T3 0 g H 2.30 | smc T3 13.5 g V 3.43") in out
    assert ("noise x1: ffpva T1 0 g H 1.65 | ffpva T3 0 g H 2.21 | ffpva T3 13.5 g V 3.48 | smc T1 0 g H 1.43 | "
            "smc T3 0 g H 2.30 | smc T3 13.5 g V 3.53") in out
    assert ("noise x1.73: ffpva T1 0 g H 1.49 | ffpva T3 0 g H 2.35 | ffpva T3 13.5 g V 3.65 | smc T1 0 g H 1.39 | "
            "smc T3 0 g H 2.38 | smc T3 13.5 g V 3.55") in out


@pytest.mark.slow  # about 4 min on 2 cores: seven parameter sets x 21 cells x 40 seeds, and T3 13.5 g vertical
def test_trial_load_friction_edge_prints_what_prediction_md_quotes(capsys):
    load_trial("trial_load_friction_edge").main()
    rows = {line.split(" | ")[0].split()[0]: line.split(" | ")[1:] for line in capsys.readouterr().out.splitlines()[1:]}
    # load friction -> costs by seed set, paired difference, cost on seeds 0-39, share of redraws won, T3 13.5 g V
    expected = {
        "0.293": ("0.559 / 0.757 / 0.741 / 0.895", "+0.000 (+0.000 to +0.000)", "0.675", "0.000", "3.51 / 3.42"),
        "0.000": ("0.763 / 1.059 / 0.973 / 1.103", "+0.237 (+0.205 to +0.302)", "0.888", "0.000", "2.79 / 2.74"),
        "0.150": ("0.771 / 0.987 / 0.936 / 1.059", "+0.200 (+0.164 to +0.230)", "0.875", "0.000", "3.11 / 3.05"),
        "0.200": ("0.665 / 0.836 / 0.906 / 1.041", "+0.124 (+0.078 to +0.165)", "0.817", "0.000", "3.21 / 3.19"),
        "0.250": ("0.616 / 0.849 / 0.773 / 0.897", "+0.046 (+0.001 to +0.092)", "0.732", "0.000", "3.41 / 3.35"),
        "0.350": ("0.560 / 0.748 / 0.783 / 0.865", "+0.001 (-0.030 to +0.041)", "0.690", "0.090", "3.79 / 3.72"),
        "0.400": ("0.793 / 0.861 / 0.680 / 0.997", "+0.095 (-0.061 to +0.234)", "0.784", "0.000", "4.22 / 4.12"),
        "0.450": ("0.762 / 0.890 / 0.943 / 1.017", "+0.165 (+0.122 to +0.204)", "0.858", "0.000", "4.74 / 4.53"),
        "0.600": ("0.762 / 1.004 / 0.924 / 1.070", "+0.202 (+0.174 to +0.247)", "0.885", "0.000", "7.26 / 6.84"),
    }
    assert {key: tuple(row) for key, row in rows.items()} == expected


@pytest.mark.slow  # about 65 s on 2 cores: two laws x two T1 cells x 40 seeds, nine variants
def test_trial_payload_cost_effects_prints_what_as_built_md_quotes(capsys):
    load_trial("trial_payload_cost_effects").main()
    rows = {line.split(" | ")[0].strip(): line.split(" | ")[1:] for line in capsys.readouterr().out.splitlines()[1:]}
    # effect switched off -> FF + PVA 0 g, 13.5 g, cost; sliding mode the same (T1 horizontal, seeds 40-79)
    assert rows == {
        "(nothing: as committed)": ["1.55, 1.56, x1.00 ± 0.02", "1.33, 1.60, x1.20 ± 0.03"],
        "compressibility,supply_line": ["4.59, 9.51, x2.07 ± 0.02", "4.07, 7.32, x1.80 ± 0.02"],
        "supply_line": ["1.59, 1.61, x1.01 ± 0.02", "1.37, 1.58, x1.15 ± 0.03"],
        "stiction": ["1.54, 1.55, x1.01 ± 0.02", "1.30, 1.60, x1.24 ± 0.04"],
        "ccw_friction": ["1.55, 1.57, x1.01 ± 0.03", "1.34, 1.56, x1.17 ± 0.03"],
        "solenoid_valve": ["0.73, 0.93, x1.27 ± 0.02", "0.43, 0.60, x1.38 ± 0.02"],
        "hall_calibration": ["1.19, 1.52, x1.27 ± 0.03", "1.31, 1.60, x1.22 ± 0.03"],
        "experiment_gains": ["1.42, 1.45, x1.02 ± 0.02", "1.24, 1.63, x1.32 ± 0.05"],
        "sensor_metrics": ["2.32, 2.24, x0.97 ± 0.02", "2.13, 2.18, x1.02 ± 0.02"],
    }


@pytest.mark.slow  # about 20 s on 2 cores: three laws on T1 from six start angles, ten seeds each
def test_trial_t1_start_prints_what_as_built_md_quotes(capsys):
    from twin.physics import trajectories

    committed = trajectories.START
    load_trial("trial_t1_start").main()
    assert trajectories.START == committed  # the trial puts the committed start back
    rows = {m.group(1, 2): m.group(3) for m in (re.fullmatch(r"start +(\d+) deg +(\w+) +(.*)", line)
                                                for line in capsys.readouterr().out.splitlines()) if m}
    # (start in deg, law) -> RMSE mean ± std, largest error (mean), move / hold RMS, SSE ranges of seeds 0-4 / 5-9
    assert rows == {
        ("10", "pva"): "1.82 ± 0.13, largest 7.8, move 2.93 hold 0.82, SSE ±0.80 / ±1.28",
        ("10", "ffpva"): "1.58 ± 0.31, largest 5.7, move 2.21 hold 1.19, SSE ±0.73 / ±0.79",
        ("10", "smc"): "1.39 ± 0.20, largest 5.8, move 2.20 hold 0.72, SSE ±0.36 / ±0.50",
        ("20", "pva"): "1.86 ± 0.18, largest 7.6, move 2.93 hold 0.96, SSE ±1.44 / ±1.40",
        ("20", "ffpva"): "1.39 ± 0.16, largest 5.7, move 2.04 hold 0.92, SSE ±1.20 / ±1.14",
        ("20", "smc"): "1.41 ± 0.25, largest 5.9, move 2.12 hold 0.90, SSE ±0.99 / ±0.99",
        ("30", "pva"): "1.66 ± 0.10, largest 7.7, move 2.82 hold 0.42, SSE ±0.21 / ±0.71",
        ("30", "ffpva"): "1.60 ± 0.15, largest 6.0, move 2.18 hold 1.23, SSE ±0.27 / ±1.17",
        ("30", "smc"): "1.34 ± 0.09, largest 5.6, move 2.14 hold 0.63, SSE ±0.59 / ±0.63",
        ("40", "pva"): "1.89 ± 0.19, largest 7.8, move 3.00 hold 0.94, SSE ±0.85 / ±0.32",
        ("40", "ffpva"): "1.44 ± 0.21, largest 5.7, move 2.14 hold 0.94, SSE ±1.18 / ±0.38",
        ("40", "smc"): "1.35 ± 0.14, largest 5.5, move 2.17 hold 0.62, SSE ±0.68 / ±0.88",
        ("50", "pva"): "1.97 ± 0.25, largest 8.3, move 3.08 hold 1.07, SSE ±0.66 / ±0.22",
        ("50", "ffpva"): "1.25 ± 0.07, largest 5.8, move 2.10 hold 0.41, SSE ±0.33 / ±1.65",
        ("50", "smc"): "1.47 ± 0.28, largest 5.5, move 2.21 hold 0.96, SSE ±0.59 / ±0.32",
        ("54", "pva"): "1.87 ± 0.27, largest 8.5, move 3.04 hold 0.85, SSE ±0.42 / ±0.28",
        ("54", "ffpva"): "1.21 ± 0.08, largest 5.8, move 1.97 hold 0.50, SSE ±0.64 / ±0.90",
        ("54", "smc"): "1.48 ± 0.33, largest 5.8, move 2.24 hold 0.97, SSE ±0.56 / ±0.31",
    }


@pytest.mark.slow  # about 20 s on 2 cores: T3's 13 cells three ways and T2's three cells five ways, five seeds
def test_trial_t2_t3_choices_prints_what_the_docs_quote(capsys):
    import twin.sim.simulation as simulation

    committed = simulation.trajectory
    load_trial("trial_t2_t3_choices").main()
    assert simulation.trajectory is committed  # the trial puts the committed trajectories back
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "T3: the 10 s runs' first 4 s give the committed runs bit for bit: True"
    assert out[16] == "T2: the 1.2 s runs' first 1 s give the committed runs bit for bit: True"
    rows = dict(line.split(": ", 1) for line in out[2:16] + out[18:])
    # cell -> mean RMSE per choice (T3: the first 2 / 4 / 6 / 8 / 10 s, from the trough; T2: the first 0.5 /
    # 0.75 / 1 / 1.2 s, from 24 / 40 / 50 deg), the largest over the smallest, stalled runs, x the rig's
    assert rows == {
        "pva T3 0 g horizontal": "3.06 / 3.04 / 3.04 / 3.05 / 3.05 / 3.06 | x1.009 | stalled 0 | the rig 3.00: "
                                 "x1.01 as committed, x1.01-x1.02",
        "ffpva T3 0 g horizontal": "2.35 / 2.38 / 2.35 / 2.34 / 2.33 / 2.33 | x1.021 | stalled 0 | the rig 2.09: "
                                   "x1.14 as committed, x1.11-x1.14",
        "ffpva T3 6.5 g horizontal": "2.49 / 2.58 / 2.62 / 2.63 / 2.65 / 2.60 | x1.067 | stalled 0",
        "ffpva T3 13.5 g horizontal": "2.87 / 2.86 / 2.91 / 2.92 / 2.92 / 2.91 | x1.024 | stalled 0",
        "ffpva T3 0 g vertical": "2.36 / 2.33 / 2.33 / 2.36 / 2.39 / 2.30 | x1.039 | stalled 0",
        "ffpva T3 6.5 g vertical": "2.57 / 2.60 / 2.59 / 2.65 / 2.68 / 2.63 | x1.041 | stalled 0",
        "ffpva T3 13.5 g vertical": "3.67 / 3.66 / 3.68 / 3.69 / 3.69 / 3.92 | x1.070 | stalled 0",
        "smc T3 0 g horizontal": "2.19 / 2.21 / 2.18 / 2.18 / 2.19 / 2.22 | x1.023 | stalled 0 | the rig 1.69: "
                                 "x1.30 as committed, x1.29-x1.32",
        "smc T3 6.5 g horizontal": "2.40 / 2.42 / 2.38 / 2.38 / 2.39 / 2.41 | x1.016 | stalled 0",
        "smc T3 13.5 g horizontal": "2.63 / 2.61 / 2.58 / 2.61 / 2.61 / 2.58 | x1.019 | stalled 0",
        "smc T3 0 g vertical": "2.17 / 2.22 / 2.19 / 2.19 / 2.20 / 2.21 | x1.025 | stalled 0",
        "smc T3 6.5 g vertical": "2.39 / 2.41 / 2.42 / 2.43 / 2.44 / 2.52 | x1.051 | stalled 0",
        "smc T3 13.5 g vertical": "3.39 / 3.42 / 3.41 / 3.40 / 3.41 / 3.52 | x1.041 | stalled 0",
        "T3, sliding mode ahead of FF + PVA in how many of the 6 cells": "2 s 6 / 4 s 6 / 6 s 6 / 8 s 6 / 10 s 6 / "
                                                                          "trough 6",
        "pva T2 0 g horizontal": "2.92 / 2.88 / 2.91 / 3.05 / 2.86 / 3.03 / 2.84 | x1.073 | stalled 0 | the rig "
                                 "2.93: x0.99 as committed, x0.97-x1.04",
        "ffpva T2 0 g horizontal": "2.47 / 2.37 / 2.37 / 2.42 / 2.42 / 2.34 / 2.38 | x1.055 | stalled 0 | the rig "
                                   "2.08: x1.14 as committed, x1.13-x1.19",
        "smc T2 0 g horizontal": "2.24 / 2.25 / 2.30 / 2.36 / 2.19 / 2.30 / 2.38 | x1.091 | stalled 0 | the rig "
                                 "1.55: x1.49 as committed, x1.41-x1.54",
    }


@pytest.mark.slow  # about 50 s on 2 cores: ten T1 and twelve T3 cells at seven supply pressures, five seeds
def test_trial_chapter6_supply_prints_what_prediction_md_quotes(capsys):
    load_trial("trial_chapter6_supply").main()
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "T3 at 300 kPa gives the committed runs bit for bit: True"
    rows = dict(line.split(": ", 1) for line in out[2:])
    # pressure -> Chapter 6 T1 cells within 20 %, the 13.5 g vertical T1 cells x the measured; T3 mean RMSE per
    # cell (FF + PVA | sliding mode; 0 / 6.5 / 13.5 g horizontal, then vertical; * a stalled run); the lead
    assert rows == {
        "285 kPa": "T1 6 of 10, 13.5 g V x1.33 / x1.65; T3 2.38 2.66 2.88 2.37 2.61 5.42 | 2.19 2.44 2.67 2.25 2.41 4.84; "
                   "smc ahead 6 of 6",
        "290 kPa": "T1 7 of 10, 13.5 g V x1.15 / x1.41; T3 2.37 2.61 2.90 2.41 2.70 4.53 | 2.19 2.42 2.63 2.20 2.42 4.17; "
                   "smc ahead 6 of 6",
        "295 kPa": "T1 8 of 10, 13.5 g V x0.96 / x1.21; T3 2.32 2.64 2.91 2.34 2.65 4.04 | 2.21 2.38 2.62 2.24 2.44 3.74; "
                   "smc ahead 6 of 6",
        "300 kPa": "T1 9 of 10, 13.5 g V x0.89 / x0.95; T3 2.38 2.58 2.86 2.33 2.60 3.66 | 2.21 2.42 2.61 2.22 2.41 3.42; "
                   "smc ahead 6 of 6",
        "305 kPa": "T1 8 of 10, 13.5 g V x0.76 / x0.86; T3 2.30 2.69 2.95 2.32 2.70 3.45 | 2.22 2.42 2.64 2.25 2.43 3.10; "
                   "smc ahead 6 of 6",
        "310 kPa": "T1 7 of 10, 13.5 g V x0.68 / x0.78; T3 2.42 2.54 2.95 2.33 2.72 3.37 | 2.23 2.39 2.60 2.22 2.43 2.95; "
                   "smc ahead 6 of 6",
        "315 kPa": "T1 7 of 10, 13.5 g V x0.56 / x0.76; T3 2.40 2.74 3.01 2.38 2.71 3.27 | 2.20 2.40 2.63 2.21 2.42 2.79; "
                   "smc ahead 6 of 6",
    }


@pytest.mark.slow  # about 1 min: §8's eleven cells, ten seeds, nine ways (the plain runs and eight delays)
def test_trial_actuation_delay_prints_what_as_built_md_quotes(capsys):
    from twin.physics.valves import ValveBank

    plain = ValveBank.update
    load_trial("trial_actuation_delay").main()
    assert ValveBank.update is plain  # the trial puts the valves back
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "delay 0 gives the plain runs bit for bit: True"
    assert out[1] == "as-built, seeds 0-9: mean RMSE (mean largest error) and x the measured mean, per cell (deg)"
    rows = {line.split(":", 1)[0]: line.split(": ", 1)[1].split(" | ") for line in out[2:]}
    # delay -> cells within 20 %, each cell "law Tn RMSE (largest) xratio", then PVA + DZC T1's move and hold
    # RMS, its SSE ranges (seeds 0-4 / 5-9), the smallest and largest |SSE| and the runs over 1 deg
    assert rows == {
        "delay 0 ms": [
            "within 20 % 8 of 11",
            "pva T1 1.66 (7.7) x0.40",
            "pva T2 2.75 (6.0) x0.94",
            "pva T3 2.89 (7.3) x0.96",
            "ffpva T1 1.60 (6.0) x1.14",
            "ffpva T2 2.20 (5.7) x1.06",
            "ffpva T3 2.14 (6.0) x1.02",
            "ffpva T4 1.82 (6.4) x0.93",
            "smc T1 1.34 (5.6) x1.12",
            "smc T2 2.25 (5.5) x1.45",
            "smc T3 2.25 (5.9) x1.33",
            "smc T4 1.95 (6.1) x1.07",
            "pva T1 move 2.82 hold 0.42 SSE ±0.21 / ±0.71, runs end 0.03-0.71 off, 0 of 10 over 1 deg",
        ],
        "delay 1 ms": [
            "within 20 % 7 of 11",
            "pva T1 1.80 (8.2) x0.43",
            "pva T2 2.81 (6.2) x0.96",
            "pva T3 2.91 (7.7) x0.97",
            "ffpva T1 1.61 (6.2) x1.15",
            "ffpva T2 2.28 (5.8) x1.09",
            "ffpva T3 2.17 (6.2) x1.04",
            "ffpva T4 1.80 (6.3) x0.93",
            "smc T1 1.53 (5.8) x1.29",
            "smc T2 2.28 (5.4) x1.47",
            "smc T3 2.31 (6.0) x1.37",
            "smc T4 1.89 (6.0) x1.04",
            "pva T1 move 2.93 hold 0.76 SSE ±0.24 / ±0.74, runs end 0.03-0.74 off, 0 of 10 over 1 deg",
        ],
        "delay 2 ms": [
            "within 20 % 7 of 11",
            "pva T1 1.80 (8.1) x0.43",
            "pva T2 2.87 (6.6) x0.98",
            "pva T3 3.01 (8.1) x1.00",
            "ffpva T1 1.64 (6.3) x1.17",
            "ffpva T2 2.35 (5.8) x1.13",
            "ffpva T3 2.27 (6.4) x1.09",
            "ffpva T4 1.88 (6.5) x0.96",
            "smc T1 1.61 (6.2) x1.35",
            "smc T2 2.37 (5.6) x1.53",
            "smc T3 2.37 (6.0) x1.40",
            "smc T4 1.95 (6.2) x1.07",
            "pva T1 move 2.98 hold 0.68 SSE ±0.59 / ±0.32, runs end 0.15-0.59 off, 0 of 10 over 1 deg",
        ],
        "delay 3 ms": [
            "within 20 % 7 of 11",
            "pva T1 1.90 (8.3) x0.45",
            "pva T2 3.08 (7.8) x1.05",
            "pva T3 3.21 (8.8) x1.07",
            "ffpva T1 1.56 (6.3) x1.11",
            "ffpva T2 2.38 (5.8) x1.14",
            "ffpva T3 2.35 (6.6) x1.12",
            "ffpva T4 1.86 (6.6) x0.95",
            "smc T1 1.43 (6.2) x1.20",
            "smc T2 2.44 (5.7) x1.58",
            "smc T3 2.46 (6.6) x1.45",
            "smc T4 1.94 (6.4) x1.06",
            "pva T1 move 3.21 hold 0.55 SSE ±0.20 / ±0.81, runs end 0.11-0.81 off, 0 of 10 over 1 deg",
        ],
        "delay 4 ms": [
            "within 20 % 7 of 11",
            "pva T1 2.55 (10.2) x0.61",
            "pva T2 3.49 (10.1) x1.19",
            "pva T3 3.38 (10.2) x1.13",
            "ffpva T1 1.59 (6.5) x1.13",
            "ffpva T2 2.44 (6.0) x1.17",
            "ffpva T3 2.37 (6.8) x1.13",
            "ffpva T4 1.89 (7.0) x0.97",
            "smc T1 1.57 (6.3) x1.32",
            "smc T2 2.49 (5.7) x1.61",
            "smc T3 2.57 (6.6) x1.52",
            "smc T4 1.98 (6.8) x1.09",
            "pva T1 move 3.58 hold 2.16 SSE ±0.48 / ±5.75, runs end 0.12-5.75 off, 3 of 10 over 1 deg",
        ],
        "delay 5 ms": [
            "within 20 % 5 of 11",
            "pva T1 4.54 (12.8) x1.08",
            "pva T2 4.23 (14.1) x1.44",
            "pva T3 3.92 (13.1) x1.31",
            "ffpva T1 1.58 (6.6) x1.13",
            "ffpva T2 2.52 (6.1) x1.21",
            "ffpva T3 2.44 (7.0) x1.17",
            "ffpva T4 1.89 (7.2) x0.97",
            "smc T1 1.65 (6.4) x1.39",
            "smc T2 2.61 (5.9) x1.68",
            "smc T3 2.60 (6.8) x1.54",
            "smc T4 2.16 (6.8) x1.19",
            "pva T1 move 4.32 hold 4.65 SSE ±5.93 / ±6.09, runs end 4.67-6.09 off, 10 of 10 over 1 deg",
        ],
        "delay 6 ms": [
            "within 20 % 4 of 11",
            "pva T1 4.57 (15.5) x1.09",
            "pva T2 5.25 (15.1) x1.79",
            "pva T3 4.53 (14.6) x1.51",
            "ffpva T1 1.58 (6.8) x1.13",
            "ffpva T2 2.56 (6.1) x1.23",
            "ffpva T3 2.54 (7.1) x1.21",
            "ffpva T4 1.94 (7.5) x1.00",
            "smc T1 1.65 (6.6) x1.39",
            "smc T2 2.67 (6.1) x1.73",
            "smc T3 2.69 (7.1) x1.59",
            "smc T4 2.08 (7.0) x1.14",
            "pva T1 move 4.99 hold 4.95 SSE ±5.59 / ±4.70, runs end 0.20-5.59 off, 6 of 10 over 1 deg",
        ],
        "delay 8 ms": [
            "within 20 % 1 of 11",
            "pva T1 8.43 (18.3) x2.01",
            "pva T2 6.45 (18.1) x2.20",
            "pva T3 6.27 (19.2) x2.09",
            "ffpva T1 1.70 (7.3) x1.21",
            "ffpva T2 2.74 (6.6) x1.32",
            "ffpva T3 2.68 (7.5) x1.28",
            "ffpva T4 2.01 (7.9) x1.03",
            "smc T1 1.74 (6.9) x1.46",
            "smc T2 2.82 (6.3) x1.82",
            "smc T3 2.85 (7.3) x1.68",
            "smc T4 2.19 (7.3) x1.21",
            "pva T1 move 7.12 hold 9.01 SSE ±7.37 / ±13.58, runs end 0.06-13.58 off, 5 of 10 over 1 deg",
        ],
    }


# What trial_smc_compensation prints, per preset: its first two lines' ends, then each reading's row and T3 line.
SMC_COMPENSATION = {
    "ninth": (  # the ninth refit's preset, as first run (2026-11-27)
        "FF + PVA T1-T4 1.60 / 2.20 / 2.14 / 1.82, PVA + DZC T1-T3 1.66 / 2.75 / 2.89",
        "FF + PVA: 2.14 / 2.41 / 2.64 / 2.19 / 2.45 / 3.49",
        {"as the thesis gives it": (
            "within 20 % 6 of 9, ahead of FF + PVA on 1 of 4, order right on 1 of 4 | T1 0 g H 1.34 x1.12 | "
            "T2 0 g H 2.25 x1.45 | T3 0 g H 2.25 x1.33 | T4 0 g H 1.95 x1.07 | T1 6.5 g H 1.38 x1.06 | "
            "T1 13.5 g H 1.57 x1.28 | T1 0 g V 1.41 x0.90 | T1 6.5 g V 1.71 x1.13 | T1 13.5 g V 3.48 x1.00",
            "T3 sliding mode 2.25 / 2.58 / 2.72 / 2.26 / 2.59 / 3.49, ahead of FF + PVA on 1 of 6"),
         "on the held part": (
            "within 20 % 7 of 9, ahead of FF + PVA on 4 of 4, order right on 4 of 4 | T1 0 g H 1.21 x1.01 | "
            "T2 0 g H 2.07 x1.34 | T3 0 g H 2.03 x1.20 | T4 0 g H 1.57 x0.86 | T1 6.5 g H 1.26 x0.96 | "
            "T1 13.5 g H 1.44 x1.18 | T1 0 g V 1.35 x0.86 | T1 6.5 g V 1.37 x0.91 | T1 13.5 g V 3.35 x0.96",
            "T3 sliding mode 2.03 / 2.20 / 2.45 / 2.06 / 2.22 / 3.09, ahead of FF + PVA on 6 of 6"),
         "on the sum": (
            "within 20 % 5 of 9, ahead of FF + PVA on 4 of 4, order right on 4 of 4 | T1 0 g H 0.96 x0.81 | "
            "T2 0 g H 1.61 x1.04 | T3 0 g H 1.56 x0.92 | T4 0 g H 1.29 x0.71 | T1 6.5 g H 1.03 x0.79 | "
            "T1 13.5 g H 1.15 x0.94 | T1 0 g V 0.97 x0.62 | T1 6.5 g V 1.12 x0.74 | T1 13.5 g V 3.22 x0.92",
            "T3 sliding mode 1.56 / 1.71 / 1.92 / 1.57 / 1.80 / 2.77, ahead of FF + PVA on 6 of 6")}),
    "tenth": (  # the tenth refit's preset (twin/plants/data/tenth_refit.json), committed when run (stop 39, as "committed")
        "FF + PVA T1-T4 1.45 / 2.42 / 2.37 / 1.87, PVA + DZC T1-T3 1.88 / 2.84 / 3.01",
        "FF + PVA: 2.37 / 2.64 / 2.88 / 2.30 / 2.61 / 3.71",
        {"as the thesis gives it": (
            "within 20 % 6 of 9, ahead of FF + PVA on 4 of 4, order right on 4 of 4 | T1 0 g H 1.36 x1.14 | "
            "T2 0 g H 2.29 x1.48 | T3 0 g H 2.20 x1.30 | T4 0 g H 1.72 x0.95 | T1 6.5 g H 1.44 x1.10 | "
            "T1 13.5 g H 1.50 x1.23 | T1 0 g V 1.47 x0.94 | T1 6.5 g V 1.61 x1.06 | T1 13.5 g V 3.38 x0.97",
            "T3 sliding mode 2.20 / 2.43 / 2.61 / 2.23 / 2.45 / 3.45, ahead of FF + PVA on 6 of 6"),
         "on the held part": (
            "within 20 % 7 of 9, ahead of FF + PVA on 4 of 4, order right on 4 of 4 | T1 0 g H 1.28 x1.08 | "
            "T2 0 g H 2.22 x1.43 | T3 0 g H 2.10 x1.24 | T4 0 g H 1.72 x0.94 | T1 6.5 g H 1.34 x1.02 | "
            "T1 13.5 g H 1.36 x1.12 | T1 0 g V 1.43 x0.91 | T1 6.5 g V 1.37 x0.91 | T1 13.5 g V 3.20 x0.92",
            "T3 sliding mode 2.10 / 2.27 / 2.42 / 2.13 / 2.25 / 3.09, ahead of FF + PVA on 6 of 6"),
         "on the sum": (
            "within 20 % 7 of 9, ahead of FF + PVA on 4 of 4, order right on 4 of 4 | T1 0 g H 1.09 x0.91 | "
            "T2 0 g H 1.93 x1.25 | T3 0 g H 1.83 x1.08 | T4 0 g H 1.47 x0.81 | T1 6.5 g H 1.12 x0.85 | "
            "T1 13.5 g H 1.12 x0.92 | T1 0 g V 1.14 x0.72 | T1 6.5 g V 1.35 x0.90 | T1 13.5 g V 3.18 x0.92",
            "T3 sliding mode 1.83 / 1.85 / 2.02 / 1.85 / 1.90 / 2.85, ahead of FF + PVA on 6 of 6")}),
}


@pytest.mark.slow  # about 40 s each on 2 cores: sliding mode three ways on nine cells and T3's six, ten seeds
@pytest.mark.parametrize("preset", sorted(SMC_COMPENSATION))
def test_trial_smc_compensation_prints_what_the_docs_quote(capsys, preset):
    from controllers import smc
    from twin.plants import as_built

    as_given = smc.SlidingMode.update
    trial = load_trial("trial_smc_compensation")
    trial.main(preset)
    assert smc.SlidingMode.update is as_given  # the trial puts the thesis's law back
    out = capsys.readouterr().out.splitlines()
    first, second, readings = SMC_COMPENSATION[preset]
    assert out[0].startswith(f"as-built preset {as_built.preset_digest(trial.PRESETS[preset])} ({preset})")
    assert out[0].endswith(first) and out[1].endswith(second)
    rows = {line[:24].strip(): line[24:].strip() for line in out[2::2]}
    t3 = dict(zip(rows, (line.strip() for line in out[3::2]), strict=True))
    assert {label: (rows[label], t3[label]) for label in rows} == readings


CHAMBER_RERUN = ("air 0.12", "leak 0")  # the moved rows CI runs again beside the committed one (all thirteen with
# --every-kept-row): the most air (past its box) and no leak at all; docs/testing.md


@pytest.mark.slow  # 222 s in stop 55's CI for its three rows; all fourteen (--every-kept-row): 301 s at stop 52
def test_trial_chamber_buildup_prints_what_the_docs_quote(capsys, every_kept_row):
    """The trial's table as the docs quote it. Since stop 55 (2026-12-07) CI runs the committed row and two of the
    thirteen moved ones again (:data:`CHAMBER_RERUN`); all fourteen run with --every-kept-row."""
    load_trial("trial_chamber_buildup").main(None if every_kept_row else CHAMBER_RERUN)
    rows = {line.split(" | ", 1)[0].strip(): line.split(" | ", 1)[1]
            for line in capsys.readouterr().out.splitlines()[1:]}
    # values -> costs on four seed sets | paired difference | within 20 % | PVA T1 (largest), SMC T2, T3, FF + PVA T1
    # | open-loop lag (ms) | the twelve T3 cells
    kept = {
        "committed":
            "0.559 / 0.757 / 0.741 / 0.895 | +0.000 (+0.000 to +0.000) | 17 | 1.72 (7.7), 2.26, 2.23, 1.59 | 74 | 2.07 / 2.43 / 2.63 / 2.15 / 2.47 / 3.51; 2.21 / 2.61 / 2.73 / 2.28 / 2.59 / 3.42",
        "air 0.01":
            "1.123 / 1.561 / 1.380 / 1.506 | +0.654 (+0.564 to +0.804) | 7 | 1.92 (7.9), 2.63, 2.63, 1.74 | 116 | 2.61 / 3.62 / 3.51 / 2.61 / 3.72 / 5.19; 2.64 / 3.90 / 3.98 / 2.55 / 3.86 / 4.99",
        "air 0.02":
            "0.661 / 1.132 / 0.828 / 0.834 | +0.126 (-0.062 to +0.374) | 15 | 1.85 (7.6), 2.37, 2.40, 1.43 | 74 | 2.32 / 2.45 / 2.63 / 2.40 / 2.50 / 3.67; 2.39 / 2.59 / 2.90 / 2.39 / 2.70 / 3.83",
        "air 0.025":
            "0.741 / 0.986 / 0.947 / 0.747 | +0.117 (-0.149 to +0.229) | 15 | 1.80 (7.8), 2.27, 2.30, 1.18 | 74 | 2.15 / 2.34 / 2.58 / 2.19 / 2.45 / 3.53; 2.28 / 2.51 / 2.82 / 2.31 / 2.57 / 3.55",
        "air 0.03":
            "0.681 / 0.903 / 0.861 / 0.767 | +0.065 (-0.128 to +0.145) | 16 | 1.67 (7.6), 2.26, 2.18, 1.22 | 74 | 2.17 / 2.40 / 2.69 / 2.15 / 2.46 / 3.41; 2.18 / 2.48 / 2.67 / 2.23 / 2.53 / 3.53",
        "air 0.04":
            "0.588 / 0.927 / 0.715 / 0.857 | +0.034 (-0.038 to +0.170) | 17 | 1.72 (8.1), 2.21, 2.15, 1.40 | 74 | 2.17 / 2.49 / 2.72 / 2.20 / 2.51 / 3.47; 2.13 / 2.40 / 2.57 / 2.22 / 2.46 / 3.33",
        "air 0.05":
            "0.657 / 0.902 / 0.734 / 0.746 | +0.022 (-0.150 to +0.144) | 17 | 1.84 (8.4), 2.21, 2.12, 1.36 | 74 | 2.21 / 2.64 / 2.85 / 2.18 / 2.58 / 3.63; 2.14 / 2.36 / 2.52 / 2.09 / 2.37 / 3.27",
        "air 0.06":
            "0.673 / 0.911 / 0.892 / 0.883 | +0.102 (-0.013 to +0.154) | 16 | 1.87 (8.9), 2.24, 2.14, 1.50 | 74 | 2.21 / 2.73 / 3.09 / 2.20 / 2.70 / 3.66; 2.13 / 2.32 / 2.54 / 2.14 / 2.41 / 3.33",
        "air 0.08":
            "0.956 / 0.998 / 0.959 / 0.864 | +0.206 (-0.031 to +0.397) | 15 | 2.03 (9.2), 2.25, 2.11, 1.51 | 74 | 2.35 / 2.96 / 3.38 / 2.25 / 2.86 / 3.86; 2.16 / 2.30 / 2.74 / 2.16 / 2.37 / 3.40",
        "air 0.12":
            "1.189 / 1.385 / 1.135 / 1.198 | +0.488 (+0.302 to +0.630) | 14 | 3.49 (11.6), 2.19, 2.11, 1.61 | 90 | 2.36 / 2.87 / 3.89 / 2.41 / 2.97 / 4.18; 2.08 / 2.46 / 2.77 / 2.06 / 2.48 / 3.52",
        "leak 0":
            "1.637 / 1.609 / 1.778 / 1.763 | +0.959 (+0.852 to +1.078) | 12 | 2.10 (7.7), 2.24, 2.26, 1.59 | 74 | 2.15 / 2.46 / 2.63 / 2.15 / 2.45 / 3.43; 2.24 / 2.51 / 2.81 / 2.23 / 2.58 / 3.46",
        "leak 3e-14":
            "0.729 / 0.961 / 0.858 / 0.811 | +0.102 (-0.084 to +0.204) | 16 | 1.67 (7.7), 2.23, 2.21, 1.24 | 67 | 2.14 / 2.39 / 2.64 / 2.14 / 2.41 / 3.43; 2.25 / 2.55 / 2.77 / 2.20 / 2.54 / 3.40",
        "leak 6e-14":
            "0.994 / 0.961 / 0.903 / 0.859 | +0.191 (-0.036 to +0.436) | 15 | 1.69 (7.6), 2.19, 2.15, 1.27 | 47 | 2.06 / 2.32 / 2.53 / 2.08 / 2.36 / 3.47; 2.19 / 2.48 / 2.68 / 2.15 / 2.54 / 3.36",
        "leak 1.2e-13":
            "1.149 / 0.834 / 1.022 / 0.877 | +0.232 (-0.018 to +0.590) | 15 | 1.72 (7.4), 2.18, 2.07, 1.34 | 18 | 1.84 / 2.25 / 2.42 / 1.94 / 2.28 / 3.34; 2.10 / 2.42 / 2.50 / 2.10 / 2.47 / 3.41",
    }
    assert list(rows) == (list(kept) if every_kept_row else ["committed", *CHAMBER_RERUN]) and CHAMBER_RERUN
    assert rows == {name: kept[name] for name in rows}


def test_the_chamber_trial_refuses_a_row_it_does_not_have():
    with pytest.raises(ValueError, match="no such row: air 0.5; the rows are air 0.01, "):
        load_trial("trial_chamber_buildup").main(["air 0.5"])


@pytest.mark.slow  # about 90 s on 2 cores: the 21 measured cells and T3's 12, five seeds, eight ways; 3 s shut
def test_trial_initial_pressure_prints_what_investigations_md_quotes(capsys):
    load_trial("trial_initial_pressure").main()
    out = capsys.readouterr().out.splitlines()
    assert out[0] == ("as-built preset 1c2dcd8c9f7f (committed), seeds 0-4; chambers starting at 0.5 of the supply "
                      "give the committed runs bit for bit: True")
    assert out[1] == "shut from half the supply, chambers A / B (kPa): 0 s 150 / 150, 1 s 98 / 106, 2 s 72 / 83, 2.999 s 57 / 67"
    rows = {line.split(": ", 1)[0]: line.split(": ", 1)[1].split(" | ") for line in out[2:9]}
    # variant -> cells within 20 % and SSE ranges within ±0.5 deg, then each cell's mean RMSE (and T1's SSE range)
    assert rows == {
        "start at 0 of the supply": [
            "within 20 % 16 of 21, SSE ranges within 12 of 13",
            "PVA T1 1.95 (±0.52)",
            "PVA T2 2.91",
            "PVA T3 3.05",
            "FF+PVA T1 1.63 (±0.49)",
            "FF+PVA T2 2.47",
            "FF+PVA T3 2.38",
            "FF+PVA T4 2.05",
            "SMC T1 1.32 (±0.48)",
            "SMC T2 2.31",
            "SMC T3 2.21",
            "SMC T4 1.77",
            "FF+PVA T1 6.5gH 1.92 (±1.58)",
            "FF+PVA T1 13.5gH 1.95 (±1.68)",
            "FF+PVA T1 0gV 1.71 (±0.88)",
            "FF+PVA T1 6.5gV 1.87 (±1.22)",
            "FF+PVA T1 13.5gV 3.85 (±2.24)",
            "SMC T1 6.5gH 1.50 (±0.40)",
            "SMC T1 13.5gH 1.57 (±0.47)",
            "SMC T1 0gV 1.47 (±1.02)",
            "SMC T1 6.5gV 1.88 (±0.66)",
            "SMC T1 13.5gV 3.52 (±1.32)",
        ],
        "start at 0.25 of the supply": [
            "within 20 % 16 of 21, SSE ranges within 9 of 13",
            "PVA T1 1.97 (±0.39)",
            "PVA T2 2.96",
            "PVA T3 3.03",
            "FF+PVA T1 1.49 (±0.50)",
            "FF+PVA T2 2.39",
            "FF+PVA T3 2.38",
            "FF+PVA T4 1.97",
            "SMC T1 1.48 (±0.46)",
            "SMC T2 2.33",
            "SMC T3 2.18",
            "SMC T4 1.81",
            "FF+PVA T1 6.5gH 1.71 (±0.52)",
            "FF+PVA T1 13.5gH 2.06 (±1.47)",
            "FF+PVA T1 0gV 1.58 (±0.72)",
            "FF+PVA T1 6.5gV 1.93 (±2.04)",
            "FF+PVA T1 13.5gV 3.76 (±1.36)",
            "SMC T1 6.5gH 1.48 (±0.54)",
            "SMC T1 13.5gH 1.50 (±0.47)",
            "SMC T1 0gV 1.55 (±1.02)",
            "SMC T1 6.5gV 1.75 (±1.20)",
            "SMC T1 13.5gV 3.40 (±1.08)",
        ],
        "start at 0.5 of the supply": [
            "within 20 % 17 of 21, SSE ranges within 9 of 13",
            "PVA T1 1.86 (±0.52)",
            "PVA T2 2.91",
            "PVA T3 3.04",
            "FF+PVA T1 1.53 (±0.55)",
            "FF+PVA T2 2.37",
            "FF+PVA T3 2.38",
            "FF+PVA T4 2.00",
            "SMC T1 1.42 (±0.50)",
            "SMC T2 2.30",
            "SMC T3 2.21",
            "SMC T4 1.78",
            "FF+PVA T1 6.5gH 1.52 (±0.47)",
            "FF+PVA T1 13.5gH 1.92 (±1.49)",
            "FF+PVA T1 0gV 1.48 (±1.65)",
            "FF+PVA T1 6.5gV 1.83 (±1.32)",
            "FF+PVA T1 13.5gV 4.05 (±1.12)",
            "SMC T1 6.5gH 1.33 (±0.54)",
            "SMC T1 13.5gH 1.47 (±0.48)",
            "SMC T1 0gV 1.52 (±0.88)",
            "SMC T1 6.5gV 1.66 (±1.11)",
            "SMC T1 13.5gV 3.32 (±0.84)",
        ],
        "start at 0.75 of the supply": [
            "within 20 % 18 of 21, SSE ranges within 8 of 13",
            "PVA T1 1.86 (±0.49)",
            "PVA T2 3.06",
            "PVA T3 2.98",
            "FF+PVA T1 1.49 (±0.42)",
            "FF+PVA T2 2.45",
            "FF+PVA T3 2.36",
            "FF+PVA T4 1.92",
            "SMC T1 1.32 (±0.50)",
            "SMC T2 2.31",
            "SMC T3 2.25",
            "SMC T4 1.78",
            "FF+PVA T1 6.5gH 1.51 (±0.48)",
            "FF+PVA T1 13.5gH 1.87 (±0.41)",
            "FF+PVA T1 0gV 1.63 (±1.65)",
            "FF+PVA T1 6.5gV 1.82 (±1.39)",
            "FF+PVA T1 13.5gV 3.97 (±1.24)",
            "SMC T1 6.5gH 1.38 (±0.54)",
            "SMC T1 13.5gH 1.46 (±0.47)",
            "SMC T1 0gV 1.59 (±0.88)",
            "SMC T1 6.5gV 1.61 (±1.11)",
            "SMC T1 13.5gV 3.42 (±0.78)",
        ],
        "start at 1 of the supply": [
            "within 20 % 18 of 21, SSE ranges within 9 of 13",
            "PVA T1 1.86 (±0.49)",
            "PVA T2 2.88",
            "PVA T3 2.97",
            "FF+PVA T1 1.52 (±0.53)",
            "FF+PVA T2 2.45",
            "FF+PVA T3 2.41",
            "FF+PVA T4 2.00",
            "SMC T1 1.35 (±0.50)",
            "SMC T2 2.32",
            "SMC T3 2.19",
            "SMC T4 1.77",
            "FF+PVA T1 6.5gH 1.48 (±0.50)",
            "FF+PVA T1 13.5gH 1.88 (±0.40)",
            "FF+PVA T1 0gV 1.62 (±1.65)",
            "FF+PVA T1 6.5gV 1.82 (±1.28)",
            "FF+PVA T1 13.5gV 3.97 (±1.35)",
            "SMC T1 6.5gH 1.36 (±0.54)",
            "SMC T1 13.5gH 1.45 (±0.48)",
            "SMC T1 0gV 1.58 (±0.88)",
            "SMC T1 6.5gV 1.59 (±1.11)",
            "SMC T1 13.5gV 3.36 (±0.67)",
        ],
        "held 1 s at the start angle first": [
            "within 20 % 16 of 21, SSE ranges within 10 of 13",
            "PVA T1 1.89 (±0.54)",
            "PVA T2 2.82",
            "PVA T3 3.07",
            "FF+PVA T1 1.46 (±0.62)",
            "FF+PVA T2 2.42",
            "FF+PVA T3 2.41",
            "FF+PVA T4 1.86",
            "SMC T1 1.48 (±0.59)",
            "SMC T2 2.26",
            "SMC T3 2.17",
            "SMC T4 1.82",
            "FF+PVA T1 6.5gH 1.71 (±0.53)",
            "FF+PVA T1 13.5gH 1.69 (±0.58)",
            "FF+PVA T1 0gV 1.71 (±1.37)",
            "FF+PVA T1 6.5gV 1.63 (±1.19)",
            "FF+PVA T1 13.5gV 3.83 (±1.24)",
            "SMC T1 6.5gH 1.38 (±0.36)",
            "SMC T1 13.5gH 1.50 (±0.63)",
            "SMC T1 0gV 1.55 (±0.66)",
            "SMC T1 6.5gV 1.77 (±0.80)",
            "SMC T1 13.5gV 3.54 (±1.05)",
        ],
        "held 3 s at the start angle first": [
            "within 20 % 16 of 21, SSE ranges within 9 of 13",
            "PVA T1 1.88 (±0.34)",
            "PVA T2 2.73",
            "PVA T3 3.05",
            "FF+PVA T1 1.87 (±0.51)",
            "FF+PVA T2 2.43",
            "FF+PVA T3 2.50",
            "FF+PVA T4 1.93",
            "SMC T1 1.33 (±0.60)",
            "SMC T2 2.31",
            "SMC T3 2.28",
            "SMC T4 1.80",
            "FF+PVA T1 6.5gH 1.54 (±0.44)",
            "FF+PVA T1 13.5gH 2.10 (±0.53)",
            "FF+PVA T1 0gV 1.75 (±0.85)",
            "FF+PVA T1 6.5gV 1.83 (±1.83)",
            "FF+PVA T1 13.5gV 3.90 (±2.73)",
            "SMC T1 6.5gH 1.43 (±0.48)",
            "SMC T1 13.5gH 1.53 (±0.49)",
            "SMC T1 0gV 1.44 (±0.81)",
            "SMC T1 6.5gV 1.60 (±0.87)",
            "SMC T1 13.5gV 3.36 (±0.64)",
        ],
    }
    assert out[9:] == [  # T3's cells in each variant: the blind prediction's, committed preset, seeds 0-4
        "T3, start at 0 of the supply (FF+PVA / SMC): "
        "0gH 2.38 / 2.21 | 6.5gH 2.64 / 2.40 | 13.5gH 2.85 / 2.56 | 0gV 2.36 / 2.20 | 6.5gV 2.69 / 2.44 | 13.5gV 3.61 / 3.42 | SMC ahead on 6 of 6",
        "T3, start at 0.25 of the supply (FF+PVA / SMC): "
        "0gH 2.38 / 2.18 | 6.5gH 2.63 / 2.38 | 13.5gH 2.88 / 2.60 | 0gV 2.40 / 2.23 | 6.5gV 2.68 / 2.45 | 13.5gV 3.73 / 3.45 | SMC ahead on 6 of 6",
        "T3, start at 0.5 of the supply (FF+PVA / SMC): "
        "0gH 2.38 / 2.21 | 6.5gH 2.58 / 2.42 | 13.5gH 2.86 / 2.61 | 0gV 2.33 / 2.22 | 6.5gV 2.60 / 2.41 | 13.5gV 3.66 / 3.42 | SMC ahead on 6 of 6",
        "T3, start at 0.75 of the supply (FF+PVA / SMC): "
        "0gH 2.36 / 2.25 | 6.5gH 2.73 / 2.42 | 13.5gH 2.99 / 2.61 | 0gV 2.36 / 2.26 | 6.5gV 2.68 / 2.42 | 13.5gV 3.77 / 3.38 | SMC ahead on 6 of 6",
        "T3, start at 1 of the supply (FF+PVA / SMC): "
        "0gH 2.41 / 2.19 | 6.5gH 2.60 / 2.44 | 13.5gH 3.00 / 2.64 | 0gV 2.37 / 2.27 | 6.5gV 2.70 / 2.45 | 13.5gV 3.71 / 3.47 | SMC ahead on 6 of 6",
        "T3, held 1 s at the start angle first (FF+PVA / SMC): "
        "0gH 2.41 / 2.17 | 6.5gH 2.62 / 2.42 | 13.5gH 2.93 / 2.65 | 0gV 2.47 / 2.23 | 6.5gV 2.76 / 2.47 | 13.5gV 3.72 / 3.42 | SMC ahead on 6 of 6",
        "T3, held 3 s at the start angle first (FF+PVA / SMC): "
        "0gH 2.50 / 2.28 | 6.5gH 2.69 / 2.41 | 13.5gH 2.88 / 2.55 | 0gV 2.47 / 2.22 | 6.5gV 2.65 / 2.41 | 13.5gV 3.70 / 3.51 | SMC ahead on 6 of 6",
    ]


def test_the_smc_lead_trials_ratio_error_and_reading_are_the_closed_forms():
    """The lead's standard error is the first-order one, r sqrt((s1/m1)^2 + (s2/m2)^2); the reading turns at two
    combined standard errors either way; the cells are the nine both laws were measured on, §8's four first."""
    import math

    trial = load_trial("trial_smc_lead")
    ratio, error = trial.lead((1.0, 0.1), (2.0, 0.0))
    assert ratio == 0.5 and error == pytest.approx(0.05, rel=1e-15)
    ratio, error = trial.lead((1.2, 0.06), (1.5, 0.15))
    assert ratio == pytest.approx(0.8) and error == pytest.approx(0.8 * math.sqrt(0.05 ** 2 + 0.1 ** 2), rel=1e-14)
    assert trial.TIE == 2.0
    for z, said in ((2.001, "weaker"), (1.999, "not told apart"), (-1.999, "not told apart"), (-2.001, "stronger")):
        reading, back = trial.against_rig((0.75 + z * 0.05, 0.03), (0.75, 0.04))  # combined error 0.05
        assert reading == said and back == pytest.approx(z, rel=1e-12)
    assert trial.cells() == [(1, 0.0, "horizontal"), (2, 0.0, "horizontal"), (3, 0.0, "horizontal"),
                             (4, 0.0, "horizontal"), (1, 6.5, "horizontal"), (1, 13.5, "horizontal"),
                             (1, 0.0, "vertical"), (1, 6.5, "vertical"), (1, 13.5, "vertical")]


@pytest.mark.slow  # about 50 s on 2 cores: nine cells x two laws x 45 seeds
def test_the_smc_lead_trial_runs_again_to_what_it_kept(capsys):
    load_trial("trial_smc_lead").main()
    assert capsys.readouterr().out == (ROOT / "examples" / "trial_smc_lead" / "lead.txt").read_text()


def test_the_docs_quote_the_smc_lead_trials_kept_output():
    """investigations.md's stop-51 tables and counts, and as-built.md's, are lead.txt's; the rig's leads in it are
    the thesis's means (reference.py) recomputed, and each reading agrees with its z."""
    from twin.experiments.calibrate import TARGET_OF

    printed = (ROOT / "examples" / "trial_smc_lead" / "lead.txt").read_text()
    assert "by over 2 combined standard errors" in printed.splitlines()[0]
    text = (ROOT / "docs" / "investigations.md").read_text(encoding="utf-8")
    section = text[text.index("## Sliding mode's lead over FF + PVA, on the rig"):].split("\n## ")[0]
    flat = " ".join(section.split())
    rows = re.findall(r"^  (T\d(?: [\d.]+ g \w+)?) +([\d.]+) ± ([\d.]+) +([\d.]+ ± [\d.]+) +([\d.]+) ± ([\d.]+)  "
                      r"([a-z ]+) \(([-+][\d.]+)\);", printed, re.M)
    assert len(rows) == 9
    for cell, rig, rig_error, first, fresh, fresh_error, said, z in rows:
        assert f"| {cell} | {rig} ± {rig_error} | {first} | {fresh} ± {fresh_error} | {said} ({z}) |" in section, cell
        t, g, o = (int(cell[1]), float(cell.split()[1]), cell.split()[-1]) if " g " in cell else (
            int(cell[1]), 0.0, "horizontal")
        assert rig == f"{TARGET_OF[('smc', t, g, o)].rmse_deg / TARGET_OF[('ffpva', t, g, o)].rmse_deg:.2f}"
        assert said == ("weaker" if float(z) > 2 else "stronger" if float(z) < -2 else "not told apart")
    summary = re.search(r"the twin's lead over the rig's: (x[\d.]+-x[\d.]+) \(median (x[\d.]+)\); weaker on (\d) of 9, "
                        r"stronger on (\d), not told apart on \d; the twin's lead smaller than the rig's on (\d) of 9",
                        printed)
    assert summary is not None
    span, median, weaker, stronger, smaller = summary.groups()
    assert stronger == "0" and "stronger on none" in flat
    assert f"Its lead is {span} the rig's (median {median}): weaker on {weaker} of 9, stronger on none, smaller on " \
        f"{smaller} of 9." in flat
    near = sorted(z for *_, said, z in rows if said == "weaker")[:2]
    assert f"(z {near[0]} and {near[1]};" in flat and all(float(z) < 2.4 for z in near)
    moves = re.findall(r"^  (T1(?: [\d.]+ g \w+)?) +FF \+ PVA RMS [\d.]+ \((\d+)% of the run's squared error\), "
                       r"([\d.]+)/s, error at opening ([\d.]+), advance ([\d.]+); sliding mode RMS [\d.]+ \((\d+)% of the "
                       r"run's squared error\), ([\d.]+)/s, error at opening ([\d.]+), advance ([\d.]+); gap ([-+][\d.]+), "
                       r"lead (x[\d.]+) the rig's$", printed, re.M)
    assert len(moves) == 6
    for cell, _, _, ff_error, ff_advance, _, _, smc_error, smc_advance, gap, shortfall in moves:
        assert f"  | {cell} | {ff_error}, {ff_advance} | {smc_error}, {smc_advance} | {gap} | {shortfall} |" in section
        assert float(gap) > 0  # "in each of the six T1 cells ... at a larger error"
    widest = max(moves, key=lambda m: float(m[9]))
    assert widest[0] == "T1 0 g vertical" and "it is largest on T1 0 g vertical, where the twin's lead is the rig's" in flat
    assert float(widest[10][1:]) == pytest.approx(1.0, abs=0.025)
    shares = [int(m[1]) for m in moves] + [int(m[5]) for m in moves]
    rates = [float(m[2]) for m in moves] + [float(m[6]) for m in moves]
    assert f"({moves[0][1]} % and {moves[0][5]} % on the flat cell" in flat
    assert f"{min(shares)}-{max(shares)} % over the six cells" in flat
    assert f"{min(rates):.0f}-{max(rates):.0f} openings a second" in flat
    assert "a median over 60-140 openings" in flat  # five runs of one second each, rounded to tens
    assert (round(5 * min(rates), -1), round(5 * max(rates), -1)) == (60, 140)
    flat_13 = next(r for r in rows if r[0] == "T1 13.5 g horizontal")
    ffpva_13 = float(re.search(r"^  T1 13.5 g horizontal .*, [\d.]+ / ([\d.]+)$", printed, re.M).group(1))
    assert f"x{ffpva_13 / TARGET_OF[('ffpva', 1, 13.5, 'horizontal')].rmse_deg:.2f} on the fresh seeds" in flat
    assert f"the rig's sliding mode tracked at {flat_13[1]} of its FF + PVA and the twin's at {flat_13[4]}" in flat
    as_built = doc_text("as-built.md")
    assert (f"on {smaller} of the 9 cells both were measured on (weaker by two standard errors on {weaker}, the three "
            f"misses among them; on this cell {flat_13[4]} against {flat_13[1]}), and by more on none") in as_built


@pytest.mark.slow  # about 10 s on 2 cores: two laws on T1-T4, ten seeds, two ways
def test_trial_subtick_coil_prints_what_investigations_md_quotes(capsys):
    load_trial("trial_subtick_coil").main()
    out = capsys.readouterr().out.splitlines()
    assert out == ["whole ticks  ffpva 1.62 / 2.24 / 2.19 / 1.95  smc 1.40 / 2.26 / 2.29 / 1.89",
                   "sub-tick     ffpva 1.67 / 2.29 / 2.26 / 2.02  smc 1.47 / 2.30 / 2.41 / 2.20"]
    (whole_ffpva, whole_smc), (sub_ffpva, sub_smc) = ([part.split(maxsplit=1)[1] for part in line[13:].split("  ")]
                                                      for line in out)
    assert (f"Sliding mode then tracked T1-T4 at {sub_smc} deg, against {whole_smc} with whole ticks. FF + PVA "
            f"tracked at {sub_ffpva}, against {whole_ffpva}.") in doc_text("investigations.md")


@pytest.mark.slow  # about 40 s on 2 cores: two laws on T4, nine members, 45 seeds
def test_trial_t4_order_prints_what_investigations_md_quotes(capsys):
    load_trial("trial_t4_order").main()
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "0 CCW 1.161 load 0.29 K_OB 340 leak 1.39e-14 | seeds 0-4: FF + PVA 1.722, SMC 1.904 | seeds 40-79: FF + PVA 1.735, SMC 1.806",
        "1 CCW 1.161 load 0.38 K_OB 340 leak 1.16e-14 | seeds 0-4: FF + PVA 1.879, SMC 2.012 | seeds 40-79: FF + PVA 1.821, SMC 1.813",
        "2 CCW 1.161 load 0.29 K_OB 272 leak 1.39e-14 | seeds 0-4: FF + PVA 1.695, SMC 1.979 | seeds 40-79: FF + PVA 1.738, SMC 1.856",
        "3 CCW 1.067 load 0.29 K_OB 340 leak 1.39e-14 | seeds 0-4: FF + PVA 1.815, SMC 1.742 | seeds 40-79: FF + PVA 1.814, SMC 1.784",
        "4 CCW 1.269 load 0.29 K_OB 340 leak 1.39e-14 | seeds 0-4: FF + PVA 2.057, SMC 1.966 | seeds 40-79: FF + PVA 2.125, SMC 1.911",
        "5 CCW 1.141 load 0.29 K_OB 340 leak 1.39e-14 | seeds 0-4: FF + PVA 1.586, SMC 1.808 | seeds 40-79: FF + PVA 1.634, SMC 1.827",
        "6 CCW 1.161 load 0.29 K_OB 340 leak 1.50e-14 | seeds 0-4: FF + PVA 1.675, SMC 1.785 | seeds 40-79: FF + PVA 1.714, SMC 1.805",
        "7 CCW 1.161 load 0.30 K_OB 340 leak 1.39e-14 | seeds 0-4: FF + PVA 1.722, SMC 1.904 | seeds 40-79: FF + PVA 1.735, SMC 1.806",
        "8 CCW 1.151 load 0.29 K_OB 340 leak 1.39e-14 | seeds 0-4: FF + PVA 1.613, SMC 1.897 | seeds 40-79: FF + PVA 1.664, SMC 1.830",
    ]
    verdict = [re.search(r"seeds 0-4: FF \+ PVA (\d\.\d+), SMC (\d\.\d+)", line).groups() for line in out]
    right = sum(float(smc) < float(ffpva) for ffpva, smc in verdict)  # the rig: sliding mode ahead on T4
    ffpva, smc = (f"{float(x):.2f}" for x in verdict[0])  # member 0: the ninth refit's fitted values
    text = doc_text("investigations.md")
    assert f"T4 had turned (FF + PVA {ffpva} against sliding mode {smc}, measured 1.95 and 1.82)" in text
    assert f"and was right on {right} of the {len(out)} on seeds 0-4" in text


@pytest.mark.slow  # about 10 s on 2 cores: FF + PVA T1 flat and on its side, with and without the leak, 40 seeds
def test_trial_vertical_hold_prints_what_investigations_md_quotes(capsys):
    load_trial("trial_vertical_hold").main()
    out = capsys.readouterr().out.splitlines()
    assert out[1:] == [
        "fitted leak  horizontal    1.63   1.33              2.30              0.34           0.879      5.33  +0.04 +- 0.33",
        "fitted leak  vertical      1.39   0.88              1.22              0.65           0.875      5.35  -0.00 +- 0.69",
        "no leak      horizontal    1.57   1.28              1.31              1.28           0.879      6.40  -1.01 +- 0.83",
        "no leak      vertical      1.37   0.91              0.92              0.91           0.851      6.41  -0.28 +- 0.89",
    ]
    row = {" ".join(line.split()[:3]): line.split()[3:] for line in out[1:]}
    leak_h, leak_v, dry_h, dry_v = (row[k] for k in ("fitted leak horizontal", "fitted leak vertical",
                                                       "no leak horizontal", "no leak vertical"))
    text = doc_text("investigations.md")
    for quoted in (f"tracks better on its side than flat: {leak_v[0]} against {leak_h[0]} deg",
                   f"RMS error {leak_v[1]} on its side against {leak_h[1]} flat",
                   f"the hold gives {dry_v[1]} against {dry_h[1]}",
                   f"at {dry_v[4]} s on its side and {dry_h[4]} s flat",
                   f"goes on {float(dry_v[5]):.1f} deg in both cases",
                   f"ends at \N{MINUS SIGN}{dry_v[6][1:]} \u00b1 {dry_v[8]} deg against \N{MINUS SIGN}{dry_h[6][1:]} "
                   f"\u00b1 {dry_h[8]}",
                   f"(flat: {leak_h[2]} to {leak_h[3]} deg; on its side: {leak_v[2]} to {leak_v[3]})"):
        assert quoted in text, quoted
    assert f"{float(dry_h[5]):.1f}" == f"{float(dry_v[5]):.1f}"  # "in both cases"


def printed_by_t1_trial(name: str, capsys) -> list[str]:
    """The lines examples/NAME.py prints, run as the T1 trials run: each swaps simulation's trajectory function for
    its own T1 and must put the committed one back."""
    import twin.sim.simulation as simulation

    committed = simulation.trajectory
    load_trial(name).main()
    assert simulation.trajectory is committed  # the trial puts T1 back
    return capsys.readouterr().out.splitlines()


@pytest.mark.slow  # about 7 s on 2 cores: three laws on T1 both ways, ten seeds
def test_trial_t1_direction_prints_what_the_docs_quote(capsys):
    out = printed_by_t1_trial("trial_t1_direction", capsys)
    assert out[0].startswith("T1 on the twelfth refit's values (6bb9e9258023; the committed preset's), seeds 0-9")
    assert out[1:] == [
        "pva    30 to 150 deg  1.90 ± 0.18, largest 8.5 (9.7), move 3.05 hold 0.90, SSE ±0.43 / ±0.64",
        "pva    150 to 30 deg  1.91 ± 0.23, largest 7.6 (9.6), move 2.87 hold 1.20, SSE ±1.11 / ±0.68",
        "ffpva  30 to 150 deg  1.49 ± 0.36, largest 6.3 (7.3), move 2.23 hold 1.01, SSE ±0.42 / ±0.81",
        "ffpva  150 to 30 deg  1.57 ± 0.21, largest 6.7 (7.6), move 2.21 hold 1.15, SSE ±1.10 / ±1.30",
        "smc    30 to 150 deg  1.37 ± 0.24, largest 6.3 (6.9), move 2.15 hold 0.77, SSE ±0.47 / ±0.95",
        "smc    150 to 30 deg  1.54 ± 0.38, largest 5.9 (6.9), move 2.11 hold 1.24, SSE ±0.88 / ±1.05",
        "mirrored minus committed, seed by seed: RMSE change mean ± its standard error (deg), seeds worse",
        "pva    +0.01 ± 0.11 (+0.1 standard errors), worse on 4 of 10",
        "ffpva  +0.09 ± 0.13 (+0.6 standard errors), worse on 7 of 10",
        "smc    +0.17 ± 0.09 (+2.0 standard errors), worse on 8 of 10",
    ]
    names = {"pva": "PVA + DZC", "ffpva": "FF + PVA", "smc": "sliding mode"}
    text = doc_text("investigations.md")
    for line in out[1:7]:
        m = re.fullmatch(r"(\w+) +(\d+ to \d+ deg)  (\S+ ± \S+), largest (\S+) (\(\S+\)), move (\S+) hold (\S+), "
                         r"SSE (±\S+ / ±\S+)", line)
        law, way, rmse, mean, top, move, hold, ranges = m.groups()
        assert f"| {names[law]} | {way} | {rmse} | {mean} {top} | {move} / {hold} | {ranges} |" in text, line
    change = {m[1]: m.groups()[1:] for m in (re.fullmatch(r"(\w+) +(\S+) ± (\S+) \(\+(\S+) standard errors\), worse on "
                                                        r"(\d+) of 10", line) for line in out[8:])}
    assert ("mean change of RMSE ± its standard error): PVA + DZC {0} ± {1} deg (worse on {3} of 10 seeds), FF + PVA "
            "{4} ± {5} ({7} of 10), sliding mode {8} ± {9} ({11} of 10)").format(
                *change["pva"], *change["ffpva"], *change["smc"]) in text
    assert (f"FF + PVA's change is {change['ffpva'][2]} of its standard error, within the runs' scatter; sliding "
            f"mode's is {change['smc'][2]}, at the edge of the two standard errors") in text
    pva = [float(line.split()[5]) for line in out[1:3]]
    assert f"tracks T1 at {pva[1]:.2f} deg against {pva[0]:.2f}, x{pva[0] / 4.20:.2f} of the rig's 4.20" in text
    assert f"{pva[0] / 4.20:.2f}" == f"{pva[1] / 4.20:.2f}"  # "either way"
    assert max(float(line.split()[10].strip("(),")) for line in out[1:3]) < 10  # "stays under 10 deg"
    assert (f"(150 to 30 deg: {pva[1]:.2f} deg mirrored against {pva[0]:.2f} as committed, seeds 0-9, stop 59)"
            in doc_text("as-built.md"))


@pytest.mark.slow  # about 20 s on 2 cores: the 13 measured T1 cells with a 4 s hold and as committed, ten seeds
def test_trial_t1_hold_prints_what_the_docs_quote(capsys):
    out = printed_by_t1_trial("trial_t1_hold", capsys)
    assert out[0].startswith("T1 with a 4 s hold on the twelfth refit's values (6bb9e9258023; the committed preset's)")
    assert out[1].endswith("bit for bit: yes")  # the first 3 s are the committed runs
    rows = {" ".join(line.split()[:4]): line.split()[4:] for line in out[3:16]}
    assert len(rows) == 13
    names = {"pva": "PVA + DZC", "ffpva": "FF + PVA", "smc": "sliding mode"}
    text = doc_text("investigations.md")
    quoted = {"pva 0.0 g horizontal": "0 g flat", "ffpva 0.0 g horizontal": "0 g flat",
              "smc 0.0 g horizontal": "0 g flat", "smc 13.5 g horizontal": "13.5 g flat",
              "ffpva 13.5 g vertical": "13.5 g on its side"}
    for key, cell in quoted.items():
        v = rows[key]  # measured, then value and (xratio) at 1, 1.25, 1.5, 2, 2.5, 3, 4, 5 s
        shown = [f"{v[i]} {v[i + 1]}" for i in (1, 5, 7, 9, 11, 13, 15)]
        assert f"| {names[key.split()[0]]}, {cell} | {v[0]} | " + " | ".join(shown) + " |" in text, key
    within = re.fullmatch(r"within 20 % of 13: (.*)", out[16]).group(1)
    counts = [int(part.split()[-1]) for part in within.split(", ")]
    assert counts[1] == 0  # 1.25 s, said beside the table
    assert "| of the 13 measured T1 cells within 20 % | | " + " | ".join(
        str(counts[i]) for i in (0, 2, 3, 4, 5, 6, 7)) + " |" in text
    assert counts[5] == max(counts) == 11  # "the committed 3 s puts the most ... (11)"
    ratios = [float(part.split()[-1]) for part in out[17].split(": ", 1)[1].split(", ")]
    assert out[17].startswith("PVA + DZC over FF + PVA, 0 g horizontal (measured 3.00)")
    assert f"is {min(ratios):.2f}-{max(ratios):.2f} at every" in text
    assert all(float(r.strip("(x)")) < 0.8 for r in rows["pva 0.0 g horizontal"][2::2])  # within at no length
    assert f"at most {rows['pva 0.0 g horizontal'][2].strip('()')}, at 1 s" in doc_text("as-built.md")


@pytest.mark.slow  # about 4 s on 2 cores: the three laws on T1-T3, five seeds, and a closed-form delay model
def test_trial_lag_relation_prints_what_the_docs_quote(capsys):
    load_trial("trial_lag_relation").main()
    out = capsys.readouterr().out.splitlines()
    row = re.compile(r"(rig|twin) +(\w+) +T1 (\S+), largest (\S+) \| from T2 \((\S+)\): +(\S+) ms, T1 (\S+) "
                     r"\(largest (\S+)\) (x\S+) \| from T3 \((\S+)\): +(\S+) ms, T1 (\S+) \(largest (\S+)\) (x\S+)")
    rows = {m[1] + " " + m[2]: m.groups()[2:] for m in map(row.fullmatch, out[1:7])}
    assert len(rows) == 6
    names = {"pva": "PVA + DZC", "ffpva": "FF + PVA", "smc": "sliding mode"}
    text = doc_text("investigations.md")
    for key, (t1, largest, _, d2, p2, l2, x2, _, d3, p3, l3, x3) in rows.items():
        source, law = key.split()
        odd = key == "rig pva"
        x2, x3 = (f"**{x}**" if odd else x for x in (x2, x3))
        assert (f"| {source}, {names[law]} | {t1} ({largest}) | {d2} ms, {p2} ({l2}) | {x2} | {d3} ms, {p3} ({l3}) "
                f"| {x3} |") in text, key
    ratios = {key: [float(v[6][1:]), float(v[11][1:])] for key, v in rows.items()}
    others = [x for key, pair in ratios.items() if key != "rig pva" for x in pair]
    assert f"within x{min(others):.2f}-{max(others):.2f}" in text  # five of the six laws
    assert f"x{min(ratios['rig pva']):.2f}-{max(ratios['rig pva']):.2f} what its own T2 and T3 imply" in text
    assert min(ratios["rig pva"]) > 1.8 and max(others) < 1.2  # the rig's PVA + DZC alone is about x2
    implied = sorted((rows["rig pva"][4], rows["rig pva"][9]), key=float)  # the rig's T2 and T3 say T1 ...
    assert f"{rows['twin pva'][0]} deg against the {implied[0]}-{implied[1]} they imply" in text  # ... the twin runs
    last = re.fullmatch(r"the delay that gives the rig's PVA \+ DZC T1 \(4.20\): (\S+) ms, which gives T2 (\S+) and "
                        r"T3 (\S+) \(the rig's 2.93 and 3.00\) and a largest T1 error of (\S+)", out[12])
    assert f"lag {last[1]} ms, which gives T2 {last[2]} and T3 {last[3]} deg" in text
    largest = {key: (float(v[1]) / float(v[5]), float(v[1]) / float(v[10])) for key, v in rows.items()}
    assert f"x{min(largest['rig pva']):.2f}-{max(largest['rig pva']):.2f} the ruler's" in text
    rest = [x for key, pair in largest.items() if key != "rig pva" for x in pair]
    assert f"largest errors are x{min(rest):.2f}-{max(rest):.2f} theirs" in text
    summary = doc_text("as-built.md")
    assert "rig's PVA + DZC T1 is x{:.2f}-{:.2f} what its own T2 and T3 imply".format(*sorted(ratios["rig pva"])) in summary
    assert f"T1 RMSE within x{min(others):.2f}-{max(others):.2f} for five of six (source, law) pairs" in summary
    assert f"twin's is what they imply ({rows['twin pva'][0]} against {implied[0]}-{implied[1]})" in summary
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert (f"by a fixed-lag ruler the rig's own PVA T2 and T3 imply {float(implied[0]):.1f}-{float(implied[1]):.1f} deg, "
            "as the twin runs") in readme
    at = {}  # the rig's ratios over other T1 lengths: PVA + DZC's range, the others', PVA + DZC's over theirs
    for line in out[8:12]:
        m = re.fullmatch(r"  (\S+) s: PVA \+ DZC (x\S+), FF \+ PVA and sliding mode (x\S+); PVA \+ DZC's over theirs "
                         r"(x\S+)", line)
        at[m[1]] = m.groups()[1:]
    assert at["3"][:2] == (f"x{min(ratios['rig pva']):.2f}-{max(ratios['rig pva']):.2f}",
                           "x{:.2f}-{:.2f}".format(*(f(ratios[k][i] for k in ("rig ffpva", "rig smc") for i in (0, 1))
                                                    for f in (min, max))))
    assert len({v[2] for v in at.values()}) == 1  # the comparison does not turn on the length
    assert (f"DZC is {at['1.5'][0]}, {at['2'][0]} and {at['5'][0]} of what its T2 and T3 imply, and its FF + "
            f"PVA and sliding mode {at['1.5'][1]}, {at['2'][1]} and {at['5'][1]}") in text
    assert f"the rig's PVA + DZC is {at['3'][2]} of its other two laws" in text
    assert f"the rig's PVA + DZC is {at['3'][2]} of its other two laws by this ruler" in summary
