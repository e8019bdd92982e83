"""Safe gear tooth loads (Lewis, eq. 3.5.4), in SI.

    W = S F Y / P_d x 600 / (600 + V)        (V in ft/min)
      = S F Y / P_d x 3.048 / (3.048 + v)    (v, the pitch-line speed, in m/s)

Static: 24.47 N for the pinion, 18.78 N for the spur; at 2.79 m/s 12.78 N and
9.80 N (SPEC §2). The pitch-line speed is the rack speed: every mesh of the
train shares it.
"""

from __future__ import annotations

import numpy as np

from twin.physics.params import GearParams

VELOCITY_FACTOR_SPEED = 600 * 0.3048 / 60  # m/s, the "600 ft/min" of the Barth factor


def lewis_safe_load(gears: GearParams, *, spur: bool, pitch_line_speed) -> np.ndarray:
    """Safe tooth load in N of the spur (``spur=True``) or the pinion, at speed(s) in m/s."""
    face = gears.spur_face_width if spur else gears.pinion_face_width
    form = gears.spur_form_factor if spur else gears.pinion_form_factor
    static = gears.safe_bending_stress * face * form / gears.diametral_pitch_si
    speed = np.abs(np.asarray(pitch_line_speed, dtype=float))
    return static * VELOCITY_FACTOR_SPEED / (VELOCITY_FACTOR_SPEED + speed)
