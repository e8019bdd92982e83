"""The plant registry: the thesis presets as values, as-built read from its file only when asked for."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import pytest

from twin.exceptions import InvalidScenario
from twin.plants import PlantRegistry, plant
from twin.plants.as_built import CALIBRATION_FILE, as_built_plant
from twin.plants.preset import THESIS_PLANTS

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _registry(path: pathlib.Path) -> PlantRegistry:
    from twin.plants import as_built

    return PlantRegistry(THESIS_PLANTS, {"as-built": (path.exists, lambda: as_built.as_built_plant(
        as_built.calibrated_values(path)))})


def test_importing_the_cli_and_running_thesis_never_reads_the_calibration():
    """Opens of as_built.json are traced; importing the CLI and building a thesis scenario make none."""
    code = ("import builtins, io\n"
            "opened = []\n"
            "real_open = io.open\n"
            "def spy(file, *a, **k):\n"
            "    opened.append(str(file)); return real_open(file, *a, **k)\n"
            "builtins.open = io.open = spy\n"
            "import pathlib; pathlib.Path.read_text.__globals__['io'].open = spy\n"
            "import twin.cli\n"
            "from twin.sim.scenario import Scenario\n"
            "Scenario('ffpva', 1, plant='thesis')\n"
            "print(sum('as_built.json' in f for f in opened))\n"
            "from twin.plants import plant\n"
            "plant('as-built')\n"
            "print(sum('as_built.json' in f for f in opened))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True).stdout
    assert out.split() == ["0", "1"]


def test_as_built_is_listed_while_its_file_exists_and_loaded_once(tmp_path):
    path = tmp_path / "as_built.json"
    registry = _registry(path)
    assert "as-built" not in list(registry)
    with pytest.raises(KeyError):
        registry["as-built"]
    path.write_text(CALIBRATION_FILE.read_text())
    assert list(registry)[-1] == "as-built" and len(registry) == len(THESIS_PLANTS) + 1
    first = registry["as-built"]
    path.unlink()  # loaded once: later lookups do not read the file again
    assert registry["as-built"] is first
    assert first == as_built_plant()


def test_a_broken_calibration_is_a_one_line_error_and_drops_out_of_the_repr(tmp_path):
    path = tmp_path / "as_built.json"
    path.write_text(json.dumps({"fitted": {}}))
    registry = _registry(path)
    assert "as-built" in registry  # listed: the file is there
    with pytest.raises(InvalidScenario, match="no as-built plant: cannot read the as-built calibration"):
        registry["as-built"]
    assert "as-built" not in repr(registry) and "thesis-pwm" in repr(registry)


def test_registry_repr_is_the_dict_of_its_presets():
    """The sweep store's code version hashes repr(PLANTS): it must read as the plain dict it replaced."""
    from twin.plants import PLANTS

    assert repr(PLANTS) == repr({name: PLANTS[name] for name in PLANTS})


def test_unknown_plant_names_the_choices():
    with pytest.raises(InvalidScenario, match="unknown plant 'nope': choose one of thesis, "):
        plant("nope")


def test_ensemble_members_are_plants_by_name_but_not_listed():
    from twin.plants import PLANTS
    from twin.plants.as_built import ensemble_values

    members = ensemble_values()
    assert "as-built~0" in PLANTS and PLANTS["as-built~0"].params == PLANTS["as-built"].params
    last = PLANTS[f"as-built~{len(members) - 1}"]
    assert last.params.friction.stiction == members[-1]["stiction"]
    assert f"as-built~{len(members)}" not in PLANTS and "as-built~x" not in PLANTS
    assert not any(name.startswith("as-built~") for name in PLANTS)  # not listed, so not in the sweep hash
    with pytest.raises(KeyError):
        PLANTS[f"as-built~{len(members)}"]


def test_ensemble_costs_are_the_files_and_every_member_is_within_the_cost_line(tmp_path):
    """The members' recorded costs, in the members' order: the first is the fit's cost, and every one lies
    within cost + noise, the line ``twin calibrate`` drew the ensemble by; a file that records no cost for a
    member says None for it, and a file without an ensemble gives the fitted cost alone."""
    from twin.plants.as_built import calibration_cost_line, ensemble_costs, ensemble_values

    costs = ensemble_costs()
    best, noise = calibration_cost_line()
    assert len(costs) == len(ensemble_values()) and costs[0] == best
    assert all(c is not None and best <= c <= best + noise for c in costs)
    record = json.loads(CALIBRATION_FILE.read_text())
    record["ensemble"][1].pop("cost")
    record["ensemble"][2]["cost"] = "nan?"
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(record))
    assert ensemble_costs(path)[:3] == [best, None, None]
    del record["ensemble"]
    path.write_text(json.dumps(record))
    assert ensemble_costs(path) == [best]
