"""Triangle meshes of the joint's spur gears and racks for the meshcat viewer (pure numpy, SI metres).

Source: SPEC §2 — 48 diametral pitch (module m = 25.4 mm / 48), 20° pressure angle; pinion 7 teeth (pitch
diameter 7/48 in, face 3.2 mm), spur gear 18 teeth (18/48 in, face 1.6 mm), racks 24 mm long with face 1.6 mm
and teeth of addendum m, dedendum 1.25 m on a bar. Meshes are (vertices float32 (N,3), faces int32 (M,3)) for
meshcat.geometry.TriangularMeshGeometry; a mesh may be a union of closed, outward-oriented pieces.
"""

from __future__ import annotations

import math

import numpy as np

MODULE = 25.4e-3 / 48  # m (48 DP)
PINION_TEETH, PINION_FACE = 7, 3.2e-3  # -, m
SPUR_TEETH, SPUR_FACE = 18, 1.6e-3  # -, m
RACK_LENGTH, RACK_FACE = 24e-3, 1.6e-3  # m, m
ADDENDUM, DEDENDUM = 1.0, 1.25  # in modules

Mesh = tuple[np.ndarray, np.ndarray]


def _inv(phi: np.ndarray | float) -> np.ndarray | float:
    return np.tan(phi) - phi  # involute function


def gear_profile(teeth: int, module: float, pressure_angle_deg: float = 20.0, points_per_flank: int = 8) -> np.ndarray:
    """Closed counter-clockwise (K,2) outline of a spur gear, tooth 0 centred on +x; no repeated end point."""
    if teeth < 3 or module <= 0 or points_per_flank < 2:
        raise ValueError("need teeth >= 3, module > 0, points_per_flank >= 2")
    alpha = math.radians(pressure_angle_deg)
    r_p = teeth * module / 2
    r_a, r_f, r_b = r_p + ADDENDUM * module, r_p - DEDENDUM * module, r_p * math.cos(alpha)
    if r_f <= 0:
        raise ValueError("root circle radius must be positive")
    # The involute exists only outside the base circle. When the base circle is above the root circle (both gears
    # of SPEC §2) the flank is continued by a radial line down to the root; undercut is ignored.
    radial = r_f < r_b
    r = np.linspace(max(r_b, r_f), r_a, points_per_flank)
    # Half angular thickness at radius r; at r_p it is pi/(2N), i.e. a tooth thickness of half the circular pitch.
    half = math.pi / (2 * teeth) + _inv(alpha) - _inv(np.arccos(np.clip(r_b / r, -1.0, 1.0)))
    if half[-1] <= 0:
        raise ValueError("teeth are pointed below the addendum circle")
    step = 2 * math.pi / teeth
    tip = np.linspace(-half[-1], half[-1], 5)[1:-1]  # interior points of the tip land
    root = np.linspace(half[0], step - half[0], max(points_per_flank // 2, 2) + 2)[1:-1]
    foot_r, foot_a = ([r_f], [half[0]]) if radial else ([], [])
    rad = np.concatenate([foot_r, r, np.full(tip.size, r_a), r[::-1], foot_r, np.full(root.size, r_f)])
    ang = np.concatenate([-np.asarray(foot_a), -half, tip, half[::-1], foot_a, root])
    ang = (ang[None, :] + step * np.arange(teeth)[:, None]).ravel()
    rad = np.tile(rad, teeth)
    return np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])


def _prism(outline: np.ndarray, z0: float, z1: float, centre_hole: bool | float, centre: np.ndarray) -> Mesh:
    """float64 prism; caps fanned from `centre` (or an annulus to a bore around it); outward normals."""
    xy = np.asarray(outline, dtype=float) - centre
    k = len(xy)
    if xy.ndim != 2 or xy.shape[1] != 2 or k < 3 or not z1 > z0:
        raise ValueError("outline must be (K>=3, 2) and z1 > z0")
    i = np.arange(k)
    j = (i + 1) % k
    radius = np.hypot(xy[:, 0], xy[:, 1])
    if np.any(xy[i, 0] * xy[j, 1] - xy[i, 1] * xy[j, 0] < -1e-12 * radius[i] * radius[j]):  # radial: ~0
        raise ValueError("outline must be counter-clockwise and star-shaped about the centre")
    ring = [np.column_stack([xy, np.full(k, z)]) for z in (z0, z1)]
    faces = [np.column_stack([i, j, j + k]), np.column_stack([i, j + k, i + k])]  # side walls
    if not centre_hole:
        ring.append(np.array([[0.0, 0.0, z0], [0.0, 0.0, z1]]))
        cb, ct = np.full(k, 2 * k), np.full(k, 2 * k + 1)
        faces += [np.column_stack([cb, j, i]), np.column_stack([ct, i + k, j + k])]
    else:
        r_h = 0.5 * radius.min() if centre_hole is True else float(centre_hole)
        if not 0 < r_h < radius.min():
            raise ValueError("bore radius must be positive and inside the outline")
        bore = r_h * xy / radius[:, None]  # bore vertices at the outline's angles (radial-line pairs coincide)
        ring += [np.column_stack([bore, np.full(k, z)]) for z in (z0, z1)]
        hb, ht = i + 2 * k, i + 3 * k
        faces += [np.column_stack(f) for f in (
            (i, j + 2 * k, j), (i, hb, j + 2 * k),  # bottom annulus (normal -z)
            (i + k, j + k, j + 3 * k), (i + k, j + 3 * k, ht),  # top annulus (normal +z)
            (hb, j + 3 * k, j + 2 * k), (hb, ht, j + 3 * k))]  # bore wall (normal towards the axis)
    vertices = np.concatenate(ring)
    vertices[:, :2] += centre
    return vertices, np.concatenate(faces)


def _pack(pieces: list[Mesh]) -> Mesh:
    offsets = np.cumsum([0] + [len(v) for v, _ in pieces[:-1]])
    vertices = np.concatenate([v for v, _ in pieces]).astype(np.float32)
    faces = np.concatenate([f + o for (_, f), o in zip(pieces, offsets, strict=True)]).astype(np.int32)
    return vertices, faces


def extrude(outline: np.ndarray, z0: float, z1: float, centre_hole: bool | float = False) -> Mesh:
    """Closed prism z0..z1 of a counter-clockwise outline star-shaped about the origin.

    Caps are fans from a centre vertex; centre_hole=True bores a hole of half the innermost radius, a float bores
    one of that radius (m). Fan/bore triangles next to radial segments of the outline are degenerate (zero area).
    """
    return _pack([_prism(outline, z0, z1, centre_hole, np.zeros(2))])


def gear_mesh(teeth: int, module: float, face_width: float, pressure_angle_deg: float = 20.0) -> Mesh:
    """Spur gear on the z axis, z in [-face_width/2, face_width/2], tooth 0 centred on +x."""
    return extrude(gear_profile(teeth, module, pressure_angle_deg), -face_width / 2, face_width / 2)


def rack_mesh(length: float, module: float, face_width: float, bar_height: float,
              pressure_angle_deg: float = 20.0) -> Mesh:
    """Rack along x (centred on x = 0), teeth towards +y, pitch line y = 0, on a bar of height bar_height.

    Union of closed prisms: one box for the bar and one trapezoid per tooth (floor(length / pitch) teeth).
    """
    p, tan_a = math.pi * module, math.tan(math.radians(pressure_angle_deg))
    y_tip, y_root = ADDENDUM * module, -DEDENDUM * module
    w_tip, w_root = p / 4 - y_tip * tan_a, p / 4 - y_root * tan_a  # half widths; p/4 at the pitch line
    n = int(length // p)
    if n < 1 or w_tip <= 0 or bar_height <= 0 or face_width <= 0:
        raise ValueError("rack too short, teeth pointed, or non-positive bar height / face width")
    x, y0 = length / 2, y_root - bar_height
    outlines = [np.array([[-x, y0], [x, y0], [x, y_root], [-x, y_root]])]
    outlines += [np.array([[c - w_root, y_root], [c + w_root, y_root], [c + w_tip, y_tip], [c - w_tip, y_tip]])
                 for c in (np.arange(n) - (n - 1) / 2) * p]
    z = face_width / 2
    return _pack([_prism(q, -z, z, False, q.mean(axis=0)) for q in outlines])
