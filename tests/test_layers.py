"""The import rule: every module imports only from its own layer or the layers below it,
and no two modules import each other, directly or round a loop (docs/layout.md).

Layers, lowest first::

    twin.exceptions < twin.physics < twin.plants < twin.sim < controllers < twin.envs
        < viz < twin.batch < twin.experiments < twin.cli

Imports inside functions count: a lazy import that points up is still an upward
dependency. The rule is read from the source (``ast``), so the test needs no import.
"""

from __future__ import annotations

import ast
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGES = ("twin", "controllers", "viz", "models")
LAYERS = ("twin.exceptions", "twin.physics", "twin.plants", "twin.sim", "controllers", "twin.envs", "viz",
          "twin.batch", "twin.experiments", "twin.cli")
TOP = len(LAYERS)  # twin.__main__ and the package roots' entry points


def layer(module: str) -> int:
    """Rank of ``module`` in LAYERS (a module is in the layer whose name prefixes it)."""
    if module in ("twin", "models") or module.startswith("models."):
        return 0  # empty package roots; models/ holds only data
    if module == "twin.__main__":
        return TOP
    for rank in range(len(LAYERS) - 1, -1, -1):
        name = LAYERS[rank]
        if module == name or module.startswith(name + "."):
            return rank
    raise AssertionError(f"{module} is in no layer: add it to LAYERS in {__file__}")


def module_name(path: pathlib.Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports(source: str, module: str, *, is_package: bool = False) -> set[str]:
    """Every project module ``source`` imports, at any depth (``from a import b`` counts b when b is a module)."""
    found = set()
    base = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = base.split(".")
                anchor = anchor[:len(anchor) - node.level + 1]
                target = ".".join(anchor + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            found.add(target)
            found.update(f"{target}.{alias.name}" for alias in node.names)
    return {name for name in found if name.split(".")[0] in PACKAGES}


def project_modules() -> dict[str, pathlib.Path]:
    modules = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            modules[module_name(path)] = path
    return modules


def graph() -> dict[str, set[str]]:
    """module -> the project modules it imports (names that are not modules, e.g. a class, are dropped)."""
    modules = project_modules()
    edges = {}
    for name, path in modules.items():
        named = imports(path.read_text(), name, is_package=path.name == "__init__.py")
        edges[name] = {n for n in named if n in modules and n != name}
    return edges


def upward(edges: dict[str, set[str]]) -> list[str]:
    return sorted(f"{a} (layer {LAYERS[min(layer(a), TOP - 1)]}) imports {b} (layer {LAYERS[layer(b)]})"
                  for a, targets in edges.items() for b in targets if layer(b) > layer(a))


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found, counter = {}, {}, [], set(), [], [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def test_every_module_is_in_a_layer():
    for name in project_modules():
        layer(name)


def test_imports_point_down_only():
    assert upward(graph()) == []


def test_no_import_cycles():
    assert cycles(graph()) == []


def test_a_physics_module_importing_viz_is_caught():
    edges = graph()
    edges["twin.physics.valves"] = edges["twin.physics.valves"] | {"viz.plots"}
    assert upward(edges) == ["twin.physics.valves (layer twin.physics) imports viz.plots (layer viz)"]


@pytest.mark.parametrize("source", ["import viz.plots", "from viz import plots", "from viz.plots import plot_run",
                                    "def f():\n    from viz.plots import plot_run\n"])
def test_every_import_form_is_read(source):
    assert "viz.plots" in imports(source, "twin.physics.valves")


def test_relative_imports_are_resolved():
    assert "twin.physics.params" in imports("from .params import JointParams", "twin.physics.valves")
    assert "twin.sim" in imports("from ..sim import tick", "twin.physics.valves")


def test_a_cycle_is_caught():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_the_validate_package_rooms_import_only_the_rooms_its_docstring_lists_before_them():
    """``twin/experiments/validate/__init__.py`` lists its modules in a table, each said to import only those
    before it; the table must name every module of the package, and the imports must keep to that order."""
    package = "twin.experiments.validate"
    init = ast.get_docstring(ast.parse((ROOT / "twin/experiments/validate/__init__.py").read_text()))
    rooms = [m.group(1) for line in init.splitlines() if (m := re.match(r"``(\w+)``\s", line))]
    modules = {name for name in project_modules() if name.startswith(package + ".")}
    assert sorted(f"{package}.{room}" for room in rooms) == sorted(modules)
    edges = graph()
    for k, room in enumerate(rooms):
        siblings = {name.rpartition(".")[2] for name in edges[f"{package}.{room}"] if name.startswith(package + ".")}
        assert siblings <= set(rooms[:k]), f"{room} imports {sorted(siblings - set(rooms[:k]))}, listed after it"
