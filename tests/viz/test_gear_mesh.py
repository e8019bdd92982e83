"""Closed-form checks of the viewer's gear and rack meshes (SPEC §2, 48 DP, 20°)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from viz.gear_mesh import (
    MODULE,
    PINION_FACE,
    PINION_TEETH,
    RACK_FACE,
    RACK_LENGTH,
    SPUR_FACE,
    SPUR_TEETH,
    extrude,
    gear_mesh,
    gear_profile,
    rack_mesh,
)

M = MODULE
ALPHA = math.radians(20.0)
# 7- and 18-tooth gears of SPEC §2 (base circle above root: radial foot); 48 teeth has its root above the base.
GEARS = [(PINION_TEETH, PINION_FACE), (SPUR_TEETH, SPUR_FACE), (48, 1.6e-3)]


def shoelace(xy: np.ndarray) -> float:
    x, y = np.asarray(xy, dtype=float).T
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    v = vertices.astype(float)[faces]
    return float(np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6)


def assert_closed_oriented(vertices: np.ndarray, faces: np.ndarray) -> None:
    assert vertices.dtype == np.float32 and vertices.shape[1] == 3
    assert faces.dtype in (np.int32, np.uint32) and faces.shape[1] == 3
    assert faces.min() >= 0 and faces.max() < len(vertices)
    f = faces.astype(np.int64)
    a, b = f.ravel(), f[:, [1, 2, 0]].ravel()
    n = len(vertices)
    directed, reverse = a * n + b, b * n + a
    assert np.unique(directed).size == directed.size  # every directed edge once ...
    assert np.array_equal(np.sort(directed), np.sort(reverse))  # ... and its reverse once


def pitch_crossings(outline: np.ndarray, r_p: float) -> tuple[np.ndarray, np.ndarray]:
    """Angles where the outline rises through / falls through the pitch circle (linear in radius per segment)."""
    r = np.hypot(outline[:, 0], outline[:, 1])
    theta = np.unwrap(np.arctan2(outline[:, 1], outline[:, 0]))
    r2, t2 = np.roll(r, -1), np.roll(theta, -1)
    t2[-1] += 2 * math.pi
    s = (r_p - r) / (r2 - r + 1e-300)
    angle = theta + s * (t2 - theta)
    up, down = (r < r_p) & (r2 >= r_p), (r >= r_p) & (r2 < r_p)
    return angle[up], angle[down]


@pytest.mark.parametrize("teeth", [t for t, _ in GEARS])
def test_pitch_circle_tooth_thickness_is_half_the_circular_pitch(teeth: int) -> None:
    r_p = teeth * M / 2
    up, down = pitch_crossings(gear_profile(teeth, M), r_p)
    assert up.size == down.size == teeth
    width = np.mod(down - up, 2 * math.pi)  # angular tooth width at r_p, tooth k from rise k to fall k
    np.testing.assert_allclose(r_p * width, math.pi * M / 2, rtol=0.02)
    centres = np.mod(up + width / 2 + math.pi, 2 * math.pi) - math.pi
    expected = np.mod(2 * math.pi * np.arange(teeth) / teeth + math.pi, 2 * math.pi) - math.pi
    np.testing.assert_allclose(centres, expected, atol=1e-3)  # tooth 0 on +x, evenly spaced


@pytest.mark.parametrize("teeth", [t for t, _ in GEARS])
def test_addendum_and_root_radii(teeth: int) -> None:
    outline = gear_profile(teeth, M)
    r = np.hypot(outline[:, 0], outline[:, 1])
    r_p = teeth * M / 2
    assert r.max() == pytest.approx(r_p + M, rel=1e-9)
    assert r.min() == pytest.approx(r_p - 1.25 * M, rel=1e-9)


@pytest.mark.parametrize("teeth", [t for t, _ in GEARS])
def test_outline_is_ccw_without_repeats_and_has_one_radius_peak_per_tooth(teeth: int) -> None:
    outline = gear_profile(teeth, M)
    assert np.all(np.linalg.norm(outline - np.roll(outline, -1, axis=0), axis=1) > 1e-12)
    assert shoelace(outline) > 0
    r = np.hypot(outline[:, 0], outline[:, 1])
    r = r[~np.isclose(r, np.roll(r, 1), rtol=1e-12, atol=0)]  # merge plateaus (tip lands, root arcs)
    peaks = (r > np.roll(r, 1)) & (r > np.roll(r, -1))
    assert int(peaks.sum()) == teeth


def test_pinion_has_radial_foot_below_base_circle() -> None:
    r_p = PINION_TEETH * M / 2
    r_b, r_f = r_p * math.cos(ALPHA), r_p - 1.25 * M
    assert r_f < r_b
    r = np.hypot(*gear_profile(PINION_TEETH, M).T)
    assert not np.any((r > r_f * (1 + 1e-9)) & (r < r_b * (1 - 1e-9)))  # no involute points below the base


@pytest.mark.parametrize(("teeth", "face"), GEARS)
def test_gear_mesh_is_closed_and_its_volume_is_area_times_face_width(teeth: int, face: float) -> None:
    vertices, faces = gear_mesh(teeth, M, face)
    assert_closed_oriented(vertices, faces)
    z = vertices[:, 2].astype(float)
    assert z.min() == np.float32(-face / 2) and z.max() == np.float32(face / 2)
    # The mesh is exact for its float32 vertices, so compare with the float32-rounded outline and face width.
    outline32 = gear_profile(teeth, M).astype(np.float32).astype(float)
    expected = shoelace(outline32) * (z.max() - z.min())
    volume = signed_volume(vertices, faces)
    assert volume > 0
    assert volume == pytest.approx(expected, rel=1e-9)
    assert volume == pytest.approx(shoelace(gear_profile(teeth, M)) * face, rel=1e-6)


def test_extrude_with_centre_hole_is_closed_and_removes_the_bore() -> None:
    outline = gear_profile(SPUR_TEETH, M)
    r_h = 1e-3
    vertices, faces = extrude(outline, 0.0, 1e-3, centre_hole=r_h)
    assert_closed_oriented(vertices, faces)
    bore = r_h * outline / np.hypot(*outline.T)[:, None]
    expected = (shoelace(outline) - shoelace(bore)) * 1e-3
    assert signed_volume(vertices, faces) == pytest.approx(expected, rel=1e-6)
    assert signed_volume(*extrude(outline, 0.0, 1e-3, centre_hole=True)) > 0


def test_extrude_rejects_clockwise_outline() -> None:
    with pytest.raises(ValueError):
        extrude(gear_profile(SPUR_TEETH, M)[::-1], 0.0, 1e-3)


BAR = 2e-3


def test_rack_pitch_and_pitch_line_thickness() -> None:
    vertices, _ = rack_mesh(RACK_LENGTH, M, RACK_FACE, BAR)
    v = vertices.astype(float)
    p = math.pi * M
    assert v[:, 1].max() == pytest.approx(M, rel=1e-6)
    assert v[:, 1].min() == pytest.approx(-1.25 * M - BAR, rel=1e-6)
    assert v[:, 0].min() == pytest.approx(-RACK_LENGTH / 2, rel=1e-6)
    assert v[:, 0].max() == pytest.approx(RACK_LENGTH / 2, rel=1e-6)
    tip_x = np.sort(v[np.isclose(v[:, 1], M, rtol=1e-6), 0])
    groups = np.split(tip_x, np.flatnonzero(np.diff(tip_x) > M) + 1)
    centres = np.array([(g.min() + g.max()) / 2 for g in groups])
    assert len(centres) == int(RACK_LENGTH // p) == 14
    np.testing.assert_allclose(np.diff(centres), p, rtol=1e-5)
    assert centres.mean() == pytest.approx(0.0, abs=1e-9)
    # Thickness at the pitch line y = 0, interpolated along the flank from root (y = -1.25 m) to tip (y = m).
    c = centres[0]
    root_x = np.sort(v[np.isclose(v[:, 1], -1.25 * M, rtol=1e-6) & (np.abs(v[:, 0] - c) < p / 2), 0])
    w_tip, w_root = (groups[0].max() - groups[0].min()) / 2, (root_x.max() - root_x.min()) / 2
    assert 2 * (w_root + (w_tip - w_root) * 1.25 / 2.25) == pytest.approx(p / 2, rel=1e-5)
    assert w_root - w_tip == pytest.approx(2.25 * M * math.tan(ALPHA), rel=1e-5)  # flanks at the pressure angle


def test_rack_is_closed_and_volume_is_sum_of_pieces() -> None:
    vertices, faces = rack_mesh(RACK_LENGTH, M, RACK_FACE, BAR)
    assert_closed_oriented(vertices, faces)
    p, n = math.pi * M, int(RACK_LENGTH // (math.pi * M))
    box = RACK_LENGTH * BAR * RACK_FACE
    tooth = 2.25 * M * (p / 2 + 0.25 * M * math.tan(ALPHA)) * RACK_FACE  # trapezoid: height x mid-height width
    assert signed_volume(vertices, faces) == pytest.approx(box + n * tooth, rel=1e-6)
