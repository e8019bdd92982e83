"""`twin sweep`: grids, resumption after SIGKILL, identical numbers whatever the backend or workers."""

from __future__ import annotations

import csv
import os
import pathlib
import signal
import sqlite3
import subprocess
import sys
import time

import pytest

from twin import grid
from twin.exceptions import InvalidScenario
from twin.sweep import make_chunks, run_chunk, run_sweep

ROOT = pathlib.Path(__file__).resolve().parents[1]
AXES = {"controller": ["ffpva", "smc"], "trajectory": [1, 2], "payload": [0.0, 13.5],
        "orientation": ["vertical"], "seed": [0, 1, 2]}


def _cli(*args, cwd, **kwargs):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", "twin", "sweep", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


def _rows(path: pathlib.Path) -> list[dict]:
    with open(path) as handle:
        return list(csv.DictReader(handle))


def test_axes_parse_lists_ranges_and_seed_spans():
    assert grid.parse_axis("payload", "0:30:7.5") == [0.0, 7.5, 15.0, 22.5, 30.0]
    assert grid.parse_axis("seed", "0-4") == [0, 1, 2, 3, 4]
    assert grid.parse_axis("seed", "1,3-4") == [1, 3, 4]
    assert grid.parse_axis("controller", "ffpva, smc") == ["ffpva", "smc"]
    assert grid.parse_axis("pwm_period_ms", "8:32:8") == [8.0, 16.0, 24.0, 32.0]
    assert len(grid.expand(AXES)) == 24


@pytest.mark.parametrize("name, value", [("payload", "abc"), ("controller", "foo"), ("trajectory", "5"),
                                         ("pwm_period_ms", "2.5"), ("supply_kpa", "900"), ("payload", "5:1:1")])
def test_bad_axis_values_are_rejected_naming_the_value(name, value):
    with pytest.raises(InvalidScenario, match="|".join([value.split(":")[0], "PWM", "supply", "range", "unknown"])):
        grid.expand({name: grid.parse_axis(name, value)})


def test_toml_grid(tmp_path):
    (tmp_path / "g.toml").write_text('[grid]\ncontroller = ["smc"]\npayload = "0:13.5:6.75"\nseed = "0-1"\n')
    axes = grid.read_toml(tmp_path / "g.toml")
    assert axes == {"controller": ["smc"], "payload": [0.0, 6.75, 13.5], "seed": [0, 1]}


def test_chunking_and_workers_do_not_change_numbers(tmp_path):
    points = grid.expand(AXES)
    assert len(make_chunks(points, 1)) != len(make_chunks(points, 2))  # really different batches
    one = run_sweep(points, out=_mkdir(tmp_path / "one"), workers=1).records
    two = run_sweep(points, out=_mkdir(tmp_path / "two"), workers=2).records
    assert [r["key"] for r in one] == [p.key for p in points]
    assert one == two
    assert all(r["status"] == "ok" for r in one)


def _mkdir(path: pathlib.Path) -> pathlib.Path:
    path.mkdir()
    return path


def test_rerun_skips_what_is_done(tmp_path):
    points = grid.expand({"controller": ["ffpva"], "trajectory": [2], "seed": [0, 1]})
    first = run_sweep(points, out=tmp_path, workers=1)
    again = run_sweep(points, out=tmp_path, workers=1)
    assert (first.ran, first.skipped) == (2, 0)
    assert (again.ran, again.skipped) == (0, 2)
    assert first.records == again.records


def test_a_scenario_that_raises_is_marked_failed_with_its_reason(monkeypatch):
    import twin.runner

    points = grid.expand({"controller": ["ffpva"], "trajectory": [2], "seed": [0, 1, 2]})
    real = twin.runner.run_many

    def flaky(scenarios, **kwargs):
        if any(s.seed == 1 for s in scenarios):
            raise RuntimeError("boom on seed 1")
        return real(scenarios, **kwargs)

    monkeypatch.setattr(twin.runner, "run_many", flaky)
    rows = run_chunk(points)
    assert [r["status"] for r in rows] == ["ok", "failed", "ok"]
    assert "boom on seed 1" in rows[1]["reason"]


def test_sigkill_midway_then_rerun_gives_every_scenario_once_and_the_same_numbers(tmp_path):
    args = ["--controller", "pva,ffpva,smc", "--trajectory", "2", "--seed", "0-11", "--workers", "2"]
    reference = _cli(*args, "--out", "ref", cwd=tmp_path)
    assert reference.wait(timeout=600) == 0, reference.stderr.read()

    victim = _cli(*args, "--out", "run", cwd=tmp_path, start_new_session=True)
    store = tmp_path / "run" / "results.sqlite"
    deadline = time.time() + 300
    stored = 0
    while time.time() < deadline and victim.poll() is None:
        if store.exists():
            try:
                stored = sqlite3.connect(store).execute("SELECT COUNT(*) FROM results").fetchone()[0]
            except sqlite3.OperationalError:
                stored = 0
            if stored >= 1:
                break
        time.sleep(0.05)
    os.killpg(victim.pid, signal.SIGKILL)
    victim.wait()
    assert 1 <= stored < 36, f"kill came too late to test anything ({stored} stored)"

    rerun = _cli(*args, "--out", "run", cwd=tmp_path)
    out, err = rerun.communicate(timeout=600)
    assert rerun.returncode == 0, err
    assert "already done" in out
    rows = _rows(tmp_path / "run" / "results.csv")
    assert len(rows) == 36 and len({r["key"] for r in rows}) == 36
    assert rows == _rows(tmp_path / "ref" / "results.csv")


def test_ray_backend_gives_the_same_numbers_as_local(tmp_path):
    ray = pytest.importorskip("ray")
    points = grid.expand({"controller": ["ffpva", "smc"], "trajectory": [2], "seed": [0, 1]})
    local = run_sweep(points, out=_mkdir(tmp_path / "local"), workers=1).records
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        remote = run_sweep(points, out=_mkdir(tmp_path / "ray"), backend="ray").records
    finally:
        ray.shutdown()
    assert remote == local


def test_cli_writes_tables_and_plot(tmp_path):
    proc = _cli("--controller", "ffpva", "--trajectory", "2", "--payload", "0,13.5", "--seed", "0-1",
                "--out", "s", cwd=tmp_path)
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    for name in ("results.csv", "results.parquet", "summary.csv", "rmse.png"):
        assert (tmp_path / "s" / name).stat().st_size > 0
    summary = _rows(tmp_path / "s" / "summary.csv")
    assert [float(s["payload_g"]) for s in summary] == [0.0, 13.5]
    assert all(s["runs"] == "2" for s in summary)


def test_cli_rejects_a_bad_axis_with_one_line(tmp_path):
    proc = _cli("--payload", "heavy", "--out", "x", cwd=tmp_path)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 2
    assert "heavy" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x").exists()
