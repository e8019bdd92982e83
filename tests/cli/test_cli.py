"""``python -m twin`` end to end, in a subprocess and a scratch folder."""

from __future__ import annotations

import csv
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import twin_in_process
from twin.sim.report import TRACE_COLUMNS

ROOT = pathlib.Path(__file__).resolve().parents[2]
REQUIRED_KEYS = {"controller", "trajectory", "payload_g", "orientation", "plant", "seed", "rmse_deg",
                 "sse_deg", "max_error_deg", "duration_s", "warnings"}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def twin(cwd: pathlib.Path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT), PYTHONIOENCODING="utf-8", MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "twin", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, encoding="utf-8", timeout=300)


def run_json(cwd: pathlib.Path, *args: str) -> dict:
    proc = twin(cwd, "run", "--controller", "ffpva", "--trajectory", "1", "--json", *args)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 1, proc.stdout
    record = json.loads(lines[0])
    assert isinstance(record, dict)
    return record


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26, a later session's slower machine)
def test_run_json_prints_one_record(tmp_path):
    record = run_json(tmp_path, "--seed", "0")
    assert REQUIRED_KEYS <= set(record)
    assert record["controller"] == "ffpva"
    assert record["trajectory"] == 1
    assert record["payload_g"] == 0
    assert record["orientation"] == "horizontal"
    assert record["plant"] == "thesis"
    assert record["seed"] == 0
    assert record["duration_s"] == pytest.approx(3.0, abs=1e-9)  # T1: 1 s rise + 2 s hold (§7)
    assert record["warnings"] == []
    assert record["rmse_deg"] >= 0 and record["max_error_deg"] >= abs(record["sse_deg"])
    assert list(tmp_path.iterdir()) == []  # --json alone writes nothing


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_plain_summary_of_a_run_that_ends_moving_says_it_has_no_steady_error(tmp_path):
    proc = twin(tmp_path, "run", "--controller", "smc", "--trajectory", "3", "--seed", "0")
    assert proc.returncode == 0, proc.stderr
    assert "SSE none (ends moving)" in proc.stdout and "RMSE " in proc.stdout


BASE = ["run", "--controller", "ffpva", "--trajectory", "1"]


@pytest.mark.parametrize("args, bad", [
    (["run", "--controller", "foo", "--trajectory", "1"], "foo"),
    (["run", "--controller", "ffpva", "--trajectory", "7"], "7"),
    (BASE + ["--payload", "abc"], "abc"),
    (BASE + ["--payload", "-1"], "-1"),
    (BASE + ["--supply-kpa", "800"], "800"),
    (BASE + ["--plant", "nope"], "nope"),
    (BASE + ["--orientation", "sideways"], "sideways"),
    # the error names the folder that does not exist
    (BASE + ["--trace", "no_such_folder/x.csv"], "no_such_folder"),
    (BASE + ["--plot", "no_such_folder/x.png"], "no_such_folder"),
    (BASE + ["--trace", "ok.csv", "--plot", "no_such_folder/x.png"], "no_such_folder"),
    (BASE + ["--trace", "ok.csv", "--plot", "figure.txt"], "figure.txt"),
    (BASE + ["--trace", "/dev/null/x.csv"], "'/dev/null' of '/dev/null/x.csv' is a file, not a folder"),
    (BASE + ["--payload", "500"], "500 g"),
    (["demo", "--seeds", "0"], "'0'"),
    (["sweep", "--payload", "heavy", "--out", "x"], "heavy"),
    (["sweep", "--controller", "ffpva"], "--out"),
])
def test_bad_input_exits_2_with_one_line_and_writes_nothing(tmp_path, args, bad):
    proc = twin_in_process(tmp_path, *args)
    assert proc.returncode == 2
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].strip()
    assert bad in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_trace_and_plot_files(tmp_path):
    proc = twin(tmp_path, *BASE, "--seed", "0", "--trace", "out.csv", "--plot", "out.png")
    assert proc.returncode == 0, proc.stderr
    with open(tmp_path / "out.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    header, data = rows[0], rows[1:]
    assert tuple(header) == tuple(TRACE_COLUMNS)
    assert len(data) == 3000  # T1 lasts 3 s, sampled every 1 ms
    t = [float(r[header.index("t_s")]) for r in data]
    assert t[0] == 0.0
    assert t[1] == pytest.approx(1e-3, abs=1e-9)
    assert t[-1] == pytest.approx(2.999, abs=1e-9)
    theta_d = [float(r[header.index("theta_d_deg")]) for r in data]
    assert theta_d[0] == pytest.approx(30.0, abs=1e-6)  # T1 starts at 30 deg
    assert theta_d[-1] == pytest.approx(150.0, abs=1e-3)  # and holds at 30 + 120 deg
    assert all(len(r) == len(header) for r in data)
    assert (tmp_path / "out.png").read_bytes()[:8] == PNG_MAGIC


def _trace(tmp_path, *args):
    proc = twin(tmp_path, "run", "--controller", "ffpva", "--trajectory", "2", "--trace", "t.csv", *args)
    assert proc.returncode == 0, proc.stderr
    with open(tmp_path / "t.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 1000  # T2's second, one row per 1 ms tick: a check on every row is not a check on none
    return np.array([float(r["y_measured_mm"]) - float(r["y_mm"]) for r in rows])


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_no_noise_means_the_sensor_reads_the_true_position(tmp_path):
    assert np.all(_trace(tmp_path, "--no-noise") == 0.0)


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_noise_is_white_within_the_thesis_bound(tmp_path):
    noise = _trace(tmp_path, "--seed", "4")
    assert np.max(np.abs(noise)) <= 0.02 + 1e-6  # mm, SPEC §5 (the CSV keeps 6 digits)
    assert np.std(noise) == pytest.approx(0.02 / np.sqrt(3), rel=0.1)  # uniform on +-0.02 mm
    assert abs(np.corrcoef(noise[:-1], noise[1:])[0, 1]) < 0.1  # white


def test_a_run_with_a_mujoco_warning_exits_1(monkeypatch, capsys):
    import dataclasses

    import twin.cli
    import twin.envs.runner

    real = twin.envs.runner.run
    monkeypatch.setattr(twin.envs.runner, "run", lambda s: dataclasses.replace(real(s), warnings=("mjWARN_BADQACC x1",)))
    assert twin.cli.main(["run", "--controller", "ffpva", "--trajectory", "2"]) == 1
    assert "mjWARN_BADQACC" in capsys.readouterr().out


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_noise_seed_changes_the_result(tmp_path):
    a = run_json(tmp_path, "--seed", "1")
    b = run_json(tmp_path, "--seed", "2")
    assert a["seed"] == 1 and b["seed"] == 2
    assert a["rmse_deg"] != b["rmse_deg"]


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_demo_writes_results_and_summary(tmp_path):
    proc = twin(tmp_path, "demo", "--seeds", "1", "--no-plots", "--out", "d")
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "d"
    with open(out / "results.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 12  # 3 controllers x 4 trajectories x 1 seed
    pairs = {(r["controller"], int(r["trajectory"])) for r in rows}
    assert pairs == {(c, t) for c in ("pva", "ffpva", "smc") for t in (1, 2, 3, 4)}
    # the CSV rules of every table (until 2026-12-08 the demo wrote True and 17 digits)
    assert {r["noise"] for r in rows} == {"true"}
    assert all(len(r["rmse_deg"].replace(".", "").lstrip("0")) <= 12 for r in rows)
    summary = (out / "summary.md").read_text(encoding="utf-8")
    assert "| controller |" in summary
    header = [line for line in proc.stdout.splitlines() if line.startswith("| controller |")]
    assert len(header) == 2  # the comparison table and T4's rest errors
    assert "RMSE" in header[0] and "T4 rest errors" in header[1]
    assert not list(out.glob("*.png"))  # --no-plots


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_without_switches_off_as_built_effects_by_name(tmp_path):
    full = run_json(tmp_path, "--plant", "as-built", "--seed", "0")
    ablated = run_json(tmp_path, "--plant", "as-built", "--seed", "0", "--without", "stiction,solenoid_valve")
    assert ablated["plant"] == "as-built-without-solenoid_valve+stiction"
    assert ablated["rmse_deg"] != full["rmse_deg"]


@pytest.mark.parametrize("args, bad", [
    (["--plant", "as-built", "--without", "friction"], "friction"),
    (["--plant", "thesis", "--without", "solenoid_valve"], "'thesis'"),
    (["--plant", "as-built", "--without", "compressibility"], "supply_line off too"),
])
def test_without_refuses_what_it_cannot_switch_off(tmp_path, args, bad):
    proc = twin_in_process(tmp_path, *BASE, *args, "--json")
    assert proc.returncode == 2
    assert bad in proc.stderr and len(proc.stderr.strip().splitlines()) == 1 and proc.stdout == ""
