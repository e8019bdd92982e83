"""Bad input and unwritable outputs from the command line: a one-line error, exit 2, nothing written
(issue: "Nothing half-written, nothing lost, no surprises"; the rows done so far)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from twin.cli import main
from twin.exceptions import InvalidAction


def _one_line_error(capsys, *needles: str) -> str:
    err = capsys.readouterr().err.strip()
    assert err.startswith("twin: error:") and len(err.splitlines()) == 1, err
    for needle in needles:
        assert needle in err, err
    return err


def test_run_writes_every_output_or_none(tmp_path, capsys):
    """An output that cannot be written (a path under /proc: root can write anywhere else) leaves none."""
    trace = tmp_path / "ok.csv"
    assert main(["run", "--controller", "ffpva", "--trajectory", "1", "--trace", str(trace),
                 "--plot", "/proc/x.png"]) == 2
    _one_line_error(capsys, "/proc/x.png")
    assert list(tmp_path.iterdir()) == []  # neither ok.csv nor a temporary


def test_run_says_what_it_wrote(tmp_path, capsys):
    trace, plot = tmp_path / "t.csv", tmp_path / "t.png"
    assert main(["run", "--controller", "smc", "--trajectory", "1", "--trace", str(trace), "--plot", str(plot),
                 "--json"]) == 0
    out, err = capsys.readouterr()
    assert out.count("\n") == 1 and out.startswith("{")  # still exactly one JSON object on stdout
    assert err.splitlines() == [f"wrote {trace}", f"wrote {plot}"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "t.png"]


def test_a_sweep_into_a_folder_it_cannot_write_is_one_line(capsys):
    assert main(["sweep", "--seed", "0", "--out", "/proc/self"]) == 2
    _one_line_error(capsys, "cannot write", "/proc/self")


@pytest.mark.parametrize("args, words", [
    (["--payload", "10:0:1"], ["'10:0:1'", "--payload", "stop before start"]),
    (["--seed", "4-0"], ["'4-0'", "--seed", "stop before start"]),
    (["--payload", "0:1:0"], ["step must be positive"]),
    (["--payload", "0:1000000:0.001"], ["1,000,000,001 values", "100,000"]),
    (["--seed", "0-999", "--payload", "0:100:0.5"], ["201,000 scenarios", "100,000"]),
    ([], ["names no axes"]),
])
def test_sweep_grids_are_checked_before_anything_runs(tmp_path, capsys, args, words):
    out = tmp_path / "never"
    assert main(["sweep", *args, "--out", str(out)]) == 2
    _one_line_error(capsys, *words)
    assert not out.exists()


def test_an_empty_grid_file_is_an_error(tmp_path, capsys):
    config = tmp_path / "grid.toml"
    config.write_text("[grid]\n")
    assert main(["sweep", "--config", str(config), "--out", str(tmp_path / "never")]) == 2
    _one_line_error(capsys, "names no axes")
    assert not (tmp_path / "never").exists()


def test_environment_refuses_non_finite_actions_and_reports_a_clip_once():
    from twin.envs import environment

    env = environment.load("track", trajectory=1, seed=0)
    env.reset()
    for bad in (np.nan, np.inf, -np.inf):
        with pytest.raises(InvalidAction, match="finite"):
            env.step([bad])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env.step([1e9])
        env.step([-1e9])
    clipped = [w for w in caught if "clipped" in str(w.message)]
    assert len(clipped) == 1 and "1e+09 % clipped to 100 %" in str(clipped[0].message)
    assert env.physics.duty[0] == -100.0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env.reset()
        env.step([500.0])
    assert len([w for w in caught if "clipped" in str(w.message)]) == 1  # once per episode


def test_a_results_store_that_cannot_be_created_is_a_one_line_error(tmp_path):
    from twin.batch.store import ResultStore, StoreUnwritable

    with pytest.raises(StoreUnwritable, match="cannot write the results store"):
        ResultStore(tmp_path / "missing-folder" / "results.sqlite", version="v")


def test_one_writer_per_output_folder(tmp_path, capsys):
    """A second writer is refused at once, naming the first's PID; a dead holder's lock is taken over."""
    import subprocess
    import sys

    from twin.batch.lock import LOCK_NAME, FolderBusy, folder_lock

    out = tmp_path / "out"
    out.mkdir()
    holder = subprocess.Popen([sys.executable, "-c", (
        "import pathlib, sys, time\n"
        "from twin.batch.lock import folder_lock\n"
        f"with folder_lock(pathlib.Path({str(out)!r})):\n"
        "    print('locked', flush=True)\n"
        "    time.sleep(60)\n")], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        assert main(["sweep", "--seed", "0", "--out", str(out)]) == 2
        _one_line_error(capsys, f"process {holder.pid}", "another --out")
        assert main(["whatif", "gear-load", "--out", str(out)]) == 2
        _one_line_error(capsys, f"process {holder.pid}")
        assert sorted(p.name for p in out.iterdir()) == [LOCK_NAME]  # nothing else was written
    finally:
        holder.kill()  # SIGKILL: no clean-up runs
        holder.wait()
    with folder_lock(out):  # the dead holder's lock is taken over
        with pytest.raises(FolderBusy):  # and held: a second taker in this process is refused too
            with folder_lock(out):
                pass


def _exit_code(argv: list[str]) -> int:
    """main's return value, or the code argparse exits with."""
    try:
        return main(argv)
    except SystemExit as stop:
        return stop.code


@pytest.mark.parametrize("argv", [["run", "--controller", "x", "--trajectory", "1"],
                                  ["whatif", "payload", "--seeds", "0", "--out", "x"],
                                  ["study", "robustness", "--seeds", "0", "--out", "x"],
                                  ["sweep", "--seed", "a", "--out", "x"], ["view", "--port", "-1"]])
def test_every_command_errors_with_one_prefix(argv, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert _exit_code(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("twin: error:") and len(err.strip().splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []


def test_bench_names_each_stage_as_it_starts(monkeypatch):
    """The measurements themselves are stubbed: only the progress reports are under test."""
    from types import SimpleNamespace

    from twin.experiments import bench

    monkeypatch.setattr(bench, "run_many", lambda scenarios, **k: [SimpleNamespace(trace=SimpleNamespace(time=[0] * 3000))])
    monkeypatch.setattr(bench, "_bare_step_cost", lambda seconds: 1.0)
    monkeypatch.setattr(bench, "_fastest", lambda work, repeats: 1.0)
    monkeypatch.setattr(bench, "_env_cost", lambda trajectory, duration: 1.0)
    monkeypatch.setattr(bench, "_sweep_walls", lambda workers: ({1: 1.0}, 1.0))
    stages: list[str] = []
    bench.measure(batch_size=3, progress=stages.append)
    assert [s.split("]")[0] for s in stages] == ["[1/4", "[2/4", "[3/4", "[4/4"]


@pytest.mark.slow  # over ~2.5 s on 2 cores
@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM"])
def test_an_interrupted_sweep_stops_at_once_keeps_what_finished_and_resumes(tmp_path, stop):
    import signal
    import sqlite3
    import subprocess
    import sys
    import time

    out = tmp_path / "sweep"
    argv = [sys.executable, "-m", "twin", "sweep", "--controller", "ffpva,smc", "--trajectory", "1,3",
            "--payload", "0:10:2", "--seed", "0-19", "--plant", "as-built", "--workers", "2", "--out", str(out)]
    total = 2 * 2 * 6 * 20

    def stored() -> int:
        try:
            with sqlite3.connect(out / "results.sqlite") as db:
                return db.execute("SELECT COUNT(*) FROM results").fetchone()[0]
        except sqlite3.Error:
            return 0

    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while stored() == 0 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert proc.poll() is None, "the sweep finished before it could be interrupted: make the grid larger"
    sent = time.monotonic()
    proc.send_signal(getattr(signal, stop))
    _, err = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 2.0  # measured 0.4 s
    assert proc.returncode == 130 and "interrupted: finished scenarios are kept" in err
    kept = stored()
    assert 0 < kept < total

    again = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    assert f"{total - kept} run, {kept} already done, 0 failed" in again.stdout
    assert f"{total}/{total}" in again.stderr.replace("\r", "\n").splitlines()[-1] or f"{total}/{total}" in again.stderr
    with sqlite3.connect(out / "results.sqlite") as db:
        assert db.execute("SELECT COUNT(*), COUNT(DISTINCT key) FROM results").fetchone() == (total, total)


def test_tables_read_cleanly_in_a_spreadsheet(tmp_path):
    import csv

    import numpy as np

    from twin.batch.tables import write_csv

    path = tmp_path / "t.csv"
    write_csv([{"a": -0.0, "b": 6.000000000000001, "c": True, "d": np.False_, "e": float("nan"), "f": ["x", "y"],
                "g": 0.1 + 0.2, "h": 1.2345678901234567e-7}], list("abcdefgh"), path)
    with open(path) as handle:
        row = next(csv.DictReader(handle))
    assert row == {"a": "0.0", "b": "6.0", "c": "true", "d": "false", "e": "nan", "f": "x;y", "g": "0.3",
                   "h": "1.23456789012e-07"}


def test_a_sweep_and_a_run_spell_booleans_alike_and_durations_cleanly(tmp_path, capsys):
    import csv
    import json

    assert main(["sweep", "--seed", "0", "--trajectory", "4", "--out", str(tmp_path / "s")]) == 0
    with open(tmp_path / "s" / "results.csv") as handle:
        row = next(csv.DictReader(handle))
    assert row["noise"] == "true" and row["duration_s"] == "6.0"
    capsys.readouterr()
    assert main(["run", "--controller", "ffpva", "--trajectory", "4", "--json",
                 "--trace", str(tmp_path / "t.csv")]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["noise"] is True and record["duration_s"] == 6.0
    assert ",-0," not in (tmp_path / "t.csv").read_text() and ",-0\n" not in (tmp_path / "t.csv").read_text()
