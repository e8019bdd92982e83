"""Bad input and unwritable outputs from the command line: a one-line error, exit 2, nothing written
(issue: "Nothing half-written, nothing lost, no surprises"; the rows done so far)."""

from __future__ import annotations

import argparse
import contextlib
import csv
import errno
import os
import pathlib
import random
import signal
import sqlite3
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest

from twin.cli import main
from twin.exceptions import InvalidAction
from twin.experiments.reference import ROBUSTNESS_CELLS
from twin.plants.as_built import calibrated_values, ensemble_values

COMMITTED_AIR_PCT = calibrated_values()["air_fraction"] * 100  # % of the chamber volume


def _one_line_error(capsys, *needles: str) -> str:
    err = capsys.readouterr().err.strip()
    assert err.startswith("twin: error:") and len(err.splitlines()) == 1, err
    for needle in needles:
        assert needle in err, err
    return err


def test_run_writes_every_output_or_none(tmp_path, capsys):
    """An output that cannot be written (a path under /proc: root can write anywhere else) leaves none (since
    2026-11-26 it is refused before the run: a file is tried in the folder, as root's os.access says yes)."""
    trace = tmp_path / "ok.csv"
    assert _exit_code(["run", "--controller", "ffpva", "--trajectory", "1", "--trace", str(trace),
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


@pytest.mark.parametrize("argv, words", [
    (["sweep", "--seed", "0", "--without", "stiction", "--out", "x"], "sweep: unrecognized arguments: --without stiction"),
    (["whatif", "gear-load", "--out", "x", "--bogus"], "whatif gear-load: unrecognized arguments: --bogus")])
def test_an_unknown_flag_is_named_after_its_command(argv, words, capsys, tmp_path, monkeypatch):
    """Every other parse error names its command; unrecognized flags did not (found by probing, 2026-11-27)."""
    monkeypatch.chdir(tmp_path)
    assert _exit_code(argv) == 2
    _one_line_error(capsys, f"twin: error: {words}")
    assert list(tmp_path.iterdir()) == []


def test_the_demo_table_shows_no_negative_zero_and_one_seed_as_one():
    from twin.experiments import demo

    row = {"controller": "ffpva", "trajectory": 1, "rmse_mean": 0.5, "rmse_std": 0.0, "thesis_rmse": 0.5 + 1e-4,
           "sse_mean": -1e-4, "sse_min": -0.004, "sse_max": 0.0, "thesis_sse": 0.35, "max_error_mean": 1.0}
    table = demo.markdown_table([row])
    assert "-0.00" not in table and "| +0.00 | +0.00 [+0.00, +0.00] |" in table


def _sweep_argv(out: pathlib.Path) -> list[str]:
    """A sweep long enough to be stopped part-way: 480 as-built scenarios on 2 workers (about 1 min)."""
    return [sys.executable, "-m", "twin", "sweep", "--controller", "ffpva,smc", "--trajectory", "1,3",
            "--payload", "0:10:2", "--seed", "0-19", "--plant", "as-built", "--workers", "2", "--out", str(out)]


SWEEP_TOTAL = 2 * 2 * 6 * 20


def _stored(out: pathlib.Path, what: str = "COUNT(*)"):
    """``SELECT what`` over the sweep's store (0 / no rows while it does not exist yet)."""
    try:
        with sqlite3.connect(out / "results.sqlite") as db:
            return db.execute(f"SELECT {what} FROM results").fetchall() if what == "key" else \
                db.execute(f"SELECT {what} FROM results").fetchone()[0]
    except sqlite3.Error:
        return [] if what == "key" else 0


def _ctrl_c_as_in_a_terminal() -> None:
    """In the child before exec: Ctrl-C at its default, as a user's terminal gives it. A shell that
    starts this suite in the background without job control passes SIGINT on ignored, and Python then
    never turns it into KeyboardInterrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


# The sweep with each worker's second batch stalled for 10 minutes (patched before the workers fork): a stop
# that waited for the batches in flight would hang, where one that stops at once ends in a second.
STALLING_SWEEP = """
import sys, time
import twin.batch.sweep as sweep
plain = sweep.run_chunk
def stalling(points):
    if getattr(stalling, "ran", False):
        time.sleep(600)
    stalling.ran = True
    return plain(points)
sweep.run_chunk = stalling
from twin.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _start_and_wait_for_a_first_row(out: pathlib.Path, *, stalling: bool = False, **popen) -> subprocess.Popen:
    argv = _sweep_argv(out)
    if stalling:
        argv = [sys.executable, "-c", STALLING_SWEEP, *argv[3:]]  # [python, -m, twin, sweep, ...] -> sweep, ...
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_ctrl_c_as_in_a_terminal, **popen)
    deadline = time.monotonic() + 120
    while _stored(out) == 0 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert proc.poll() is None, "the sweep finished before it could be interrupted: make the grid larger"
    return proc


def _resume_completes_with_every_row_once(out: pathlib.Path, kept: int) -> None:
    """The same command again: it runs only what is missing, counts the rest, and results.csv holds every
    scenario of the grid exactly once."""
    again = subprocess.run(_sweep_argv(out), capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    assert f"{SWEEP_TOTAL - kept} run, {kept} already done, 0 failed" in again.stdout
    assert f"{SWEEP_TOTAL}/{SWEEP_TOTAL}" in again.stderr
    with sqlite3.connect(out / "results.sqlite") as db:
        assert db.execute("SELECT COUNT(*), COUNT(DISTINCT key) FROM results").fetchone() == (SWEEP_TOTAL, SWEEP_TOTAL)
    with open(out / "results.csv") as handle:
        keys = [row["key"] for row in csv.DictReader(handle)]
    assert len(keys) == len(set(keys)) == SWEEP_TOTAL


@pytest.mark.slow  # over ~2.5 s on 2 cores
@pytest.mark.parametrize("stop", ["SIGINT", "SIGTERM"])
def test_an_interrupted_sweep_stops_at_once_keeps_what_finished_and_resumes(tmp_path, stop):
    out = tmp_path / "sweep"
    proc = _start_and_wait_for_a_first_row(out, stalling=True)
    deadline = time.monotonic() + 120
    while _stored(out) < 120 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)  # both workers' first batches (60 scenarios each) stored: their second ones stall now
    time.sleep(0.5)
    proc.send_signal(getattr(signal, stop))
    try:  # "at once": not waiting for the stalled batches in flight (600 s); 60 s is a hang guard, not a measure
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()  # its workers die with it (the parent-death signal)
        proc.communicate()
        raise AssertionError(f"the sweep waited for its batches in flight after {stop}") from None
    assert proc.returncode == 130 and "interrupted: finished scenarios are kept" in err
    kept = _stored(out)
    assert kept == 120  # the two finished batches, and nothing of the stalled ones
    _resume_completes_with_every_row_once(out, kept)


def _children(pid: int) -> list[int]:
    """The PIDs of ``pid``'s child processes (its sweep workers), from /proc."""
    found = []
    for task in pathlib.Path(f"/proc/{pid}/task").iterdir():
        found += [int(c) for c in (task / "children").read_text().split()]
    return found


_draws = random.Random(16)
KILL_DELAYS = [round(_draws.uniform(0.0, 4.0), 2) for _ in range(3)]  # s after the first stored row


@pytest.mark.slow  # over ~2.5 s on 2 cores (a whole sweep each)
@pytest.mark.parametrize("delay", KILL_DELAYS)
def test_a_sweep_killed_at_a_random_point_resumes_with_every_finished_row_once(tmp_path, delay):
    """SIGKILL to the sweep and its workers (its process group, as the OOM killer of a cgroup, ``timeout -s
    KILL`` or a closed session would) at a seeded random moment after its first stored row: no clean-up
    runs, yet every row stored before the kill is in the resumed sweep's results.csv exactly once."""
    out = tmp_path / "sweep"
    proc = _start_and_wait_for_a_first_row(out, start_new_session=True)
    time.sleep(delay)
    assert proc.poll() is None, "the sweep finished before the kill: make the grid larger"
    os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    finished = {key for (key,) in _stored(out, "key")}
    assert 0 < len(finished) < SWEEP_TOTAL
    _resume_completes_with_every_row_once(out, len(finished))
    with open(out / "results.csv") as handle:
        assert finished <= {row["key"] for row in csv.DictReader(handle)}


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_a_sweep_whose_parent_alone_is_killed_leaves_no_workers_and_resumes(tmp_path):
    out = tmp_path / "sweep"
    proc = _start_and_wait_for_a_first_row(out)
    workers = _children(proc.pid)
    try:
        proc.kill()  # the parent only (the OOM killer picks one process)
        proc.wait(timeout=10)  # not communicate(): workers that outlive it hold its pipes open
        proc.stdout.close()
        proc.stderr.close()
        kept = _stored(out)
        time.sleep(2.0)
        alive = [pid for pid in workers if pathlib.Path(f"/proc/{pid}").exists()
                 and pathlib.Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"]
        assert alive == [], f"workers {alive} outlived their killed sweep"
        _resume_completes_with_every_row_once(out, kept)
    finally:
        for pid in workers:  # this test's own processes, by PID
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)


@contextlib.contextmanager
def _tmpfs(folder: pathlib.Path, size: str):
    """A tiny RAM file system on ``folder`` (needs root: skipped where it cannot be mounted)."""
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


def _after_disk_full(capsys, folder: pathlib.Path, code: int, *, named: pathlib.Path | None = None) -> list[str]:
    """Exit 2 and, last on stderr (after any progress bar), one line saying the disk is full (and, if
    given, that ``named`` cannot be written); what is left in ``folder``."""
    assert code == 2
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if line.startswith("twin: error:")]
    assert len(errors) == 1 and err.rstrip().endswith(errors[0]) and "Traceback" not in err, err
    assert "No space left on device" in errors[0], errors[0]
    assert named is None or f"cannot write {named}: " in errors[0], errors[0]
    return sorted(p.name for p in folder.iterdir()) if folder.exists() else []


@pytest.mark.parametrize("size, full", [("128k", "t.csv"), ("240k", "t.png")])  # trace 205 KB, plot 55 KB
def test_a_full_disk_leaves_no_output_of_twin_run(tmp_path, capsys, size, full):
    with _tmpfs(tmp_path / "disk", size) as disk:
        code = main(["run", "--controller", "ffpva", "--trajectory", "1", "--trace", str(disk / "t.csv"),
                     "--plot", str(disk / "t.png")])
        assert _after_disk_full(capsys, disk, code, named=disk / full) == []  # neither output, nor a temporary


def test_a_full_disk_leaves_no_part_of_a_live_recording(tmp_path, capsys):
    """``twin view --html`` left its temporary (the disk's whole 64 KB) and named no file until stop 60."""
    with _tmpfs(tmp_path / "disk", "64k") as disk:
        code = main(["view", "--controller", "ffpva", "--trajectory", "1", "--port", "0", "--duration", "1",
                     "--html", str(disk / "v.html")])
        assert _after_disk_full(capsys, disk, code, named=disk / "v.html") == []


def test_a_disk_that_fills_while_the_trace_is_written_leaves_no_output_of_twin_run(tmp_path, capsys, monkeypatch):
    """The same without root: the trace writer fills the disk after its first bytes."""
    from twin.sim import report

    def write_until_full(result, path):
        pathlib.Path(path).write_text("time_s,angle_deg\n0.0,")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(report, "write_trace", write_until_full)
    code = main(["run", "--controller", "ffpva", "--trajectory", "1", "--trace", str(tmp_path / "t.csv"),
                 "--plot", str(tmp_path / "t.png")])
    assert _after_disk_full(capsys, tmp_path, code) == []


@pytest.mark.parametrize("size", ["8k", "12k"])  # full in lift.txt, full in lift.png (measured)
def test_a_full_disk_leaves_no_half_written_whatif_output(tmp_path, capsys, size):
    with _tmpfs(tmp_path / "disk", size) as disk:
        code = main(["whatif", "lift", "--pressures", "100", "--out", str(disk / "out")])
        left = _after_disk_full(capsys, disk / "out", code, named=disk / "out")  # its folder: no name until stop 60
        # the folder the command made goes again (2026-11-26; before, its lock file stayed), or is whole
        assert left in ([], [".twin.lock", "lift.csv", "lift.png", "lift.txt"]), left
        assert all((disk / "out" / name).stat().st_size > 0 for name in left)


def test_a_disk_that_fills_while_a_table_is_written_leaves_no_temporary(tmp_path, capsys, monkeypatch):
    """A whole sweep, then its results.csv fills the disk after the header: exit 2, and neither a half-written
    results.csv nor its temporary is left (the store keeps the finished scenarios)."""
    import twin.batch.tables

    cell = twin.batch.tables._cell

    def until_full(value):
        if isinstance(value, str) and value.startswith("ffpva"):  # the first row's key: the header is out
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return cell(value)

    monkeypatch.setattr(twin.batch.tables, "_cell", until_full)
    out = tmp_path / "sweep"
    code = main(["sweep", "--controller", "ffpva", "--trajectory", "4", "--seed", "0", "--workers", "1",
                 "--out", str(out)])
    assert _after_disk_full(capsys, out, code) == [".twin.lock", "results.sqlite"]


def test_a_full_disk_while_a_sweep_stores_its_rows_is_a_one_line_error(tmp_path, capsys, monkeypatch):
    """SQLite's own answer to a full disk, injected where the store writes its rows."""
    connect = sqlite3.connect

    class FullDisk:
        def __init__(self, db):
            self._db = db

        def __getattr__(self, name):
            return getattr(self._db, name)

        def __enter__(self):
            return self._db.__enter__()

        def __exit__(self, *exc):
            return self._db.__exit__(*exc)

        def executemany(self, *args):
            raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(sqlite3, "connect", lambda *args, **kwargs: FullDisk(connect(*args, **kwargs)))
    out = tmp_path / "sweep"
    code = main(["sweep", "--trajectory", "4", "--seed", "0", "--workers", "1", "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if line.startswith("twin: error:")]
    assert len(errors) == 1 and err.rstrip().endswith(errors[0]) and "Traceback" not in err, err  # after the bar
    assert "cannot write the results store" in errors[0] and "full" in errors[0]
    assert not (out / "results.csv").exists()


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


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
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


@pytest.mark.parametrize("argv, words", [
    (["run", "--controller", "ffpva", "--trajectory", "1", "--seed", str(2**63)], "seed must be an integer from 0"),
    (["sweep", "--controller", "ffpva", "--trajectory", "1", "--seed", str(2**63), "--out", "OUT"],
     "seed must be an integer from 0 to 2^63 - 1"),
    (["sweep", "--controller", "ffpva", "--trajectory", "1", "--out", "OUT", "--workers", "99999"],
     "--workers: at most"),
    (["study", "robustness", "--out", "OUT", "--workers", "99999"], "workers must be an integer from 1 to"),
    (["whatif", "smc-phi", "--out", "OUT", "--seeds", "1001"], "seeds per case must be an integer from 1 to 1000"),
    (["whatif", "observer", "--out", "OUT", "--seeds", "100000"], "seeds per case"),
    (["demo", "--out", "OUT", "--seeds", "100000"], "seeds per case"),
    (["whatif", "next-experiment", "--out", "OUT", "--prediction-seeds", "1000000"], "seeds per case"),
    # the committed preset and each ensemble member, every cell of Chapter 6, 1000 seeds each
    (["study", "robustness", "--out", "OUT", "--seeds", "1000"],
     f"the grid has {1000 * len(ROBUSTNESS_CELLS) * (1 + len(ensemble_values())):,} scenarios: more than the 100,000"),
    (["whatif", "smc-phi", "--out", "OUT", "--phis", "0.2,,0.3"], "--phis: numbers in m/s separated by commas"),
    (["whatif", "pva-rate", "--out", "OUT", "--rates", "8,,16"], "--rates: whole milliseconds"),
    (["whatif", "air", "--out", "OUT", "--air", "2,x"], "--air: percentages separated by commas, got '2,x'"),
    (["whatif", "air", "--out", "OUT", "--air", "25"], "--air: each value must be 0-20 % of the chamber volume"),
    (["whatif", "air", "--out", "OUT", "--air", ",".join(str(k / 10) for k in range(60))], "--air: at most 50 values"),
    (["whatif", "pva-rate", "--out", "OUT", "--rates", "16"], "--rates: give a period under the thesis's 16 ms"),
    # Found by a helper's probing (2026-12-08): lists that cannot answer their question ran and answered it
    (["whatif", "pva-rate", "--out", "OUT", "--rates", "17,32"], "--rates: give a period under the thesis's 16 ms"),
    (["whatif", "pwm", "--out", "OUT", "--periods", "16"], "--periods: give two periods or more to compare, got '16'"),
    (["whatif", "air", "--out", "OUT", "--air", f"{COMMITTED_AIR_PCT:.4g}"],
     f"--air: give a value other than the committed {COMMITTED_AIR_PCT:.4g} %"),
    # Found by probing again (2026-11-27): a range whose step is so small its count overflows was a traceback, and
    # the what-ifs below had no cap (the first took 23 GB before it was killed); whatif payload's refusal came
    # after its folder was made. Each count is the what-if's own: laws or controllers x cells x values x seeds.
    (["sweep", "--payload", "0:1e300:1e-300", "--out", "OUT"], "has over a trillion values: more than the 100,000"),
    (["whatif", "lift", "--out", "OUT", "--pressures", "1:700:0.01"], "--pressures would make 1,179,938 runs"),
    (["whatif", "pwm", "--out", "OUT", "--periods", "4:100:1", "--seeds", "1000"],
     "--periods x --seeds would make 388,000 runs: more than the 100,000 one command takes"),
    (["whatif", "smc-phi", "--out", "OUT", "--phis", ",".join(f"{k / 100:g}" for k in range(1, 301)), "--seeds",
      "1000"], "--phis x --seeds would make 2,709,000 runs"),  # (300, 0.3 among them, + FF + PVA) x 9 cells x 1000
    (["whatif", "pva-rate", "--out", "OUT", "--rates", ",".join(str(k) for k in range(1, 65)), "--seeds", "1000"],
     f"--rates x --seeds x --members would make {28 * 64 * 1000 * len(ensemble_values()):,} runs"),
    (["whatif", "observer", "--out", "OUT", "--seeds", "1000"],
     f"--seeds x --members would make {16 * 1000 * len(ensemble_values()):,} runs"),
    (["whatif", "payload", "--out", "OUT", "--payloads", "0:200:0.01", "--seeds", "1000"],
     "--payloads x --seeds would make 80,004,000 runs"),
    (["whatif", "air", "--out", "OUT", "--air", "1,2,3,4,5,6,7,8,9,10", "--seeds", "1000"],
     "--air x --seeds would make 134,310 runs"),  # 11 values x (21 cells x 10 fit seeds + 12 T3 cells x 1000)
    (["study", "ablation", "--out", "OUT", "--seeds", "1000"], "--seeds would make 110,000 runs"),  # 10 x 11 x 1000
    (["whatif", "next-experiment", "--out", "OUT", "--seeds", "1000", "--prediction-seeds", "1000", "--pressure-step",
      "1"], f"would make up to {len(ensemble_values()) * (1000 * (2 * 8 * 9 + 1) + 1000 * 24):,} runs"),  # 9 rounds: 281 rungs
    (["bench", "--batch", "1000000"], "runs in the batch must be an integer from 1 to 2,000"),
    (["view", "--controller", "smc", "--trajectory", "1", "--host", ""], "--host: give a host name or address"),
    (["whatif", "gear-load", "--out", ""], "the output folder must be named"),
    (["sweep", "--controller", "ffpva", "--trajectory", "1", "--out", ""], "the output folder must be named"),
    # empty inputs (a helper's probe, 2026-12-08): the current folder, or "not given"
    (["sweep", "--seed", "0", "--backend", "ray", "--ray-address", "", "--out", "OUT"], "the address must be named"),
    (["sweep", "--config", "", "--out", "OUT"], "argument --config: the path must be named, got ''"),
    (["score", "--measured", "", "--out", "OUT"], "argument --measured: the path must be named, got ''"),
    (["score", "--measured", "m.csv", "--prediction", "", "--out", "OUT"], "argument --prediction: the path must be"),
    (["view", "--controller", "smc", "--trajectory", "4", "--html", "/proc/a.html"], "cannot write '/proc/a.html'"),
    (["run", "--controller", "ffpva", "--trajectory", "1", "--trace", ".csv"], "must be a file name ending in .csv"),
])
def test_absurd_sizes_empty_names_and_loose_lists_are_refused_before_anything_runs(tmp_path, capsys, monkeypatch,
                                                                                      argv, words):
    """Found by probing the commands (2026-11-26): seeds past what a store can hold crashed a sweep after its
    runs; tens of thousands of seeds or workers were taken (gigabytes, thousands of processes); an empty
    list item, an empty --out (the current folder) and an unwritable folder that root's os.access calls
    writable were let through. Each is now one line, exit 2, and nothing in the folder."""
    import twin.cli.experiments
    import twin.cli.sweep

    def began(*args, **kwargs):
        raise AssertionError("a command that should be refused began its work")  # not hours of a huge run

    monkeypatch.setattr(twin.cli.experiments, "output_folder", began)
    monkeypatch.setattr(twin.cli.sweep, "output_folder", began)
    monkeypatch.chdir(tmp_path)
    argv = [str(tmp_path / "out") if a == "OUT" else a for a in argv]
    assert _exit_code(argv) == 2
    _one_line_error(capsys, words)
    assert list(tmp_path.iterdir()) == []


def test_version_names_the_twin_and_mujoco(capsys):
    assert _exit_code(["--version"]) == 0
    import mujoco

    from twin.batch.sweep import package_version

    assert capsys.readouterr().out == f"twin {package_version()} (mujoco {mujoco.__version__})\n"


def test_a_seed_past_what_a_store_holds_is_refused_by_the_scenario_itself():
    from twin.exceptions import InvalidScenario
    from twin.sim.scenario import MAX_SEED, Scenario

    Scenario("ffpva", 1, seed=MAX_SEED)
    with pytest.raises(InvalidScenario, match="seed must be an integer from 0 to 2"):
        Scenario("ffpva", 1, seed=MAX_SEED + 1)


def test_a_pool_never_starts_more_workers_than_it_has_calls(monkeypatch):
    from twin.batch import sweep

    started = []
    real = sweep.concurrent.futures.ProcessPoolExecutor

    def counting(*args, max_workers, **kwargs):
        started.append(max_workers)
        return real(*args, max_workers=max_workers, **kwargs)

    monkeypatch.setattr(sweep.concurrent.futures, "ProcessPoolExecutor", counting)
    done = []
    sweep.run_forked([(abs, (-3,)), (abs, (-4,))], 500, done.append)
    assert started == [2] and sorted(done) == [3, 4]


def _interrupting(experiment_module, monkeypatch):
    def run(self, args, out):
        (out / "partial.bin").write_bytes(b"x")
        raise KeyboardInterrupt

    monkeypatch.setattr(type(experiment_module.EXPERIMENT), "run", run)


def test_ctrl_c_in_an_experiment_is_one_line_and_leaves_no_folder_it_made(tmp_path, capsys, monkeypatch):
    """A what-if that keeps no runs, interrupted: `twin: interrupted`, exit 130, no traceback, and the
    folder it made is gone; a folder that was there before keeps what it had."""
    from twin.experiments.whatifs import gear_load

    _interrupting(gear_load, monkeypatch)
    out = tmp_path / "new"
    assert main(["whatif", "gear-load", "--out", str(out)]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "twin: interrupted"
    assert not out.exists()
    kept = tmp_path / "old"
    kept.mkdir()
    (kept / "mine.txt").write_text("keep")
    assert main(["whatif", "gear-load", "--out", str(kept)]) == 130
    assert (kept / "mine.txt").read_text() == "keep"


def test_ctrl_c_in_a_resumable_experiment_says_where_its_runs_are_kept(tmp_path, capsys, monkeypatch):
    from twin.experiments.whatifs import payload

    _interrupting(payload, monkeypatch)
    out = tmp_path / "p"
    assert main(["whatif", "payload", "--out", str(out)]) == 130
    err = capsys.readouterr().err.strip()
    assert err == f"interrupted: finished runs are kept in {out / 'payload-runs'}; run the same command again to finish the rest"
    assert (out / "partial.bin").exists()  # a resumable experiment's folder stays


def test_ctrl_c_while_the_command_line_loads_is_one_line(tmp_path):
    """The `twin` script's entry loads the command line inside the guard: an interrupt during the imports
    (stood in for here by one raised from them) is the same line and code as any other."""
    code = ("import builtins, sys\n"
            "real = builtins.__import__\n"
            "def interrupted(name, *a, **k):\n"
            "    if name == 'twin.cli': raise KeyboardInterrupt\n"
            "    return real(name, *a, **k)\n"
            "builtins.__import__ = interrupted\n"
            "from twin.__main__ import entry\n"
            "sys.exit(entry())\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 130 and proc.stderr.strip() == "twin: interrupted", proc.stderr


def test_a_resumable_experiment_that_fails_keeps_its_folder_and_its_runs(tmp_path, capsys, monkeypatch):
    """Whatever stops a resumable experiment (here an error after some runs), the folder it made stays:
    its store may hold hours of finished runs."""
    from twin.exceptions import InvalidScenario
    from twin.experiments.whatifs import payload

    def run(self, args, out):
        (out / "payload-runs").mkdir()
        (out / "payload-runs" / "results.sqlite").write_bytes(b"runs")
        raise InvalidScenario("late")

    monkeypatch.setattr(type(payload.EXPERIMENT), "run", run)
    out = tmp_path / "p"
    assert main(["whatif", "payload", "--out", str(out)]) == 2
    _one_line_error(capsys, "late")
    assert (out / "payload-runs" / "results.sqlite").read_bytes() == b"runs"


def test_a_second_command_on_a_busy_new_folder_removes_nothing(tmp_path, capsys):
    """The folder another command made and is writing into (it holds the lock) is left whole when a second
    command on the same --out is refused: the second one did not make it, whatever it saw first."""
    from twin.batch.lock import folder_lock

    out = tmp_path / "busy"
    out.mkdir()
    (out / "work.bin").write_bytes(b"hours")
    with folder_lock(out):
        assert main(["whatif", "gear-load", "--out", str(out)]) == 2
    _one_line_error(capsys, "is being written by process")
    assert (out / "work.bin").read_bytes() == b"hours"


def test_a_folder_made_here_but_locked_by_another_first_is_left_to_it(tmp_path, capsys, monkeypatch):
    """The race: this command makes the new folder, another takes its lock first and starts writing; this
    one is refused and must not remove the folder (it removes only while it holds the lock)."""
    import contextlib

    from twin.batch.lock import FolderBusy
    from twin.cli import common

    @contextlib.contextmanager
    def taken_first(folder):
        (folder / "theirs.bin").write_bytes(b"hours")
        raise FolderBusy(f"{folder} is being written by process 1")
        yield

    monkeypatch.setattr(common, "folder_lock", taken_first)
    out = tmp_path / "new"
    assert main(["whatif", "gear-load", "--out", str(out)]) == 2
    _one_line_error(capsys, "is being written by process 1")
    assert (out / "theirs.bin").read_bytes() == b"hours"


def test_sigterm_stops_an_experiment_as_ctrl_c_does(tmp_path, capsys, monkeypatch):
    """`kill` (SIGTERM) during a what-if: the same line, exit 130 and clean-up as Ctrl-C (the folder it
    made is gone), and the handler it replaced is back afterwards."""
    from twin.experiments.whatifs import gear_load

    def run(self, args, out):
        (out / "partial.bin").write_bytes(b"x")
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # the signal arrives first
        raise AssertionError("SIGTERM did not stop the run")

    class Unhandled(Exception):
        pass

    def sentinel(number, frame):  # stands in for "no handler": without the fix, this fails the test, not pytest
        raise Unhandled

    monkeypatch.setattr(type(gear_load.EXPERIMENT), "run", run)
    before = signal.signal(signal.SIGTERM, sentinel)
    try:
        out = tmp_path / "new"
        assert main(["whatif", "gear-load", "--out", str(out)]) == 130
        assert capsys.readouterr().err.strip().splitlines()[-1] == "twin: interrupted"
        assert not out.exists()
        assert signal.getsignal(signal.SIGTERM) is sentinel  # put back afterwards
    finally:
        signal.signal(signal.SIGTERM, before)


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26, a later session's slower machine)
def test_a_figure_that_cannot_be_drawn_costs_no_table(tmp_path, capsys, monkeypatch):
    """A plotting library's error (not the disk's) leaves the tables written: exit 1, one line naming the
    figure, and no figure of an earlier run left to pass for this one's."""
    from twin.experiments.whatifs import gear_load

    def broken(self, outcome, path):
        path.write_bytes(b"half a png")
        raise ValueError("no such font\nsecond line")

    out = tmp_path / "g"
    out.mkdir()
    (out / "gear-load.png").write_bytes(b"an earlier run's")
    monkeypatch.setattr(type(gear_load.EXPERIMENT), "plot", broken)
    assert main(["whatif", "gear-load", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "twin: could not draw gear-load.png: ValueError: no such font\n" in err and "Traceback" not in err
    assert sorted(p.name for p in out.iterdir()) == [".twin.lock", "gear-load.csv", "gear-load.txt"]


def _calibration_stand_ins(monkeypatch, preset):
    """``twin calibrate`` with its fit, record and plot stood in for (the file handling is under test)."""
    from twin.experiments import calibrate
    from twin.plants import as_built

    monkeypatch.setattr(as_built, "CALIBRATION_FILE", preset)
    monkeypatch.setattr(calibrate, "calibrate", lambda **kwargs: type("R", (), {"evaluations": 1, "wall_time": 0.0}))
    monkeypatch.setattr(calibrate, "record", lambda result: {"fitted": {"stiction": 1.0}})
    monkeypatch.setattr(calibrate, "format_residuals", lambda data: "residuals")


def test_calibrate_install_is_checked_before_the_fit(tmp_path, capsys, monkeypatch):
    from twin.experiments import calibrate

    _calibration_stand_ins(monkeypatch, pathlib.Path("/proc/as_built.json"))
    monkeypatch.setattr(calibrate, "calibrate", lambda **kwargs: pytest.fail("the fit ran"))
    assert main(["calibrate", "--out", str(tmp_path / "c"), "--install"]) == 2
    _one_line_error(capsys, "--install: cannot write the as-built preset's folder /proc")
    assert list(tmp_path.iterdir()) == []


def test_calibrate_says_it_has_begun_before_its_workers_start(tmp_path, capsys, monkeypatch):
    """`twin calibrate` printed nothing for about 15 s, while its workers started and compiled (a helper's probe,
    stop 40). Its first line now comes before the fit: how many evaluations at most, on how many workers."""
    import viz.calibration_plots
    from twin.experiments import calibrate

    _calibration_stand_ins(monkeypatch, tmp_path / "as_built.json")
    said = []
    monkeypatch.setattr(calibrate, "calibrate", lambda **kwargs: said.append(capsys.readouterr().err) or
                        type("R", (), {"evaluations": 1, "wall_time": 0.0}))
    monkeypatch.setattr(calibrate, "planned_evaluations", lambda: 70)
    monkeypatch.setattr(viz.calibration_plots, "plot_calibration", lambda data, png: png.write_bytes(b"png"))
    assert main(["calibrate", "--out", str(tmp_path / "c"), "--workers", "2"]) == 0
    assert said == ["calibrate: 70 evaluations at most, on 2 workers; a line for each once the workers have "
                    "started\n"]


def test_calibrate_installs_whole_or_not_at_all_and_before_its_figure(tmp_path, capsys, monkeypatch):
    """The preset is replaced by a rename: a disk that fills while the new one is written leaves the old
    one whole (and no temporary); the figure comes after the install, and its failure loses neither file."""
    import json

    import viz.calibration_plots

    preset = tmp_path / "data" / "as_built.json"
    preset.parent.mkdir()
    preset.write_text('{"old": true}\n')
    _calibration_stand_ins(monkeypatch, preset)
    real = pathlib.Path.write_text

    def full_disk(self, text, *args, **kwargs):
        if self.parent == preset.parent:
            real(self, text[:5], *args, **kwargs)
            raise OSError(errno.ENOSPC, "No space left on device", str(self))
        return real(self, text, *args, **kwargs)

    monkeypatch.setattr(pathlib.Path, "write_text", full_disk)
    assert main(["calibrate", "--out", str(tmp_path / "c1"), "--install"]) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines()[-1] == f"twin: error: cannot write {preset}: No space left on device"  # not
    # its temporary (stop 60)
    assert preset.read_text() == '{"old": true}\n' and sorted(p.name for p in preset.parent.iterdir()) == [
        "as_built.json"]
    # the finished fit is kept in the folder the command made, though the install failed after it
    assert json.loads((tmp_path / "c1" / "as_built.json").read_text()) == {"fitted": {"stiction": 1.0}}
    monkeypatch.setattr(pathlib.Path, "write_text", real)

    def broken(data, path):
        raise RuntimeError("matplotlib says no")

    monkeypatch.setattr(viz.calibration_plots, "plot_calibration", broken)
    (tmp_path / "c2").mkdir()
    (tmp_path / "c2" / "calibration.png").write_bytes(b"an earlier fit's")
    assert main(["calibrate", "--out", str(tmp_path / "c2"), "--install"]) == 1
    err = capsys.readouterr().err
    assert "twin: could not draw calibration.png: RuntimeError: matplotlib says no" in err
    assert sorted(p.name for p in (tmp_path / "c2").iterdir()) == [".twin.lock", "as_built.json"]
    monkeypatch.setattr(viz.calibration_plots, "plot_calibration", lambda data, path: path.write_bytes(b"png"))
    assert main(["calibrate", "--out", str(tmp_path / "c2")]) == 0
    assert sorted(p.name for p in (tmp_path / "c2").iterdir()) == [".twin.lock", "as_built.json", "calibration.png"]
    assert json.loads(preset.read_text()) == {"fitted": {"stiction": 1.0}}
    assert (tmp_path / "c2" / "as_built.json").read_text() == preset.read_text()


@pytest.mark.slow  # about 10 s on 2 cores: four demos of 12-36 runs
def test_a_demo_rerun_leaves_one_run_in_its_folder_and_a_stopped_one_leaves_it_as_it_was(tmp_path, capsys,
                                                                                      monkeypatch):
    """Fewer seeds, then a demo stopped while it plots: the folder holds the last whole run's files only
    (no figure of a run with more seeds, no staging folder), and the user's own files stay."""
    import viz.plots

    drawn = []

    def quick(result, path):  # the file handling is under test, not the figure
        drawn.append(path.name)
        path.write_bytes(b"png")

    monkeypatch.setattr(viz.plots, "plot_run", quick)
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--seeds", "2"]) == 0
    (out / "mine.txt").write_text("keep")
    assert main(["demo", "--out", str(out), "--seeds", "1"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted([".twin.lock", "mine.txt", "results.csv", "summary.md",
                            *[f"{c}_T{t}_seed0.png" for c in ("pva", "ffpva", "smc") for t in (1, 2, 3, 4)]])
    table = (out / "results.csv").read_text()

    def stopped(result, path):
        if len(drawn) > 3:
            raise KeyboardInterrupt
        quick(result, path)

    drawn.clear()
    monkeypatch.setattr(viz.plots, "plot_run", stopped)
    assert main(["demo", "--out", str(out), "--seeds", "3"]) == 130
    assert sorted(p.name for p in out.iterdir()) == names and (out / "results.csv").read_text() == table
    drawn.clear()
    assert main(["demo", "--out", str(tmp_path / "new"), "--seeds", "1"]) == 130
    assert not (tmp_path / "new").exists()
    mine = tmp_path / "mine"  # a folder no demo wrote: a PNG that only looks like a run's stays
    mine.mkdir()
    (mine / "smc_T1_seed7.png").write_bytes(b"my own")
    monkeypatch.setattr(viz.plots, "plot_run", quick)
    assert main(["demo", "--out", str(mine), "--seeds", "1", "--no-plots"]) == 0
    assert (mine / "smc_T1_seed7.png").read_bytes() == b"my own"


def test_a_sweep_on_ray_without_ray_is_one_line_before_anything(tmp_path, capsys, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "ray" else real(name, *a))
    assert main(["sweep", "--seed", "0", "--backend", "ray", "--out", str(tmp_path / "s")]) == 2
    _one_line_error(capsys, "--backend ray: Ray is not installed here")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("extra, words", [
    (["--backend", "ray", "--ray-address", "127.0.0.1:1"], "--ray-address: cannot reach a Ray cluster at 127.0.0.1:1"),
    (["--backend", "ray", "--ray-address", "head"], "--ray-address: HOST:PORT, ray://HOST:PORT, auto or local"),
    (["--backend", "ray", "--ray-address", "ray://head:99999"], "--ray-address: HOST:PORT"),
    (["--ray-address", "127.0.0.1:6379"], "--ray-address: only with --backend ray"),
    (["--backend", "ray", "RAY_ADDRESS=127.0.0.1:1"], "RAY_ADDRESS: cannot reach a Ray cluster at 127.0.0.1:1"),
])
def test_a_ray_address_that_cannot_be_reached_is_one_line_before_anything(tmp_path, capsys, monkeypatch, extra, words):
    """Found by probing (2026-11-27): a wrong --ray-address (or RAY_ADDRESS) left the sweep at 0 of 1 for minutes
    while Ray retried, and without --backend ray the address was silently ignored."""
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    for item in [e for e in extra if e.startswith("RAY_ADDRESS=")]:
        monkeypatch.setenv("RAY_ADDRESS", item.split("=", 1)[1])
        extra = [e for e in extra if e != item]
    assert main(["sweep", "--seed", "0", *extra, "--out", str(tmp_path / "s")]) == 2
    _one_line_error(capsys, words)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("server", ["web", "silent"])
def test_a_ray_address_that_answers_but_not_as_ray_is_one_line_before_anything(tmp_path, capsys, monkeypatch, server):
    """Found by a helper's probing (2026-12-08): an address where something else listens (a web server, Ray's
    dashboard) passed the connection check, and the sweep then sat at 0 of 1 while Ray retried, took 32 s to stop
    on a Ctrl-C and said "finished scenarios are kept" of none. A server that never replies is refused too."""
    import http.server
    import socketserver
    import threading

    from twin.cli import sweep

    class Silent(socketserver.BaseRequestHandler):
        def handle(self):
            self.request.recv(1024)
            time.sleep(1.0)  # past the timeout below, then close

    handler = http.server.SimpleHTTPRequestHandler if server == "web" else Silent
    monkeypatch.setattr(http.server.SimpleHTTPRequestHandler, "log_message", lambda *a: None)
    monkeypatch.setattr(sweep, "RAY_CONNECT_TIMEOUT", 0.3)
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    monkeypatch.delenv("RAY_USE_TLS", raising=False)
    with socketserver.ThreadingTCPServer(("127.0.0.1", 0), handler) as listening:
        threading.Thread(target=listening.serve_forever, daemon=True).start()
        address = f"127.0.0.1:{listening.server_address[1]}"
        try:
            assert main(["sweep", "--seed", "0", "--backend", "ray", "--ray-address", address,
                         "--out", str(tmp_path / "s")]) == 2
            _one_line_error(capsys, f"--ray-address: {address} answers, but not as a Ray cluster does")
            assert list(tmp_path.iterdir()) == []
            monkeypatch.setenv("RAY_USE_TLS", "1")  # a TLS cluster wants a handshake first: the connection alone
            sweep.check_ray_address(address)
        finally:
            listening.shutdown()


def test_ray_failing_to_connect_is_not_read_as_a_file_that_cannot_be_written(monkeypatch):
    """Ray's ConnectionError is an OSError, which the command line reads as an unwritable output."""
    import ray

    from twin.batch import grid, sweep

    def refuse(**_):
        raise ConnectionError("Could not find any running Ray instance.\nmore")

    monkeypatch.setattr(ray, "is_initialized", lambda: False)
    monkeypatch.setattr(ray, "init", refuse)
    with pytest.raises(sweep.ClusterNotStarted, match="^could not reach the Ray cluster at auto: Could not find any "
                                                      "running Ray instance.; no scenario ran$"):  # (stop 41: was
        sweep._ray(grid.expand({"seed": [0]}), None, "auto", lambda rows: None)  # "finished scenarios are kept")
    monkeypatch.setattr(ray, "is_initialized", lambda: True)  # connected; then the connection breaks mid-sweep
    monkeypatch.setattr(ray, "cluster_resources", lambda: {"CPU": 1})
    monkeypatch.setattr(ray, "remote", lambda function: type("Remote", (), {"remote": lambda self, chunk: chunk})())
    monkeypatch.setattr(ray, "wait", lambda pending, num_returns: refuse())
    monkeypatch.setattr(ray, "cancel", lambda ref: refuse())  # a lost cluster refuses the clean-up too
    with pytest.raises(sweep.ClusterUnreachable, match="^lost or could not reach the Ray cluster at auto"):
        sweep._ray(grid.expand({"seed": [0]}), None, "auto", lambda rows: None)


def test_a_broken_pipe_while_a_ray_sweep_reports_is_not_the_clusters(monkeypatch):
    """Only Ray's own calls are read as the cluster's: on_done's own BrokenPipeError (a ConnectionError) is not."""
    import ray

    from twin.batch import grid, sweep

    def broken(rows):
        raise BrokenPipeError(errno.EPIPE, "Broken pipe")

    monkeypatch.setattr(ray, "is_initialized", lambda: True)
    monkeypatch.setattr(ray, "cluster_resources", lambda: {"CPU": 1})
    monkeypatch.setattr(ray, "remote", lambda function: type("Remote", (), {"remote": lambda self, chunk: chunk})())
    monkeypatch.setattr(ray, "wait", lambda pending, num_returns: (pending[:1], pending[1:]))
    monkeypatch.setattr(ray, "get", lambda ref: [])
    monkeypatch.setattr(ray, "cancel", lambda ref: None)
    with pytest.raises(BrokenPipeError):
        sweep._ray(grid.expand({"seed": [0]}), None, "auto", broken)


def test_an_os_error_without_a_file_is_said_as_itself(capsys, monkeypatch):
    """Only an OSError that names a file reads "cannot write FILE" (a failed fork said "cannot write : None")."""
    import twin.cli as cli

    def failing(args):
        raise BlockingIOError(errno.EAGAIN, "Resource temporarily unavailable")

    parser = cli.build_parser()
    monkeypatch.setattr(cli, "build_parser", lambda: parser)
    monkeypatch.setattr(parser, "parse_known_args", lambda argv: (argparse.Namespace(func=failing), []))
    assert main(["bench"]) == 2
    _one_line_error(capsys, "twin: error: [Errno 11] Resource temporarily unavailable")


@pytest.mark.slow  # over ~2.5 s on 2 cores: two sweeps
def test_a_sweep_whose_plot_fails_writes_its_tables(tmp_path, capsys, monkeypatch):
    import viz.sweep_plots

    out = tmp_path / "s"
    argv = ["sweep", "--controller", "ffpva", "--trajectory", "2", "--seed", "0", "--workers", "1", "--out", str(out)]
    assert main(argv) == 0
    assert (out / "rmse.png").exists()
    monkeypatch.setattr(viz.sweep_plots, "plot_summary", lambda summary, path: 1 / 0)
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "twin: could not draw rmse.png: ZeroDivisionError" in err and "Traceback" not in err
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "results.csv", "results.parquet", "results.sqlite", "summary.csv"]


def test_the_evaluators_workers_leave_ctrl_c_to_the_parent_and_stop_at_once_on_abort():
    """Like a sweep's: a worker ignores SIGINT (the parent stops it) and dies with its parent; on Ctrl-C,
    SIGTERM or an error the parent kills them rather than waiting for the share each is running."""
    from twin.experiments.calibrate import Evaluator

    evaluator = Evaluator(seeds=(0,), workers=2)
    try:
        assert evaluator.pool.submit(signal.getsignal, signal.SIGINT).result(timeout=60) == signal.SIG_IGN
        busy = evaluator.pool.submit(time.sleep, 60)
        waited = time.monotonic()
        while not busy.running() and time.monotonic() - waited < 30:
            time.sleep(0.01)
        workers = list(evaluator.pool._processes)  # PIDs
        started = time.monotonic()
        evaluator.abort()

        def running(pid: int) -> bool:  # by /proc: the pool's own thread may have reaped it already
            try:
                return pathlib.Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
            except OSError:  # gone, or going while read
                return False

        def alive() -> list[int]:
            return [pid for pid in workers if running(pid)]

        while alive() and time.monotonic() - started < 10:
            time.sleep(0.05)
        assert alive() == [], "workers outlived the abort"
        assert busy.done()  # settled (broken), not still running its minute
    finally:
        evaluator.abort()


def test_a_plotting_librarys_own_oserror_costs_only_the_figure_and_a_full_disk_stops_all(tmp_path):
    """matplotlib's font cache or an image encoder can raise OSErrors of their own: those only cost the
    figure; the disk's (full, read-only, refused) still stop the whole set."""
    from twin.experiments.base import drawn

    undrawn = []

    def font(path):
        path.write_bytes(b"half")
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", "/usr/share/fonts/x.ttf")

    assert drawn(font, tmp_path / "a.png", undrawn) == [] and not (tmp_path / "a.png").exists()
    assert undrawn == [("a.png", "FileNotFoundError: [Errno 2] No such file or directory: '/usr/share/fonts/x.ttf'")]

    def full(path):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    with pytest.raises(OSError, match="No space left"):
        drawn(full, tmp_path / "b.png", undrawn)
    assert drawn(lambda path: path.write_bytes(b"png"), tmp_path / "c.png", undrawn) == [tmp_path / "c.png"]


def test_a_stop_while_a_set_is_renamed_in_waits_until_the_whole_set_is_in(tmp_path, monkeypatch,
                                                                          ctrl_c_as_in_a_terminal):
    """Ctrl-C and SIGTERM that come between two of staged()'s renames are held until the last one: the
    folder gets the whole new set and loses the staging folder, then the stops are delivered in order to
    the handlers they had, each even when an earlier one raised."""
    from twin.experiments.base import staged

    out = tmp_path / "out"
    out.mkdir()
    rename = os.replace
    terms = []
    before = signal.signal(signal.SIGTERM, lambda number, frame: terms.append(number))
    try:
        for order in ([signal.SIGTERM, signal.SIGINT], [signal.SIGINT, signal.SIGTERM]):
            for name in ("a.csv", "b.csv", "c.png"):
                (out / name).write_text("old")
            signals = iter([*order, None])

            def rename_then_stop(source, target, signals=signals):
                rename(source, target)
                signum = next(signals)
                if signum is not None:
                    os.kill(os.getpid(), signum)
                    time.sleep(0.05)  # an unheld signal would be handled here, mid-set

            terms.clear()
            monkeypatch.setattr(os, "replace", rename_then_stop)
            with pytest.raises(KeyboardInterrupt), staged(out, "t") as stage:
                for name in ("a.csv", "b.csv", "c.png"):
                    (stage.folder / name).write_text("new")
                    stage.names.append(name)
            monkeypatch.undo()
            assert {path.name: path.read_text() for path in out.iterdir()} == {"a.csv": "new", "b.csv": "new",
                                                                               "c.png": "new"}
            assert terms == [signal.SIGTERM]  # delivered after the set was in, whichever came first
            assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGTERM, before)


def test_a_folder_in_the_way_of_an_output_file_is_refused_and_no_file_of_the_set_moves(tmp_path, capsys):
    """Found by probing (2026-11-27): with a folder named like one of a set's files, the files before it were
    already renamed in when the rename onto the folder failed, and the error named the staging folder. Now
    staged() checks every name first, and a what-if checks its usual names before it runs."""
    from twin.experiments.base import staged

    (tmp_path / "b.png").mkdir()
    (tmp_path / "a.csv").write_text("old")
    with pytest.raises(IsADirectoryError, match="a folder is in the way") as error, staged(tmp_path, "x") as stage:
        for name in ("a.csv", "b.png"):
            (stage.folder / name).write_text("new")
            stage.names.append(name)
    assert error.value.filename == str(tmp_path / "b.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "b.png"] and (tmp_path / "a.csv").read_text() == "old"
    out = tmp_path / "out"
    (out / "gear-load.png").mkdir(parents=True)
    assert _exit_code(["whatif", "gear-load", "--out", str(out)]) == 2
    _one_line_error(capsys, f"cannot write {out / 'gear-load.png'}: a folder is in the way of this file")
    assert [p.name for p in out.iterdir()] == ["gear-load.png"]


@pytest.mark.parametrize("argv", [
    ["run", "--controller", "smc", "--trajectory", "1", "--seed", "1" + "0" * 400],
    ["demo", "--seeds", "1" + "0" * 400],
    ["bench", "--batch", "9" * 5000],  # past Python's 4300-digit limit on int()
])
def test_an_integer_too_long_for_a_float_is_a_one_line_error(argv, capsys):
    """math.isfinite(int) converts to float: a 401-digit seed overflowed it, a traceback (found 2026-11-27)."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    _one_line_error(capsys, "got '")


def test_a_killed_pool_leaves_no_thread_running_into_the_exit():
    """kill_pool kills the workers and waits for the pool's manager thread to end: left running into the
    interpreter's exit it wrote to a closed pipe, and a Ctrl-C printed a traceback after its one line."""
    from twin.batch import sweep

    pool = sweep.fork_pool(2)
    futures = [pool.submit(time.sleep, 30) for _ in range(4)]
    deadline = time.monotonic() + 60
    while not any(f.running() for f in futures):
        assert time.monotonic() < deadline, "no worker started within 60 s"
        time.sleep(0.01)
    manager = pool._executor_manager_thread
    assert manager is not None and manager.is_alive()
    sweep.kill_pool(pool)
    assert not manager.is_alive()
    assert all(not p.is_alive() for p in (pool._processes or {}).values())


@pytest.mark.parametrize("stop", ["SIGTERM", "SIGHUP"])
def test_a_kill_or_a_closed_terminal_while_twin_run_writes_leaves_nothing(tmp_path, capsys, monkeypatch, stop):
    """`twin run` ran outside the SIGTERM guard that other commands have: a kill while it wrote left a
    half-written hidden temporary beside its outputs and exit 143, with no word (a helper's probe, stop 40).
    Every command now runs inside it, and a closed terminal (SIGHUP) stops as Ctrl-C does too."""
    from twin.sim import report

    def write_trace(result, path):
        pathlib.Path(path).write_text("t_s,theta_deg\n0,30\n")  # part of the trace on disk
        os.kill(os.getpid(), getattr(signal, stop))
        time.sleep(5)  # the signal arrives first
        raise AssertionError(f"{stop} did not stop the run")

    class Unhandled(Exception):
        pass

    def sentinel(number, frame):  # stands in for "no handler": without the fix this fails the test, not pytest
        raise Unhandled

    monkeypatch.setattr(report, "write_trace", write_trace)
    signum = getattr(signal, stop)
    before = signal.signal(signum, sentinel)
    try:
        argv = ["run", "--controller", "ffpva", "--trajectory", "2", "--trace", str(tmp_path / "t.csv"),
                "--plot", str(tmp_path / "p.png")]
        assert main(argv) == 130
        assert capsys.readouterr().err.strip().splitlines()[-1] == "twin: interrupted"
        assert list(tmp_path.iterdir()) == []  # no output, no temporary
        assert signal.getsignal(signum) is sentinel  # put back afterwards
    finally:
        signal.signal(signum, before)


def test_a_closed_stdout_after_the_outputs_are_written_is_not_called_bad_input(tmp_path, monkeypatch):
    """`twin run --json | true`: every output written, then 'twin: error: [Errno 32] Broken pipe' and exit 2,
    the code for bad input with nothing written (a helper's probe, stop 40). Now 141, as a shell reports a
    reader that went away, and no message."""
    read, write = os.pipe()
    os.close(read)  # the reader is gone before the first line
    argv = [sys.executable, "-m", "twin", "run", "--controller", "ffpva", "--trajectory", "2", "--json", "--trace",
            str(tmp_path / "t.csv")]
    proc = subprocess.run(argv, stdout=write, stderr=subprocess.PIPE, text=True, timeout=300)
    os.close(write)
    assert proc.returncode == 141, proc.stderr
    assert "Broken pipe" not in proc.stderr and "error" not in proc.stderr
    assert (tmp_path / "t.csv").stat().st_size > 10_000  # the trace is whole


def test_a_grid_file_over_1_mb_is_refused_without_reading_it_all(tmp_path):
    """`twin sweep --config /dev/zero` read until the kernel killed it (24 GB in 10 s; a helper's probe, stop
    40). Now it reads at most 1 MB. (Checked on a 2 MB file, not on /dev/zero: without the fix that would
    take the machine's memory, not fail.)"""
    from twin.batch import grid
    from twin.exceptions import InvalidScenario

    big = tmp_path / "big.toml"
    big.write_text("seed = [0]\n" + "# padding\n" * 200_000)
    with pytest.raises(InvalidScenario, match="over 1 MB: not a grid"):
        grid.read_toml(big)
    small = tmp_path / "small.toml"
    small.write_text("seed = [0, 1]\n")
    assert grid.read_toml(small) == {"seed": [0, 1]}


@pytest.mark.slow  # 5-8 s on 2 cores: a whole what-if in a subprocess, the cheapest that draws a progress bar
def test_a_command_started_with_its_error_stream_closed_still_runs(tmp_path):
    """`twin whatif gear-load --out DIR 2>&-` exited 1 with no word and removed its folder: the progress bar
    wrote to a missing stderr (a helper's probe, stop 40). Now both streams fall back to /dev/null."""
    script = "import sys; from twin.__main__ import entry; sys.exit(entry())"
    proc = subprocess.run([sys.executable, "-c", script, "whatif", "gear-load", "--out", str(tmp_path / "g")],
                          stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                          timeout=300, close_fds=True, pass_fds=(), preexec_fn=lambda: os.close(2))
    assert proc.returncode == 0
    assert (tmp_path / "g").is_dir() and any((tmp_path / "g").iterdir())


def test_a_command_started_under_nohup_runs_on_when_the_terminal_closes(tmp_path, capsys, monkeypatch):
    """``nohup`` starts a command with SIGHUP ignored so that it outlives the terminal; the SIGHUP guard
    above must leave it ignored (a review caught the first version of that guard taking it over)."""
    from twin.sim import report

    plain = report.write_trace

    def write_trace(result, path):
        os.kill(os.getpid(), signal.SIGHUP)  # the terminal closes mid-run
        time.sleep(0.2)
        plain(result, path)

    monkeypatch.setattr(report, "write_trace", write_trace)
    before = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        assert main(["run", "--controller", "ffpva", "--trajectory", "2", "--trace", str(tmp_path / "t.csv")]) == 0
        assert (tmp_path / "t.csv").stat().st_size > 10_000
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, before)


def test_a_broken_pipe_in_process_returns_its_code_and_leaves_the_callers_stdout_alone(monkeypatch, capsys):
    """``main`` called in a process of its own caller's (a script, a test): a reader gone away is its exit code
    only; the caller's stdout is not redirected (a review caught the first version doing that in ``main``)."""
    from twin.cli import run as run_command

    def gone(args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(run_command, "_cmd_run", gone)
    monkeypatch.setattr(sys, "stdout", sys.stdout)
    before = os.fstat(1)
    parser_default = main(["run", "--controller", "ffpva", "--trajectory", "2"])
    assert parser_default == 141
    after = os.fstat(1)
    assert (before.st_dev, before.st_ino) == (after.st_dev, after.st_ino)


class _StopInsideDel:
    """An object whose ``__del__`` sends ``signum`` to this process: the handler's KeyboardInterrupt is raised
    inside ``__del__``, where Python swallows it ("Exception ignored in ..."), as it does inside a garbage
    collector's callback."""

    def __init__(self, signum: int):
        self.signum = signum

    def __del__(self):
        os.kill(os.getpid(), self.signum)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_a_stop_python_swallowed_during_a_run_still_stops_it_before_its_outputs(tmp_path, capsys, monkeypatch,
                                                                                 signum, ctrl_c_as_in_a_terminal):
    """A Ctrl-C or SIGTERM that landed inside a garbage collector's callback during `twin run` (2 in 8 tries at
    one moment) was swallowed: the run wrote its outputs and exited 0, the stop lost. Now it is raised again
    before the outputs go into place: exit 130, nothing written, and the unraisable hook put back."""
    from twin.sim import report

    plain = report.write_trace

    def write_trace(result, path):
        _StopInsideDel(signum)  # dropped at once: its stop is swallowed here
        plain(result, path)

    monkeypatch.setattr(report, "write_trace", write_trace)
    hook = sys.unraisablehook
    assert main(["run", "--controller", "ffpva", "--trajectory", "2", "--trace", str(tmp_path / "t.csv")]) == 130
    err = capsys.readouterr().err
    assert err.strip().splitlines()[-1] == "twin: interrupted"
    assert "Exception ignored" not in err
    assert list(tmp_path.iterdir()) == []  # no output, no temporary
    assert sys.unraisablehook is hook


def test_a_stop_python_swallowed_during_an_experiment_still_stops_it(tmp_path, capsys, monkeypatch):
    """The same for a what-if: its tables are not put into place and the folder it made goes."""
    from twin.experiments.whatifs import gear_load

    plain = type(gear_load.EXPERIMENT).run

    def run(self, args, out):
        outcome = plain(self, args, out)
        _StopInsideDel(signal.SIGTERM)
        return outcome

    monkeypatch.setattr(type(gear_load.EXPERIMENT), "run", run)
    out = tmp_path / "new"
    assert main(["whatif", "gear-load", "--out", str(out)]) == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "twin: interrupted"
    assert not out.exists()


def test_other_errors_python_swallows_are_still_reported(tmp_path, monkeypatch):
    """Only a swallowed stop is kept back: any other error inside ``__del__`` goes to the hook that was there
    before (Python's prints it), and the command goes on."""
    from twin.sim import report

    class Broken:
        def __del__(self):
            raise ValueError("broken finaliser")

    plain = report.write_trace

    def write_trace(result, path):
        Broken()
        plain(result, path)

    monkeypatch.setattr(report, "write_trace", write_trace)
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", seen.append)
    assert main(["run", "--controller", "ffpva", "--trajectory", "2", "--trace", str(tmp_path / "t.csv")]) == 0
    assert [str(u.exc_value) for u in seen] == ["broken finaliser"]
    assert (tmp_path / "t.csv").stat().st_size > 10_000


@pytest.mark.parametrize("argv, needle", [
    (["run", "--controller", "ffpva", "--trajectory", "2", "--payload", "5_0"],
     "payload must be a non-negative number of grams, got '5_0'"),
    (["run", "--controller", "ffpva", "--trajectory", "2", "--seed", "\uff13"],
     "seed must be an integer from 0 to 2^63 - 1, got '\uff13'"),
    (["sweep", "--payload", "0,6_5", "--out", "x"], "bad value '6_5' for --payload"),
    (["sweep", "--seed", "0-1_0", "--out", "x"], "bad value '0-1_0' for --seed"),
    (["sweep", "--payload", "0:1_0:5", "--out", "x"], "bad value '0:1_0:5' for --payload"),
    (["whatif", "smc-phi", "--phis", "0.1_5", "--out", "x"], "--phis: numbers in m/s separated by commas"),
    (["whatif", "pva-rate", "--rates", "\u0664", "--out", "x"], "--rates: whole milliseconds separated by commas"),
    (["run", "--controller", "ffpva", "--trajectory", "\uff13"], "trajectory must be 1, 2, 3 or 4, got '\uff13'"),
    (["whatif", "payload", "--trajectory", "1_0", "--out", "x"], "trajectory must be 1, 2, 3 or 4, got '1_0'"),
    (["whatif", "next-experiment", "--pressure-step", "1_0", "--out", "x"], "expected a number of kPa, got '1_0'"),
])
def test_numbers_in_pythons_other_spellings_are_refused(tmp_path, capsys, monkeypatch, argv, needle):
    """Flags took Python's other number spellings: ``5_0`` as 50, full-width and other scripts' digits (a
    helper's probe, stop 40), where `twin score` refused ``2_5``. Every number flag and list now reads ASCII
    digits, a point and an exponent only; nothing is written."""
    monkeypatch.chdir(tmp_path)
    try:
        code = main(argv)
    except SystemExit as stopped:  # a flag's own type: argparse's exit
        code = stopped.code
    assert code == 2
    _one_line_error(capsys, needle)
    assert list(tmp_path.iterdir()) == []


def test_numbers_written_plainly_still_read():
    """What the refusal above must not catch: signs, a leading or trailing point, an exponent, spaces round a
    list item; an int axis still takes 3.0 as 3."""
    from twin.batch import grid

    assert grid.parse_axis("payload", "+5, .5,5.,1e1") == [5.0, 0.5, 10.0]
    assert grid.parse_axis("seed", "3.0, 1-2") == [3, 1, 2]
    assert grid.plain_number("-0") == 0.0 and grid.plain_number(" 7 ", int) == 7


@pytest.mark.parametrize("argv, needle", [
    (["study", "robustness", "--plant", "", "--out", "x"], "unknown plant ''"),
    (["study", "openloop", "--plant", "", "--out", "x"], "unknown plant ''"),
    (["sweep", "--payload", "0,1e400", "--out", "x"], "bad value '1e400' for --payload: expected finite numbers"),
    (["run", "--controller", "smc", "--trajectory", "2", "--html", "x.html", "--compare", "controller=smc"],
     "--compare controller=smc: the first joint has these settings already: nothing to compare"),
    (["run", "--plant", "as-built", "--without", "stiction", "--controller", "smc", "--trajectory", "2", "--html",
      "x.html", "--compare", "without=stiction,seed=0"], "--compare without=stiction,seed=0: the first joint has"),
    (["run", "--controller", "smc", "--trajectory", "2", "--html", "x.html", "--compare", "supply-kpa=300"],
     "--compare supply-kpa=300: the first joint has"),  # the thesis plant's own supply, named
])
def test_the_probes_last_inputs_are_refused(tmp_path, capsys, monkeypatch, argv, needle):
    """What a helper's probe (stop 40) left: an empty `--plant` ran the default plant's study; a payload of
    1e400 was named "inf g"; a `--compare` that changes nothing recorded two alike joints. Each is now a
    one-line error, exit 2, nothing written."""
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    _one_line_error(capsys, needle)
    assert list(tmp_path.iterdir()) == []


def test_a_stop_python_swallowed_during_a_sweep_stops_it_after_the_batch_it_came_in(tmp_path, capsys, monkeypatch,
                                                                                  ctrl_c_as_in_a_terminal):
    """In a sweep, a swallowed stop is raised again once the batch it came in is stored: the sweep stops as on
    Ctrl-C (exit 130, the finished batch kept for a resume), instead of running every batch."""
    from twin.batch import sweep

    plain = sweep.run_chunk

    def run_chunk(chunk):
        rows = plain(chunk)
        _StopInsideDel(signal.SIGINT)
        return rows

    monkeypatch.setattr(sweep, "run_chunk", run_chunk)
    out = tmp_path / "s"
    assert main(["sweep", "--trajectory", "2,3", "--seed", "0-3", "--workers", "1", "--out", str(out)]) == 130
    assert "interrupted: finished scenarios are kept" in capsys.readouterr().err
    store = sweep.open_store(out)
    try:
        assert len(store.done()) == 4  # the first batch (one trajectory's four seeds), not the second
    finally:
        store.close()


def test_a_swallowed_stop_outlives_an_inner_block_that_ends_first(ctrl_c_as_in_a_terminal):
    """A command nests the keeping of swallowed stops (``main`` and its output folder each keep them): the inner
    block's end must not forget a stop the outer block has yet to raise (a review caught the first version)."""
    from twin.batch.stops import raise_if_stopped, swallowed_stops_kept

    hook = sys.unraisablehook
    with pytest.raises(KeyboardInterrupt), swallowed_stops_kept():
        with swallowed_stops_kept():
            _StopInsideDel(signal.SIGINT)
        raise_if_stopped()
    assert sys.unraisablehook is hook
    raise_if_stopped()  # nothing kept once the outer block has ended


def test_a_stop_python_swallowed_in_a_forked_sweep_stops_it_after_that_batch(tmp_path, capsys, monkeypatch):
    """The same on two worker processes: the stop is swallowed in the parent as it stores a finished batch."""
    from twin.batch import sweep

    plain = sweep.ResultStore.add
    calls = []

    def add(self, rows):
        plain(self, rows)
        calls.append(len(rows))
        if len(calls) == 1:
            _StopInsideDel(signal.SIGTERM)

    monkeypatch.setattr(sweep.ResultStore, "add", add)
    out = tmp_path / "s"
    assert main(["sweep", "--trajectory", "2,3", "--seed", "0-3", "--workers", "2", "--out", str(out)]) == 130
    assert "interrupted: finished scenarios are kept" in capsys.readouterr().err
    assert len(calls) == 1  # stopped after the first batch it stored, whichever finished first
    store = sweep.open_store(out)
    try:
        assert len(store.done()) == calls[0]
    finally:
        store.close()


def _must_not_run(*args, **kwargs):
    raise AssertionError("the work ran before the outputs were checked")


@pytest.mark.parametrize("command, in_the_way, work", [
    (["calibrate"], "as_built.json", "twin.experiments.calibrate.calibrate"),  # a finished fit was lost
    (["sweep", "--seed", "0"], "summary.csv", "twin.batch.sweep.run_sweep"),  # found once the grid had run
    (["demo", "--no-plots"], "results.csv", "twin.experiments.demo.run_demo"),
    (["demo"], "smc_T4_seed4.png", "twin.experiments.demo.run_demo"),  # a figure it will draw
])
def test_a_folder_in_the_way_of_an_output_is_found_before_the_work(tmp_path, capsys, monkeypatch, command,
                                                                   in_the_way, work):
    """Until stop 60 these three found it only when the results went into place: a calibration's whole fit
    (5-12 min) was lost, a sweep's grid ran first."""
    monkeypatch.setattr(work, _must_not_run)
    out = tmp_path / "out"
    (out / in_the_way).mkdir(parents=True)
    assert main([*command, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"twin: error: cannot write {out / in_the_way}: a folder is in the way of this file"
    assert sorted(p.name for p in out.iterdir()) == [in_the_way]


def _demos_summary(out):
    (out / "summary.md").write_text("# Thesis controller comparison on the twin ('thesis' plant, 5 seeds)\n")


def _sweeps_summary(out):
    from twin.batch.tables import write_summary

    write_summary([], out)


def _stopped_sweeps_store(out):
    from twin.batch.sweep import open_store

    open_store(out).close()


@pytest.mark.parametrize("command, other, mark, write", [
    (["sweep", "--seed", "0"], "demo", "summary.md", _demos_summary),
    (["demo", "--no-plots"], "sweep", "summary.csv", _sweeps_summary),
    (["demo", "--no-plots"], "sweep", "results.sqlite", _stopped_sweeps_store),  # no summary yet
])
def test_demo_and_sweep_refuse_each_others_folder_which_they_would_half_overwrite(tmp_path, capsys, monkeypatch,
                                                                                   command, other, mark, write):
    """Both write results.csv; a sweep into a demo's folder replaced it and left the demo's summary.md
    describing other runs (found by probing, stop 60)."""
    monkeypatch.setattr("twin.batch.sweep.run_sweep", _must_not_run)
    monkeypatch.setattr("twin.experiments.demo.run_demo", _must_not_run)
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.csv").write_text("theirs\n")
    write(out)
    assert main([*command, "--out", str(out)]) == 2
    assert capsys.readouterr().err.strip() == (f"twin: error: --out {out} holds twin {other}'s results ({mark}): "
                                               f"give twin {command[0]} a folder of its own")
    assert (out / "results.csv").read_text() == "theirs\n"


@pytest.mark.parametrize("command", [["sweep", "--seed", "0"], ["demo", "--no-plots"]])
def test_a_summary_of_the_users_own_is_no_other_commands(tmp_path, monkeypatch, command):
    monkeypatch.setattr("twin.batch.sweep.run_sweep", _must_not_run)
    monkeypatch.setattr("twin.experiments.demo.run_demo", _must_not_run)
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.md").write_text("# my own notes\n")
    (out / "summary.csv").write_text("controller,rmse\n")
    with pytest.raises(AssertionError, match="before the outputs were checked"):  # the check let it through
        main([*command, "--out", str(out)])


@pytest.mark.parametrize("command, said", [
    (["run", "--controller", "ffpva", "--trajectory", "1", "--payload", "200.0000001"], "got 200.0000001 g"),
    (["sweep", "--supply-kpa", "700.0000001", "--out", "never"], "got 700.0000001 kPa"),
    (["whatif", "next-experiment", "--pressure-step", "100.0000001", "--out", "never"], "got 100.0000001"),
])
def test_a_value_just_past_a_bound_is_not_shown_as_the_bound(tmp_path, capsys, monkeypatch, command, said):
    """They said "got 200 g", "got 700 kPa", "got 100" until stop 60."""
    monkeypatch.chdir(tmp_path)
    assert main(command) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.rstrip().endswith(said), err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", [["sweep", "--seed", "0"], ["whatif", "payload", "--payloads", "0", "--seeds", "1"]])
def test_a_command_whose_store_cannot_be_made_leaves_no_folder(tmp_path, capsys, command):
    """A full disk where the store is made: nothing ran, so a folder made here goes, as for refused input
    (it stayed, with a lock and a broken store, until stop 60)."""
    with _tmpfs(tmp_path / "disk", "64k") as disk:
        code = main([*command, "--out", str(disk / "out")])
        assert code == 2
        err = capsys.readouterr().err
        errors = [line for line in err.splitlines() if line.startswith("twin: error:")]
        assert len(errors) == 1 and err.rstrip().endswith(errors[0]), err
        assert errors[0].startswith("twin: error: cannot write the results store"), err
        assert list(disk.iterdir()) == []
