"""The joint as a meshcat scene, built from the compiled MJCF.

``viz`` only reads MuJoCo: every visual geom of the model becomes a meshcat
object under its body's node, and each frame sets the bodies' world poses from
``MjData`` (``xpos``, ``xmat``). On top of the model's own geoms the scene adds
what the MJCF has no geometry for:

* the 7-tooth pinion, the 18-tooth spur gear and the rack teeth as real 48 DP
  gear meshes (:mod:`viz.gear_mesh`) in place of the model's plain cylinders;
* a water column in each cylinder, from the closed end to the piston, coloured
  by its chamber pressure (blue at 0, red at the supply pressure);
* the four valves V1-V4 (§4) as lamps, lit when open;
* a ghost of the link at the desired angle (the link's pose with the racks
  placed at the reference, through MuJoCo's kinematics);
* an arrow along gravity, beside the cylinders' closed ends, out of the link's
  reach.

The joint is millimetres across and meshcat's camera orbits the world origin,
so everything hangs under ``/twin`` (compare mode's second joint under
``/compare``, tinted, beside the first), drawn ``SCALE`` times larger with the
middle of the mechanism at the origin, and meshcat's metre grid and axes are
hidden. Each joint carries an invisible box, ``<root>/bodies/housing/view_box``,
round its cylinders, racks, gears, gravity arrow and the link's whole sweep: the
pages fit the camera to those boxes (:func:`scene_commands` sets the direction,
by orientation: from in front and 45 deg above a joint lying flat, 10 deg above
one on its side). Gears are flat-shaded solids, the housing translucent so the
pinion shows through it, the payload a brass sphere of its true size.
Commands are meshcat's lowered dicts: :mod:`viz.recording` packs them into
an HTML file, :mod:`viz.live_server` streams them to a browser.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import meshcat.geometry as g
import mujoco
import numpy as np
from meshcat.commands import SetObject, SetProperty, SetTransform
from meshcat.path import Path

from twin.physics.model import JointModel
from twin.sim.plant_state import place_on_manifold
from viz.gear_mesh import gear_mesh, rack_mesh

ROOT = "/twin"
SCALE = 10.0  # the scene is drawn this many times its size
RACK_BAR_HEIGHT = 0.6e-3  # m, bar under the rack teeth
VALVE_RADIUS = 1.2e-3  # m
VALVES = ("v1", "v2", "v3", "v4")  # V1 supplies A, V2 discharges A, V3 supplies B, V4 discharges B (§4)
# Lamp positions in the housing frame (m): supply valves at the closed ends, discharge valves beside them.
VALVE_POSITIONS = {
    "v1": (-0.062, 0.0085, 0.0), "v2": (-0.054, 0.0085, 0.0),
    "v3": (-0.062, -0.0085, 0.0), "v4": (-0.054, -0.0085, 0.0),
}
VALVE_OPEN_RGB = (0.2, 0.95, 0.2)
VALVE_SHUT_RGB = (0.12, 0.12, 0.12)
LOW_PRESSURE_RGB = np.array([0.15, 0.35, 0.75])
HIGH_PRESSURE_RGB = np.array([0.85, 0.1, 0.1])
CHAMBERS = {"a": ("cylinder_a_barrel", "rack_a_rod"), "b": ("cylinder_b_barrel", "rack_b_rod")}
GHOST_RGBA = (0.9, 0.9, 0.95, 0.35)
GHOST_LIFT = 1.2e-3  # m along the shaft
GRAVITY_ARROW_LENGTH = 12e-3  # m
GRAVITY_ARROW_HEAD_RADIUS = 1.2e-3  # m
# The arrow's middle, in the housing frame, by orientation: beside the cylinders' closed ends, where the link
# never reaches (its sweep stays within about 37 mm of the spur, at x = 6.6 mm), on the housing's side toward
# the camera (-y: in front of a joint lying flat) or against gravity (+y: above a joint on its side, clear of
# the 3D view's legend at the bottom left): no part of the joint comes between it and the camera. It stood in
# the sweep, and the link passed over it (in compare mode, seen from further above, it hid behind the link).
GRAVITY_ARROW_MIDDLE = {"horizontal": np.array([-0.048, -0.02, 0.0]), "vertical": np.array([-0.048, 0.02, 0.0])}  # m
# Camera direction in the world (z up), toward the camera, each showing how the joint stands. Horizontal (the
# link turns in the x-y plane, gravity across it): from in front and 45 deg above, as a joint lying on a bench
# is seen, its sweep drawn as a flattened disc and the gravity arrow upright on the screen. Vertical (the x-z
# plane, gravity in it): from in front and 10 deg above, the sweep nearly face-on and up the screen's up. (Both
# were about 30 deg off face-on, and drew the same picture.) The distance is fitted to the view boxes by the
# page; CAMERA_DISTANCE is the start before the fit.
CAMERA_ELEVATION_DEG = {"horizontal": 45.0, "vertical": 10.0}
CAMERA_DIRECTION = {name: (0.0, -float(np.cos(np.radians(deg))), float(np.sin(np.radians(deg))))
                    for name, deg in CAMERA_ELEVATION_DEG.items()}
CAMERA_DISTANCE = 1.4  # m, in the drawn (SCALE times) scene
VIEW_MARGIN = 1.5e-3  # m round the view box
COMPARE_ROOT = "compare"
COMPARE_TINT = np.array([0.1, 0.75, 0.8])  # teal, mixed into the second joint's solid parts
COMPARE_TINT_SHARE = 0.6
COMPARE_GAP = 10e-3  # m between the two joints' view boxes
BRASS_RGBA = (0.78, 0.6, 0.2, 1.0)  # the payload: brass (SPEC §2; its size from params.masses.payload_density)

SOLID_GEOMS = ("pinion_body", "spur_body", "rack_a_bar", "rack_b_bar", "link_beam", "payload_mass",
               "cylinder_a_barrel", "cylinder_b_barrel", "rack_a_rod", "rack_b_rod", "pinion_mark")

_Y_TO_Z = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Rx(+90 deg): three.js y -> z


def _homogeneous(rotation: np.ndarray, translation: np.ndarray, scale=(1.0, 1.0, 1.0)) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = rotation @ np.diag(scale)
    matrix[:3, 3] = translation
    return matrix


def _colour(rgb) -> int:
    r, gr, b = (int(round(255 * min(max(c, 0.0), 1.0))) for c in rgb[:3])
    return (r << 16) | (gr << 8) | b


def _material(rgba, *, solid: bool = False) -> g.Material:
    """Lambert (matte) by default; ``solid``: flat-shaded Phong, so a gear's faces read as faces."""
    opacity = float(rgba[3])
    if solid:
        return g.MeshPhongMaterial(color=_colour(rgba), opacity=opacity, transparent=opacity < 1.0,
                                   flatShading=True, shininess=40, specular=0x333333)
    return g.MeshLambertMaterial(color=_colour(rgba), opacity=opacity, transparent=opacity < 1.0,
                                 depthWrite=opacity >= 1.0)


def pressure_rgb(pressure: float, supply: float) -> tuple[float, float, float]:
    """Chamber colour: blue at 0 Pa, red at the supply pressure."""
    share = min(max(pressure / supply, 0.0), 1.0) if supply > 0 else 0.0
    return tuple(float(c) for c in (1.0 - share) * LOW_PRESSURE_RGB + share * HIGH_PRESSURE_RGB)


@dataclasses.dataclass
class Frame:
    """One picture of the joint: world poses (4x4, m) and colours (rgb) by meshcat path."""

    transforms: dict[str, np.ndarray]
    colours: dict[str, tuple[float, float, float]]

    @classmethod
    def merged(cls, frames: Sequence[Frame]) -> Frame:
        """One picture of several joints (each under its own root)."""
        return cls(transforms={k: v for f in frames for k, v in f.transforms.items()},
                   colours={k: v for f in frames for k, v in f.colours.items()})


class JointScene:
    """The meshcat scene of one compiled joint under ``/root``; see the module docstring.
    ``tint``: an rgb mixed into its solid parts (compare mode's second joint)."""

    def __init__(self, joint: JointModel, *, supply_pressure: float, root: str = ROOT.strip("/"),
                 tint=None):
        self.joint = joint
        self.model = joint.model
        self.supply = supply_pressure  # Pa, for the chamber colour scale
        self.root, self.tint = root, tint
        self.kinematics = mujoco.MjData(self.model)  # poses of replayed states
        self.ghost_data = mujoco.MjData(self.model)  # poses at the desired angle
        self.body_names = [self.model.body(b).name for b in range(1, self.model.nbody)]
        self.link_body = self.model.body("link").id
        self.housing_body = self.model.body("housing").id
        mujoco.mj_kinematics(self.model, self.kinematics)

    # -- the scene, sent once ------------------------------------------------
    def view_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Corners (m, housing frame) of the box the camera keeps in view: the cylinders and valves,
        the racks and gears, the link with its payload over the racks' whole travel, and the gravity arrow."""
        m, data = self.model, self.kinematics
        low, high = np.full(3, np.inf), np.full(3, -np.inf)
        for name in ("cylinder_a_barrel", "cylinder_b_barrel"):
            geom = m.geom(name).id
            centre, half = m.geom_pos[geom], float(m.geom_size[geom][1])
            low, high = np.minimum(low, centre - [half, 0, 0]), np.maximum(high, centre + [half, 0, 0])
        for x, y, z in VALVE_POSITIONS.values():
            low, high = np.minimum(low, [x - VALVE_RADIUS, y - VALVE_RADIUS, z]), np.maximum(high, [x, y, z])
        payload = m.geom("payload_mass").id
        reach_out = float(m.geom_size[payload][0]) if self._rgba(payload)[3] > 0 else 0.0
        housing = self._housing_pose()
        travel = m.jnt_range[m.body_jntadr[m.body("rack_a").id]]
        for y in np.linspace(travel[0], travel[1], 49):  # the link's sweep, through MuJoCo's kinematics
            self._place(data, float(y))
            mujoco.mj_kinematics(m, data)
            tip = housing[0].T @ (data.xpos[m.body("payload").id] - housing[1])
            low, high = np.minimum(low, tip - reach_out), np.maximum(high, tip + reach_out)
        shell = m.geom("housing_shell").id
        low[2] = min(low[2], -m.geom_size[shell][2])
        for end in self._gravity_arrow_ends():
            low, high = np.minimum(low, end - GRAVITY_ARROW_HEAD_RADIUS), np.maximum(high, end + GRAVITY_ARROW_HEAD_RADIUS)
        return low - VIEW_MARGIN, high + VIEW_MARGIN

    def setup_commands(self) -> list[dict]:
        """This joint's objects and their fixed offsets: send once per model (after
        :func:`scene_commands`'s camera and placement, or use that)."""
        commands = []
        for geom in range(self.model.ngeom):
            rgba = self._rgba(geom)
            if rgba[3] <= 0.0:
                continue  # the empty payload's placeholder
            body = self.body_names[self.model.geom_bodyid[geom] - 1]
            path = Path((self.root, "bodies", body, self.model.geom(geom).name))
            geometry, offset = self._geometry(geom)
            solid = self.model.geom(geom).name in SOLID_GEOMS
            commands.append(SetObject(geometry, _material(self._tinted(rgba), solid=solid), path).lower())
            commands.append(SetTransform(offset, path).lower())
            if body == "link":  # the ghost floats just above the link so the two never z-fight
                ghost = Path((self.root, "ghost", self.model.geom(geom).name))
                lifted = offset.copy()
                lifted[2, 3] += GHOST_LIFT
                commands.append(SetObject(geometry, _material(GHOST_RGBA), ghost).lower())
                commands.append(SetTransform(lifted, ghost).lower())
        for name, (barrel, _) in CHAMBERS.items():
            radius = 1.1 * float(self.model.geom_size[self.model.geom(barrel).id][0])
            commands.append(SetObject(g.Cylinder(1.0, radius), _material((*LOW_PRESSURE_RGB, 0.85)),
                                      Path((self.root, "chambers", name))).lower())
        for name in VALVES:
            commands.append(SetObject(g.Sphere(VALVE_RADIUS), _material((*VALVE_SHUT_RGB, 1.0)),
                                      Path((self.root, "bodies", "housing", "valves", name))).lower())
            commands.append(SetTransform(_homogeneous(np.eye(3), np.array(VALVE_POSITIONS[name])),
                                         Path((self.root, "bodies", "housing", "valves", name))).lower())
        low, high = self.view_box()
        box = Path((self.root, "bodies", "housing", "view_box"))
        commands.append(SetObject(g.Box(list(high - low)), _material((1.0, 1.0, 1.0, 1.0)), box).lower())
        commands.append(SetTransform(_homogeneous(np.eye(3), (low + high) / 2), box).lower())
        commands.append(SetProperty("visible", False, box).lower())
        commands.extend(self._gravity_arrow())
        return commands

    def _tinted(self, rgba) -> tuple:
        if self.tint is None:
            return tuple(rgba)
        rgb = (1.0 - COMPARE_TINT_SHARE) * np.asarray(rgba[:3]) + COMPARE_TINT_SHARE * np.asarray(self.tint)
        return (*rgb, rgba[3])

    def _rgba(self, geom: int) -> np.ndarray:
        material = self.model.geom_matid[geom]
        rgba = self.model.mat_rgba[material] if material >= 0 else self.model.geom_rgba[geom]
        if self.model.geom(geom).name == "payload_mass" and rgba[3] > 0:
            return np.array(BRASS_RGBA)  # the model's grey marks it; the part is brass
        return rgba

    def _geometry(self, geom: int) -> tuple[g.Geometry, np.ndarray]:
        """A meshcat geometry for a MuJoCo geom and its transform in the body frame."""
        m = self.model
        name, size = m.geom(geom).name, m.geom_size[geom]
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, m.geom_quat[geom])
        rotation = rotation.reshape(3, 3)
        position = m.geom_pos[geom].copy()
        gears = self.joint.params.gears
        module = 0.0254 / gears.diametral_pitch
        if name == "pinion_body":
            return _mesh(gear_mesh(gears.pinion_teeth, module, 2 * size[1])), _homogeneous(rotation, position)
        if name == "spur_body":  # half a tooth turned: a gap of the spur faces the pinion's tooth 0 on +x
            half_pitch = np.pi / gears.spur_teeth
            turn = np.array([[np.cos(half_pitch), -np.sin(half_pitch), 0.0],
                             [np.sin(half_pitch), np.cos(half_pitch), 0.0], [0.0, 0.0, 1.0]])
            return _mesh(gear_mesh(gears.spur_teeth, module, 2 * size[1])), _homogeneous(rotation @ turn, position)
        if name in ("rack_a_bar", "rack_b_bar"):
            # Teeth toward the pinion, pitch line on the pinion's pitch circle (the body's origin).
            above = position[1] > 0
            facing = np.diag([1.0, -1.0, -1.0]) if above else np.eye(3)
            joint = m.body_jntadr[m.geom_bodyid[geom]]
            length, shift = rack_teeth_layout(
                travel=tuple(m.jnt_range[joint]), teeth=gears.pinion_teeth, pinion_radius=gears.pinion_radius,
                module=module, contact_angle=np.pi / 2 if above else -np.pi / 2)
            mesh = rack_mesh(length, module, 2 * size[2], RACK_BAR_HEIGHT)
            return _mesh(mesh), _homogeneous(facing, np.array([shift, 0.0, 0.0]))
        kind = m.geom_type[geom]
        if kind == mujoco.mjtGeom.mjGEOM_BOX:
            return g.Box(list(2 * size)), _homogeneous(rotation, position)
        if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
            return g.Sphere(float(size[0])), _homogeneous(rotation, position)
        if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
            return g.Cylinder(2 * float(size[1]), float(size[0])), _homogeneous(rotation @ _Y_TO_Z, position)
        raise ValueError(f"geom {name!r}: no meshcat shape for MuJoCo geom type {kind}")

    def _housing_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """The housing's rotation and origin in the world (it is fixed: a joint on its side is turned by it)."""
        data = self.kinematics
        return data.xmat[self.housing_body].reshape(3, 3).copy(), data.xpos[self.housing_body].copy()

    def _gravity_arrow_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """The gravity arrow's tail and tip (m, housing frame): GRAVITY_ARROW_LENGTH along gravity, about
        GRAVITY_ARROW_MIDDLE."""
        gravity = self.model.opt.gravity
        rotation, _ = self._housing_pose()
        down = rotation.T @ (gravity / np.linalg.norm(gravity))
        middle, half = GRAVITY_ARROW_MIDDLE[self.joint.orientation.value], down * GRAVITY_ARROW_LENGTH / 2
        return middle - half, middle + half

    def _gravity_arrow(self) -> list[dict]:
        gravity = self.model.opt.gravity
        down = gravity / np.linalg.norm(gravity)
        # A rotation taking three.js's cylinder axis (y) onto -gravity, so the cone's tip points down.
        up = -down
        helper = np.array([1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x = np.cross(up, helper)
        x /= np.linalg.norm(x)
        rotation = np.column_stack([x, up, np.cross(x, up)])
        shaft, head = 0.7 * GRAVITY_ARROW_LENGTH, 0.3 * GRAVITY_ARROW_LENGTH
        housing, origin = self._housing_pose()
        base = housing @ self._gravity_arrow_ends()[0] + origin  # the tail, in the world
        grey = _material((0.3, 0.3, 0.3, 1.0))
        return [
            SetObject(g.Cylinder(shaft, 0.4e-3), grey, Path((self.root, "gravity", "shaft"))).lower(),
            SetTransform(_homogeneous(rotation, base - up * shaft / 2), Path((self.root, "gravity", "shaft"))).lower(),
            SetObject(g.Cylinder(head, radiusTop=GRAVITY_ARROW_HEAD_RADIUS, radiusBottom=0.0), grey,
                      Path((self.root, "gravity", "head"))).lower(),
            SetTransform(_homogeneous(rotation, base - up * (shaft + head / 2)),
                         Path((self.root, "gravity", "head"))).lower(),
        ]

    # -- a frame, sent as often as the picture changes -----------------------
    def frame(self, data: mujoco.MjData, *, desired_angle: float, pressures: tuple[float, float],
              valve_open) -> Frame:
        """The poses in ``data`` (kinematics done), the ghost at ``desired_angle`` (rad), the
        chamber pressures (Pa) and valves V1-V4 (bool) as one :class:`Frame`."""
        root = "/" + self.root
        transforms = {f"{root}/bodies/{name}": _homogeneous(data.xmat[b].reshape(3, 3), data.xpos[b])
                      for b, name in enumerate(self.body_names, start=1)}
        transforms[f"{root}/ghost"] = self._ghost_pose(desired_angle)
        colours = {}
        for (name, (barrel, rod)), pressure in zip(CHAMBERS.items(), pressures, strict=True):
            transforms[f"{root}/chambers/{name}"] = self._chamber_pose(data, barrel, rod)
            colours[f"{root}/chambers/{name}/<object>"] = pressure_rgb(float(pressure), self.supply)
        for name, is_open in zip(VALVES, valve_open, strict=True):
            colours[f"{root}/bodies/housing/valves/{name}/<object>"] = (
                VALVE_OPEN_RGB if is_open else VALVE_SHUT_RGB)
        return Frame(transforms=transforms, colours=colours)

    def replay_frame(self, *, rack_position: float, angle: float, desired_angle: float,
                     pressures: tuple[float, float], valve_open) -> Frame:
        """A recorded state: racks and pinion at ``rack_position`` (m), the output at ``angle`` (rad)."""
        self._place(self.kinematics, rack_position)
        self.kinematics.qpos[self.joint.spur_dof] = angle
        mujoco.mj_kinematics(self.model, self.kinematics)
        return self.frame(self.kinematics, desired_angle=desired_angle, pressures=pressures, valve_open=valve_open)

    def _place(self, data: mujoco.MjData, rack_position: float) -> None:
        qpos = data.qpos[None, :].copy()
        place_on_manifold(qpos, self.joint, np.array([rack_position]))
        data.qpos[:] = qpos[0]

    def _ghost_pose(self, desired_angle: float) -> np.ndarray:
        self._place(self.ghost_data, desired_angle * self.joint.params.gears.spur_radius)
        mujoco.mj_kinematics(self.model, self.ghost_data)
        b = self.link_body
        return _homogeneous(self.ghost_data.xmat[b].reshape(3, 3), self.ghost_data.xpos[b])

    def _chamber_pose(self, data: mujoco.MjData, barrel: str, rod: str) -> np.ndarray:
        """Water column from the barrel's closed end to the piston (the rod's far end)."""
        b, r = self.model.geom(barrel).id, self.model.geom(rod).id
        barrel_axes = data.geom_xmat[b].reshape(3, 3)
        axis = barrel_axes[:, 2]
        closed_end = data.geom_xpos[b] - axis * self.model.geom_size[b][1]
        piston = data.geom_xpos[r] - data.geom_xmat[r].reshape(3, 3)[:, 2] * self.model.geom_size[r][1]
        length = max(float(np.dot(piston - closed_end, axis)), 0.5e-3)
        return _homogeneous(barrel_axes @ _Y_TO_Z, closed_end + axis * length / 2, scale=(1.0, length, 1.0))


def _world_box(scene: JointScene) -> tuple[np.ndarray, np.ndarray]:
    low, high = scene.view_box()
    rotation = scene.kinematics.xmat[scene.housing_body].reshape(3, 3)
    origin = scene.kinematics.xpos[scene.housing_body]
    corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
    world = corners @ rotation.T + origin
    return world.min(axis=0), world.max(axis=0)


def placement(scenes: Sequence[JointScene]) -> list[np.ndarray]:
    """Where each joint's origin sits in the world (m, before SCALE) so that the first is beside the
    second along the first housing's -y (in its plane of rotation) and the pair is centred."""
    boxes = [_world_box(scene) for scene in scenes]
    across = -scenes[0].kinematics.xmat[scenes[0].housing_body].reshape(3, 3)[:, 1]
    offsets = [np.zeros(3)]
    for low, high in boxes[1:]:
        first_low, first_high = boxes[0]
        offsets.append(across * (float(np.abs(across) @ (first_high - first_low)) / 2
                                 + float(np.abs(across) @ (high - low)) / 2 + COMPARE_GAP))
    low = np.min([box[0] + offset for box, offset in zip(boxes, offsets, strict=True)], axis=0)
    high = np.max([box[1] + offset for box, offset in zip(boxes, offsets, strict=True)], axis=0)
    centre = (low + high) / 2
    return [offset - centre for offset in offsets]


def scene_commands(scenes: Sequence[JointScene]) -> list[dict]:
    """The whole scene: meshcat's grid and axes hidden, the camera's direction (CAMERA_DIRECTION, by the
    first joint's orientation), each joint placed (:func:`placement`) and drawn."""
    commands = [SetProperty("visible", False, Path(("Grid",))).lower(),
                SetProperty("visible", False, Path(("Axes",))).lower()]
    x, y, z = CAMERA_DISTANCE * np.array(CAMERA_DIRECTION[scenes[0].joint.orientation.value])
    commands.append(SetProperty("position", [float(x), float(z), float(-y)],  # meshcat's y-up camera frame
                                Path(("Cameras", "default", "rotated", "<object>"))).lower())
    for scene, origin in zip(scenes, placement(scenes), strict=True):
        commands.append(SetTransform(_homogeneous(SCALE * np.eye(3), SCALE * origin), Path((scene.root,))).lower())
        commands.extend(scene.setup_commands())
    return commands


def rack_teeth_layout(*, travel: tuple[float, float], teeth: int, pinion_radius: float, module: float,
                      contact_angle: float) -> tuple[float, float]:
    """Length (m) of a rack's toothed part and where its centre sits in the rack's frame (m), so
    that its teeth cover the pinion's contact point over the rack joint's whole ``travel`` (m)
    and, at zero travel, a tooth fills the pinion's gap nearest the contact (tooth 0 of the
    pinion on +x, the contact at ``contact_angle`` rad on the pitch circle)."""
    pitch = np.pi * module
    low, high = -travel[1], -travel[0]  # the contact point's x in the rack's frame
    count = int(np.ceil((high - low) / pitch)) + 4  # two spare teeth at each end
    gap = (np.round(contact_angle / (2 * np.pi / teeth) - 0.5) + 0.5) * 2 * np.pi / teeth
    tooth_x = -pinion_radius * (gap - contact_angle) * np.sin(contact_angle)  # along the pitch line
    first = tooth_x - np.ceil((tooth_x - (low + high) / 2) / pitch) * pitch  # a tooth near the middle
    centre = first - (0.0 if count % 2 else pitch / 2)  # rack_mesh centres its teeth on its middle
    return count * pitch, float(centre)


def _path(text: str) -> Path:
    return Path(tuple(text.strip("/").split("/")))


def _mesh(mesh) -> g.TriangularMeshGeometry:
    vertices, faces = mesh
    return g.TriangularMeshGeometry(np.asarray(vertices, dtype=np.float32), np.asarray(faces, dtype=np.uint32))


def frame_commands(frame: Frame) -> list[dict]:
    """meshcat commands that show ``frame`` (live viewing)."""
    commands = [SetTransform(matrix, _path(path)).lower() for path, matrix in frame.transforms.items()]
    commands += [SetProperty("color", [*rgb, 0.85 if "chambers" in path else 1.0],
                             _path(path)).lower()
                 for path, rgb in frame.colours.items()]
    return commands

