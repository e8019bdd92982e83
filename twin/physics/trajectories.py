"""The four test trajectories of §7, as rack position references.

Angles are the output angle theta = y / r_s. Start angles and holds that the
thesis does not state are chosen inside the friction fit's range
(y = 2 - 14.5 mm, i.e. 24 - 174 deg) where SPEC allows and written down here:

==  =======  =========  ==========================================================
#   start    duration   shape
==  =======  =========  ==========================================================
T1  30 deg   3.0 s      +120 deg cycloid in 1 s to 150 deg, hold 2 s
T2  30 deg   1.0 s      ramp at 10 mm/s rack speed for 1 s (10 mm, 120.3 deg, to 150.3 deg);
                        like T3 it ends moving, so it has no steady error: SPEC §7 gives
                        T1 a hold and T4 its rests but T2 none, and the thesis reports
                        steady errors for T1 and T4 only
T3  80 deg   4.0 s      80 + 60 sin(pi t) deg: 0.5 Hz, 20 - 140 deg as SPEC §7 says
                        (so it dips below the fit), two periods, starting mid-stroke
                        at full speed (the thesis reports its largest error at the
                        start of T3); it ends moving, so it has no steady error
T4  30 deg   6.0 s      +120 (1 s), rest 1, -120 (1 s), rest 0.5, +60 (0.5 s),
                        rest 0.5, -60 (0.5 s), rest 1: 30, 150, 30, 90, 30 deg
==  =======  =========  ==========================================================

The cycloidal rise (eqs. 5.2.5 - 5.2.7) of height H over T:
``y = H (t/T - sin(2 pi t/T) / (2 pi))``, so ``a = A_max sin(2 pi t/T)`` with
``A_max = 2 pi H / T^2``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from twin.exceptions import InvalidScenario

RAMP_SPEED = 10e-3  # m/s, T2's rack speed (§7)


@dataclasses.dataclass(frozen=True)
class Reference:
    """Desired rack motion sampled at ticks; arrays are (T,)."""

    position: np.ndarray  # m
    velocity: np.ndarray  # m/s
    acceleration: np.ndarray  # m/s^2


@dataclasses.dataclass(frozen=True)
class Segment:
    kind: str  # "cycloid" or "rest" or "ramp" or "sine"
    duration: float  # s
    delta: float = 0.0  # rad of output angle (cycloid, ramp); the amplitude of a sine

    @property
    def change(self) -> float:
        """rad the segment moves the angle from its start to its end (a sine: where its last period stops)."""
        if self.kind == "sine":
            return self.delta * math.sin(math.pi * self.duration)
        return self.delta if self.kind in ("cycloid", "ramp") else 0.0


@dataclasses.dataclass(frozen=True)
class Trajectory:
    number: int
    start: float  # rad
    segments: tuple[Segment, ...]

    @property
    def duration(self) -> float:
        return sum(s.duration for s in self.segments)  # s

    @property
    def end(self) -> float:
        """rad, where the trajectory ends (and holds)."""
        level = self.start
        for seg in self.segments:
            level = level + seg.change
        return level

    @property
    def ends_at_rest(self) -> bool:
        return self.segments[-1].kind == "rest"

    def rest_ends(self) -> list[float]:
        """Times (s) at which each rest segment ends: where the thesis reads its steady errors."""
        ends, clock = [], 0.0
        for seg in self.segments:
            clock += seg.duration
            if seg.kind == "rest":
                ends.append(clock)
        return ends

    def sample(self, t: np.ndarray, spur_radius: float) -> Reference:
        """The reference at times ``t`` (s), as rack motion (y = theta r_s)."""
        theta = np.full_like(t, self.start)
        omega = np.zeros_like(t)
        alpha = np.zeros_like(t)
        begin, level = 0.0, self.start
        for seg in self.segments:
            local = t - begin
            inside = (local >= 0) & (local < seg.duration)
            after = local >= seg.duration
            if seg.kind == "cycloid":
                tau = 2.0 * math.pi / seg.duration
                theta = np.where(inside, level + seg.delta * (local / seg.duration - np.sin(tau * local) / (2 * math.pi)), theta)
                omega = np.where(inside, seg.delta / seg.duration * (1.0 - np.cos(tau * local)), omega)
                alpha = np.where(inside, seg.delta / seg.duration * tau * np.sin(tau * local), alpha)
            elif seg.kind == "ramp":
                rate = seg.delta / seg.duration
                theta = np.where(inside, level + rate * local, theta)
                omega = np.where(inside, rate, omega)
            elif seg.kind == "sine":  # amplitude in delta, 0.5 Hz, about the start level
                w = math.pi
                theta = np.where(inside, level + seg.delta * np.sin(w * local), theta)
                omega = np.where(inside, seg.delta * w * np.cos(w * local), omega)
                alpha = np.where(inside, -seg.delta * w * w * np.sin(w * local), alpha)
            end_level = level + seg.change
            theta = np.where(after, end_level, theta)
            omega = np.where(after, 0.0, omega)
            alpha = np.where(after, 0.0, alpha)
            begin, level = begin + seg.duration, end_level
        return Reference(position=theta * spur_radius, velocity=omega * spur_radius,
                         acceleration=alpha * spur_radius)


def _deg(x: float) -> float:
    return math.radians(x)


START = math.radians(30.0)  # rad, T1, T2 and T4: inside the friction fit (y = 2.49 mm)


RAMP_TIME = 1.0  # s, T2's length: 10 mm of rack travel, a whole number of ticks


def _t2(spur_radius: float) -> Trajectory:
    return Trajectory(2, START, (Segment("ramp", RAMP_TIME, RAMP_SPEED * RAMP_TIME / spur_radius),))


def trajectory(number: int, *, spur_radius: float) -> Trajectory:
    """T1..T4 of §7."""
    if number == 1:
        return Trajectory(1, START, (Segment("cycloid", 1.0, _deg(120.0)), Segment("rest", 2.0)))
    if number == 2:
        return _t2(spur_radius)
    if number == 3:
        return Trajectory(3, _deg(80.0), (Segment("sine", 4.0, _deg(60.0)),))
    if number == 4:
        return Trajectory(4, START, (
            Segment("cycloid", 1.0, _deg(120.0)), Segment("rest", 1.0),
            Segment("cycloid", 1.0, _deg(-120.0)), Segment("rest", 0.5),
            Segment("cycloid", 0.5, _deg(60.0)), Segment("rest", 0.5),
            Segment("cycloid", 0.5, _deg(-60.0)), Segment("rest", 1.0),
        ))
    raise InvalidScenario(f"unknown trajectory {number!r}: choose 1, 2, 3 or 4")
