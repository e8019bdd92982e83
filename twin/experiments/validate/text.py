"""Small pieces of the report's wording: numbers, lists, cell names, and a fitted parameter's name, value and unit
(:data:`PARAMETER_TEXT`) across the ensemble's members."""

from __future__ import annotations

import math
from collections.abc import Sequence

from twin.experiments import calibrate
from twin.experiments.validate.common import PARAMETER_TEXT
from twin.sim.scenario import CONTROLLER_LABELS


def _with_unit(text: str, unit: str) -> str:
    return f"{text} {unit}" if unit else text


def _member_text(member: dict, names: Sequence[str]) -> str:
    """``member``'s values of ``names``, as the report writes them ("breakaway 1.21 N, load friction ...")."""
    return ", ".join(f"{PARAMETER_TEXT[n][0]} {_with_unit(PARAMETER_TEXT[n][1](member[n]), PARAMETER_TEXT[n][2])}"
                     for n in names)


def _profiled(members: Sequence[dict]) -> list[str]:
    """The parameters to show across ``members``: the profiled ones every member carries, in the fit's order,
    then any other they differ in (a simplex step may have moved it)."""
    carried = [n for n in PARAMETER_TEXT if all(n in m for m in members)]
    return ([n for n in calibrate.PROFILED if n in carried]
            + [n for n in carried if n not in calibrate.PROFILED and len({m[n] for m in members}) > 1])


def _and_list(items: Sequence[str]) -> str:
    """"T1", "T1 and T2", "T1, T2 and T3"."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + f" and {items[-1]}"


def _numbers_text(members: Sequence[int]) -> str:
    """"member 1", "members 0 and 3", "members 0, 2 and 5": ensemble members by their numbers (from 0, as the
    members' table and ``prediction_members.csv`` number them)."""
    return ("member " if len(members) == 1 else "members ") + _and_list([str(k) for k in members])


def _which_members(count: int, right: Sequence[int]) -> str:
    """" (members 2 and 4)" or " (all but member 3)", the shorter, for ``right`` among ``count`` members; "" when
    they are none or all."""
    if not 0 < len(right) < count:
        return ""
    others = [k for k in range(count) if k not in right]
    return f" ({_numbers_text(right)})" if len(right) <= len(others) else f" (all but {_numbers_text(others)})"


def _fmt(value, spec=".2f") -> str:
    return "–" if value is None or (isinstance(value, float) and math.isnan(value)) else format(value, spec)


def _loaded(r: dict) -> bool:
    """Whether a cell carries a payload or stands on its side (named after its trajectory), or is §8's flat 0 g."""
    return bool(r["payload_g"]) or r["orientation"] == "vertical"


def _cell_name(r: dict) -> str:
    return (f"{CONTROLLER_LABELS[r['controller']]} T{r['trajectory']}"
            + (f" {r['payload_g']:g} g {r['orientation']}" if _loaded(r) else ""))


def _tick(r: dict) -> str:
    """A cell's short name under a figure's bar: controller, trajectory, and payload and orientation if any."""
    return (f"{r['controller']}\nT{r['trajectory']}"
            + (f"\n{r['payload_g']:g} g {r['orientation'][0].upper()}" if _loaded(r) else ""))


def _percent_span(fractions: Sequence[float]) -> str:
    low, high = min(fractions) * 100, max(fractions) * 100
    return f"{low:.0f} %" if round(low) == round(high) else f"{low:.0f}-{high:.0f} %"


def _effect_name(r: dict) -> str:
    return f"{r['payload_g']:g} g {'H' if r['orientation'] == 'horizontal' else 'V'}"


def _band_ends_text(members: int) -> str:
    """How the 10-90 % band's ends sit among ``members`` means (numpy's linear percentiles)."""
    if members < 2:
        return "one member: no spread"
    if round((members - 1) * 0.1, 9).is_integer():
        k = round((members - 1) * 0.1)
        nth = {1: "second", 2: "third", 3: "fourth"}.get(k, f"{k + 1}th")
        return f"with {members} members its ends are the {nth}-lowest and the {nth}-highest member's means"
    return f"with {members} members its ends are interpolated between neighbouring members"


def _times(ratio) -> str:
    """A twin / measured ratio as the report writes it (x1.31), or "failed" for a mean that is not a number."""
    return "failed" if ratio is None or not math.isfinite(ratio) else f"x{ratio:.2f}"
