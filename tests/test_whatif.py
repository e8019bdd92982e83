"""What-if studies against closed forms (Lewis loads, static lift limit, tooth force when holding)."""

from __future__ import annotations

import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import open_loop
from twin.gears import lewis_safe_load
from twin.model import Orientation
from twin.params import GearParams, JointParams
from twin.whatif import lift_study

ROOT = pathlib.Path(__file__).resolve().parents[1]
COULOMB = (-3.051e14, 1.587e13, -3.244e11, 3.294e9, -1.727e7, 4.36e4, -39.551)  # eq. 4.5.7


@pytest.mark.parametrize("spur, speed, expected", [
    (False, 0.0, 24.47), (True, 0.0, 18.78), (False, 2.79, 12.78), (True, 2.79, 9.80)])
def test_lewis_safe_loads_of_spec_section_2(spur, speed, expected):
    assert float(lewis_safe_load(GearParams(), spur=spur, pitch_line_speed=speed)) == pytest.approx(expected, abs=0.02)


def _lift_by_hand(pressure: float) -> float:
    """Torque balance at the worst angle of 80-100 deg, eq. 4.5.7 written out here (thesis plant: no stiction)."""
    p = JointParams()
    r_s, length, area = 9.525e-3 / 2, 35e-3, math.pi * 2e-3**2
    theta = np.radians(np.linspace(80, 100, 2001))
    y = np.clip(theta * r_s, 2e-3, 14.5e-3)
    coulomb = np.maximum(np.polyval(COULOMB, y), 0.0)
    mass = (pressure * area - coulomb) * r_s / (9.81 * length * np.sin(theta)) - p.masses.link_mass / 2
    return float(mass.min())


def test_static_lift_limit_matches_the_torque_balance():
    study = lift_study(pressures_kpa=[250.0, 500.0], tolerance=0.004)
    for row in study.rows:
        by_hand = _lift_by_hand(row["supply_kpa"] * 1e3) * 1e3
        assert row["lift_closed_form_g"] == pytest.approx(by_hand, rel=1e-3)
        assert row["lift_simulated_g"] == pytest.approx(by_hand, rel=0.02)


def test_too_low_a_pressure_lifts_nothing():
    row = lift_study(pressures_kpa=[100.0]).rows[0]
    assert row["lift_simulated_g"] == 0.0 and row["lift_closed_form_g"] == 0.0


def test_spur_tooth_force_when_holding_is_the_gravity_torque_over_r_spur():
    result = open_loop(0.0, trajectory=3, payload=13.5e-3, orientation=Orientation.VERTICAL)
    p = JointParams()
    theta = result.trace.angle[-1]
    torque = (13.5e-3 + p.masses.link_mass / 2) * p.gravity * p.masses.link_length * math.sin(theta)
    assert result.trace.tooth_force_spur[-1] == pytest.approx(torque / p.gears.spur_radius, rel=1e-6)


def test_whatif_cli_writes_table_plot_and_answer(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "twin", "whatif", "gear-load", "--out", "w"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    for suffix in (".csv", ".png", ".txt"):
        assert (tmp_path / "w" / f"gear-load{suffix}").stat().st_size > 0
    assert "Lewis" in proc.stdout
