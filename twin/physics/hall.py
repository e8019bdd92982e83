"""The as-built Hall reading: eq. 4.2.1 applied to the sensor's true volts (SPEC §5).

The sensor's real volts-angle curve V(theta) is the piecewise-linear curve
through the measured calibration points (linear extrapolation beyond the first
and last pair); the DAQ turns volts into degrees with the quadratic fit

    theta_fit(x) = a x^2 + b x + c     (deg, x in V; eq. 4.2.1)

so the reading is off by the fit's residual

    e(theta) = theta_fit(V(theta)) - theta

(+2.70 deg at 94 deg, up to ~7 deg near 0 deg). Angles are in rad and rack
positions in m (theta = y / r_s, eq. 3.4.1); degrees and volts appear only
where eq. 4.2.1 needs them.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from twin.exceptions import InvalidParameter
from twin.physics.params import HallParams


class _Curve(NamedTuple):
    """V(theta): calibration knots sorted by angle plus the two end slopes."""

    angles: np.ndarray  # deg, (K,) increasing
    volts: np.ndarray  # V, (K,)
    slope_low: float  # V/deg, through the first pair
    slope_high: float  # V/deg, through the last pair


def _curve(params: HallParams) -> _Curve:
    points = np.array(params.points, dtype=float).reshape(-1, 2)
    if len(points) < 2:
        raise InvalidParameter(f"Hall calibration needs at least 2 points, got {len(points)}")
    angles, volts = points[np.argsort(points[:, 0], kind="stable")].T
    if np.any(np.diff(angles) <= 0):
        raise InvalidParameter(f"Hall calibration angles must be distinct, got {angles.tolist()}")
    slope_low = (volts[1] - volts[0]) / (angles[1] - angles[0])
    slope_high = (volts[-1] - volts[-2]) / (angles[-1] - angles[-2])
    return _Curve(angles, volts, float(slope_low), float(slope_high))


def _volts(curve: _Curve, angle_deg: np.ndarray) -> np.ndarray:
    # np.interp holds the end values; the two end terms add the linear extrapolation.
    below = np.minimum(angle_deg - curve.angles[0], 0.0)
    above = np.maximum(angle_deg - curve.angles[-1], 0.0)
    return np.interp(angle_deg, curve.angles, curve.volts) + curve.slope_low * below + curve.slope_high * above


def true_volts(params: HallParams, angle_deg: np.ndarray) -> np.ndarray:
    """The sensor's real output V(theta) in V for true output angles ``angle_deg`` (deg, any shape)."""
    return _volts(_curve(params), np.asarray(angle_deg, dtype=float))


def fit_degrees(params: HallParams, volts: np.ndarray) -> np.ndarray:
    """Eq. 4.2.1: the DAQ's angle a x^2 + b x + c in deg for sensor volts ``volts`` (V, any shape)."""
    return np.polyval(params.fit, np.asarray(volts, dtype=float))


def reading_error(params: HallParams, angle_rad: np.ndarray) -> np.ndarray:
    """e(theta) = theta_fit(V(theta)) - theta in rad for true angles ``angle_rad`` (rad, any shape).

    Exactly zero everywhere when ``params.calibration_error`` is False.
    """
    angle_rad = np.asarray(angle_rad, dtype=float)
    if not params.calibration_error:
        return np.zeros_like(angle_rad)
    angle_deg = np.degrees(angle_rad)
    return np.radians(fit_degrees(params, true_volts(params, angle_deg)) - angle_deg)


class HallReading:
    """Rack position the Hall sensor reports, y_read = r_s (theta + e(theta)) with theta = y / r_s.

    The calibration curve is sorted once at construction; each call is one
    ``np.interp`` and one quadratic, exact (no tabulation error). With
    ``calibration_error`` False the call returns its argument itself.
    """

    def __init__(self, params: HallParams, spur_radius: float) -> None:
        if not (spur_radius > 0 and math.isfinite(spur_radius)):
            raise InvalidParameter(f"spur_radius must be positive and finite, got {spur_radius!r}")
        self._enabled = params.calibration_error
        self._curve = _curve(params)
        self._a, self._b, self._c = (float(k) for k in params.fit)  # eq. 4.2.1
        self._deg_per_m = math.degrees(1.0) / spur_radius  # deg of output per m of rack
        self._m_per_deg = spur_radius * math.radians(1.0)

    def __call__(self, y: np.ndarray) -> np.ndarray:
        """Reported rack positions (m) for true rack positions ``y`` (m, any shape)."""
        if not self._enabled:
            return y
        angle_deg = np.asarray(y, dtype=float) * self._deg_per_m
        x = _volts(self._curve, angle_deg)  # V
        return ((self._a * x + self._b) * x + self._c) * self._m_per_deg

    def true_position(self, reported: np.ndarray) -> np.ndarray:
        """The true rack positions (m) whose reading is ``reported`` (m): the reading rises monotonically
        with the angle over -40..220 deg, so it is inverted on a 0.01 deg table (error < 1e-4 deg)."""
        if not self._enabled:
            return reported
        true = np.arange(-40.0, 220.0, 0.01) * self._m_per_deg
        return np.interp(reported, self(true), true)
