"""One experiment interface: every what-if and study is driven the same way by the CLI, and a new
one is a registered object, nothing else."""

from __future__ import annotations

import argparse
import os
import pathlib
import subprocess
import sys

import pytest

from twin.cli import main
from twin.exceptions import InvalidScenario
from twin.experiments.base import Experiment, Outcome
from twin.experiments.studies import STUDIES
from twin.experiments.whatifs import WHATIFS


@pytest.mark.parametrize("name,experiment", [*WHATIFS.items(), *STUDIES.items()])
def test_every_registered_experiment_implements_the_interface(name, experiment):
    assert isinstance(experiment, Experiment)
    assert experiment.name == name and experiment.help
    for method in ("run", "plot"):
        assert getattr(type(experiment), method) is not getattr(Experiment, method), f"{name} lacks {method}"


@pytest.mark.parametrize("command,registry", [("whatif", WHATIFS), ("study", STUDIES)])
def test_the_cli_offers_exactly_the_registered_experiments(command, registry, capsys):
    from twin.cli import build_parser

    group = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    offered = next(a for a in group._actions if isinstance(a, argparse._SubParsersAction)).choices
    assert list(offered) == list(registry)  # each one, no other, in the registry's order
    with pytest.raises(SystemExit):
        main([command, "--help"])
    shown = capsys.readouterr().out
    for name in registry:
        assert name in shown


def test_the_top_level_help_names_every_registered_experiment():
    """``twin --help`` summarises each group from its registry (it once named five what-ifs of ten)."""
    from twin.cli import build_parser

    commands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    summary = {choice.dest: choice.help for choice in commands._choices_actions}
    for command, registry in (("whatif", WHATIFS), ("study", STUDIES)):
        assert summary[command].split(": ", 1)[1].split(", ") == list(registry), command


class Recorder(Experiment):
    """A what-if that records the order the CLI drives it in."""

    name = "recorder"
    help = "records calls"

    def __init__(self, *, fail_check: bool = False, failed_runs: int = 0):
        self.calls: list[str] = []
        self.fail_check, self.failed_runs = fail_check, failed_runs

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--level", type=float, default=1.0)

    def check(self, args: argparse.Namespace) -> None:
        self.calls.append("check")
        if self.fail_check:
            raise InvalidScenario("--level is out of range")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        self.calls.append("run")
        assert out.is_dir()
        return Outcome(rows=[{"level": args.level, "answer": 42}], answer="forty-two", failed=self.failed_runs)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        self.calls.append("plot")
        path.write_bytes(b"png")


def test_a_new_whatif_is_one_registered_object(tmp_path, monkeypatch, capsys):
    recorder = Recorder()
    monkeypatch.setitem(WHATIFS, "recorder", recorder)
    assert main(["whatif", "recorder", "--level", "2.5", "--out", str(tmp_path / "r")]) == 0
    assert recorder.calls == ["check", "run", "plot"]
    assert (tmp_path / "r" / "recorder.csv").read_text().splitlines() == ["level,answer", "2.5,42"]
    assert (tmp_path / "r" / "recorder.txt").read_text() == "forty-two\n"
    assert (tmp_path / "r" / "recorder.png").read_bytes() == b"png"
    out = capsys.readouterr().out
    assert out.startswith("forty-two\nwrote ")


def test_bad_input_writes_nothing_and_a_failed_run_exits_1(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(WHATIFS, "recorder", Recorder(fail_check=True))
    assert main(["whatif", "recorder", "--out", str(tmp_path / "never")]) == 2
    assert not (tmp_path / "never").exists()
    assert capsys.readouterr().err.strip() == "twin: error: --level is out of range"
    monkeypatch.setitem(WHATIFS, "recorder", Recorder(failed_runs=1))
    assert main(["whatif", "recorder", "--out", str(tmp_path / "some")]) == 1
    assert (tmp_path / "some" / "recorder.csv").exists()


EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples"
SCRIPTS = sorted(p for p in EXAMPLES.glob("*.py") if '__name__ == "__main__"' in p.read_text(encoding="utf-8"))


@pytest.mark.slow  # a new interpreter per script: ~1-2 s each
@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_example_script_says_what_it_runs_on_help_instead_of_running_it(script):
    """Stop 41 made the trials' --help print their docstring; trial_smc_lead.py, written later, ran its ~50 s
    trial on --help until 2026-12-08 (a helper's run of the docs' commands found it)."""
    proc = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, timeout=30,
                          cwd=script.parents[1], env={**os.environ, "PYTHONPATH": str(script.parents[1])})
    assert proc.returncode == 0 and proc.stdout.startswith("usage:"), (proc.stdout[-500:], proc.stderr[-500:])
