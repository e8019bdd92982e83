"""The docs pages that quote numbers run on the committed as-built preset name the preset they were run on.

A refit, a valve refit or a changed assumption about the plant changes
:func:`twin.plants.as_built.preset_digest` (every parameter of the as-built plant and its ensemble; not the
controllers' gains, the trajectories or the code, which it does not see); this test then fails until each page below has been brought up to the new preset and its stamp changed. The stamp is a
promise, not a proof: the slow test of ``twin validate`` checks docs/validation.md, the README's results
table and docs/prediction.md's current table against a fresh run, number for number; the other numbers of
these pages only the person who re-runs them can check.
"""

from __future__ import annotations

import json
import pathlib
import re

import pytest

from twin.plants import as_built

ROOT = pathlib.Path(__file__).resolve().parents[1]
STAMPED = ("README.md", "docs/as-built.md", "docs/prediction.md", "docs/studies-and-whatifs.md")
STAMP = re.compile(r"<!-- as-built preset ([0-9a-f]{12}): ")


def test_each_page_that_quotes_the_committed_preset_names_it():
    digest = as_built.preset_digest()
    for page in STAMPED:
        found = STAMP.findall((ROOT / page).read_text(encoding="utf-8"))
        assert found == [digest], (f"{page} says it was run on as-built preset {found or 'none'}, the committed one is "
                                   f"{digest}: re-run what it quotes, then change its stamp")


def test_the_digest_follows_every_value_of_the_calibration_and_nothing_else(tmp_path):
    record = json.loads(as_built.CALIBRATION_FILE.read_text(encoding="utf-8"))
    same = tmp_path / "same.json"
    same.write_text(json.dumps({**record, "wall_time_s": 1.0, "made_by": "someone else"}), encoding="utf-8")
    committed = as_built.preset_digest()
    assert as_built.preset_digest(same) == committed
    for name in record["fitted"]:
        for where in ("fitted", "ensemble"):
            moved = json.loads(json.dumps(record))
            values = moved["fitted"] if where == "fitted" else moved["ensemble"][-1]["values"]
            values[name] *= 1.001
            path = tmp_path / f"{where}-{name}.json"
            path.write_text(json.dumps(moved), encoding="utf-8")
            assert as_built.preset_digest(path) != committed, (where, name)


def test_every_import_in_the_docs_python_blocks_resolves():
    """A page's example starts with its imports; each one, run alone, imports (``from twin import env`` in
    docs/environment.md did not, after the package was split into layers)."""
    import importlib
    import importlib.util

    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    imports = [(page.name, line.strip()) for page in pages
               for block in re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
               for line in block.splitlines() if re.match(r"\s*(from \S+ )?import ", line)]
    assert len(imports) >= 7  # the README's, commands.md's and environment.md's
    for page, line in imports:
        match = re.match(r"from (\S+) import (.+)", line)
        if match is None:
            importlib.import_module(line.split()[1])
            continue
        module = importlib.import_module(match[1])
        for name in (n.split(" as ")[0].strip() for n in match[2].split(",")):
            assert hasattr(module, name) or importlib.util.find_spec(f"{match[1]}.{name}"), f"{page}: {line}"


@pytest.mark.slow  # the blocks run the twin: an as-built run, a batch of 20 and an episode (~10 s)
def test_every_python_block_in_the_docs_runs_as_written():
    """Each page's example runs as printed, in a namespace of its own, not only its imports: docs/environment.md's
    stepped with a ``duty_percent`` it never set until 2026-12-08 (a helper's run of the docs' commands)."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    blocks = [(page.name, block) for page in pages
              for block in re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)]
    assert len(blocks) >= 3  # the README's, commands.md's and environment.md's
    for name, block in blocks:
        exec(compile(block, name, "exec"), {"__name__": f"docs:{name}"})  # noqa: S102 - the docs' own code
