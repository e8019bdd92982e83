"""What the trial-script tests share (tests/experiments/test_trials_*.py): the checkout's root, a loader for a script
in examples/ (not installed), a doc page's words, and a stand-in for calibrate.Evaluator."""

from __future__ import annotations

import importlib.util
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]


def load_trial(name: str):
    """examples/NAME.py as a module."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def doc_text(name: str) -> str:
    """docs/NAME with its line breaks and runs of spaces as single spaces, as the trial tests find quotes in it."""
    return " ".join((ROOT / "docs" / name).read_text(encoding="utf-8").split())


class StubEvaluator:
    """In place of calibrate.Evaluator where a test supplies the costs: runs nothing; its cells are the values."""

    def __init__(self, **kwargs):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def cells(self, values, **kwargs):
        return values
