"""A run as one self-contained HTML file: the 3D animation beside strip charts
of the run's traces (angle and desired, error, duty, pressures, valves), with
the page's own play / pause / scrub / speed controls driving one clock that
poses the 3D view and moves the charts' cursor together; a drag across a chart
zooms every chart to that span. In compare mode both joints are drawn and their
traces overlaid. Works offline: meshcat's viewer script, the chart drawer
(``viz/strip_chart.js``), the scene, the animation and the traces are all inside
the file.
"""

from __future__ import annotations

import base64
import dataclasses
import html
import importlib.resources
import json
import pathlib
import re
import uuid
from collections.abc import Sequence

import numpy as np
import umsgpack
from meshcat.transformations import quaternion_from_matrix

from twin.physics.model import compile_joint
from twin.sim.simulation import Result
from viz.scene import COMPARE_ROOT, COMPARE_TINT, Frame, JointScene, scene_commands

FPS = 50  # animation frames per second of simulated time
PAGE = importlib.resources.files("viz") / "recording_page.html"  # package data
MESHCAT_SCRIPT = importlib.resources.files("meshcat") / "viewer" / "dist" / "main.min.js"
STRIP_CHART_SCRIPT = importlib.resources.files("viz") / "strip_chart.js"  # package data


@dataclasses.dataclass(frozen=True)
class TraceRows:
    """The traces a recording plots, one row per animation frame; SI units. The valves are kept
    as their changes, tick exact, since a PWM pulse is shorter than a frame."""

    time: np.ndarray  # s
    angle: np.ndarray  # rad
    desired_angle: np.ndarray  # rad
    duty: np.ndarray  # %
    pressure_a: np.ndarray  # Pa
    pressure_b: np.ndarray  # Pa
    supply_pressure: np.ndarray  # Pa
    valve_changes: list  # [time (s), [V1..V4 open]] at the start and at each change

    def as_json(self) -> dict:
        """Degrees and kPa, the field names of the live page's samples."""
        return {"time": self.time.tolist(), "angle_deg": np.degrees(self.angle).tolist(),
                "desired_deg": np.degrees(self.desired_angle).tolist(),
                "error_deg": np.degrees(self.desired_angle - self.angle).tolist(), "duty": self.duty.tolist(),
                "pressure_a_kpa": (self.pressure_a / 1e3).tolist(),
                "pressure_b_kpa": (self.pressure_b / 1e3).tolist(),
                "supply_kpa": (self.supply_pressure / 1e3).tolist(),
                "valves": [[float(t), [bool(v) for v in is_open]] for t, is_open in self.valve_changes]}


def valve_changes(time: np.ndarray, valve_open: np.ndarray) -> list:
    """``[time, [V1..V4]]`` at the first row and wherever ``valve_open`` (n, 4) changes."""
    if len(time) == 0:
        return []
    changed = np.flatnonzero(np.any(valve_open[1:] != valve_open[:-1], axis=1)) + 1
    return [[float(time[k]), [bool(v) for v in valve_open[k]]] for k in (0, *changed)]


def animation_command(frames: Sequence[Frame], fps: int) -> dict:
    """meshcat's ``set_animation`` for ``frames`` at ``fps``: poses as position, quaternion
    and scale tracks, colours as ``material.color`` tracks."""
    clips: dict[str, dict[str, tuple[str, list]]] = {}

    def key(path: str, track: str, jstype: str, frame: int, value) -> None:
        clips.setdefault(path, {}).setdefault(track, (jstype, []))[1].append({"time": frame, "value": value})

    for i, frame in enumerate(frames):
        for path, matrix in frame.transforms.items():
            scale = np.linalg.norm(matrix[:3, :3], axis=0)
            unscaled = matrix.copy()
            unscaled[:3, :3] /= scale
            w, x, y, z = quaternion_from_matrix(unscaled)
            key(path, "position", "vector3", i, [float(v) for v in matrix[:3, 3]])
            key(path, "quaternion", "quaternion", i, [float(x), float(y), float(z), float(w)])
            if not np.allclose(scale, 1.0):
                key(path, "scale", "vector3", i, [float(v) for v in scale])
        for path, rgb in frame.colours.items():
            key(path, "material.color", "color", i, [float(c) for c in rgb])
    animations = [{"path": path, "clip": {"fps": fps, "name": "default", "tracks": [
        {"name": "." + track, "type": jstype, "keys": keys} for track, (jstype, keys) in tracks.items()]}}
        for path, tracks in clips.items()]
    return {"type": "set_animation", "animations": animations,
            "options": {"play": True, "repetitions": 1}, "path": ""}


def replay_frames(scene: JointScene, result: Result, fps: int) -> tuple[list[Frame], TraceRows]:
    """Frames of a finished run every 1/fps s of simulated time, and the trace rows they show."""
    tr = result.trace
    h = float(tr.time[1] - tr.time[0]) if len(tr.time) > 1 else 1e-3
    rows = np.arange(0, len(tr.time), max(1, int(round(1.0 / (fps * h)))))
    frames = [scene.replay_frame(
        rack_position=float(tr.rack_position[k]), angle=float(tr.angle[k]),
        desired_angle=float(tr.desired_angle[k]),
        pressures=(float(tr.pressure_a[k]), float(tr.pressure_b[k])), valve_open=tr.valve_open[k])
        for k in rows]
    return frames, TraceRows(time=tr.time[rows], angle=tr.angle[rows], desired_angle=tr.desired_angle[rows],
                             duty=tr.duty[rows], pressure_a=tr.pressure_a[rows], pressure_b=tr.pressure_b[rows],
                             supply_pressure=tr.supply_pressure[rows],
                             valve_changes=valve_changes(tr.time, np.asarray(tr.valve_open, dtype=bool)))


def compare_label(text: dict) -> str:
    """``controller=smc, payload=13.5``: compare mode's settings as the user wrote them."""
    return ", ".join(f"{key}={value}" for key, value in text.items())


UUID = re.compile(r"[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}")


def stable_uuids(command, renamed: dict[str, str]):
    """``command`` with every UUID meshcat gave it (``uuid1``: the time it was made and this machine's network
    address) renamed in order of first appearance, the same name wherever it is referred to: a recording is
    then the same bytes for the same run, and says nothing of where or when it was made. ``renamed`` carries
    the names across one page's commands."""
    if isinstance(command, dict):
        return {key: stable_uuids(value, renamed) for key, value in command.items()}
    if isinstance(command, list | tuple):
        return type(command)(stable_uuids(value, renamed) for value in command)
    if isinstance(command, str) and UUID.fullmatch(command):
        return renamed.setdefault(command, str(uuid.UUID(int=len(renamed) + 1)))
    return command


TRACE_LABELS = ("first", "compare")  # the charts' names for the traces; the legend shows the second's


def page(*, title: str, commands: Sequence[dict], rows: Sequence[TraceRows]) -> str:
    """The HTML text of a recording of ``commands`` (scene + animation) and its traces ``rows`` (the
    first joint's, and the second's in compare mode); the title says what each is."""
    labels = TRACE_LABELS[:len(rows)]
    renamed: dict[str, str] = {}
    packed = [base64.b64encode(umsgpack.packb(stable_uuids(c, renamed))).decode("ascii") for c in commands]
    traces = [r.as_json() for r in rows]
    return (PAGE.read_text()
            .replace("{{title}}", html.escape(title))
            .replace("{{commands}}", json.dumps(packed))
            .replace("{{trace}}", json.dumps(traces[0]))
            .replace("{{traces}}", json.dumps(traces))
            .replace("{{labels}}", json.dumps(list(labels)))
            .replace("{{strip_chart_script}}", STRIP_CHART_SCRIPT.read_text().replace("</script>", "<\\/script>"))
            .replace("{{meshcat_script}}", MESHCAT_SCRIPT.read_text().replace("</script>", "<\\/script>")))


def write_page(path: pathlib.Path, *, scenes: Sequence[JointScene], frames: Sequence[Frame],
               rows: Sequence[TraceRows], title: str, fps: int = FPS) -> None:
    path.write_text(page(title=title, commands=[*scene_commands(scenes), animation_command(frames, fps)],
                         rows=rows))


def title_of(scenario) -> str:
    return (f"{scenario.controller} T{scenario.trajectory}, {scenario.payload * 1e3:g} g "
            f"{scenario.orientation.value} ({scenario.plant_name}, seed {scenario.seed})")


def write_recording(result: Result, path: pathlib.Path, *, compare: Result | None = None,
                    compare_text: dict | None = None, fps: int = FPS) -> None:
    """Write ``result`` as a self-contained HTML recording at ``path``; with ``compare`` (a run of
    the same trajectory, its settings ``compare_text`` as the user wrote them), both joints."""
    scenes, all_frames, all_rows = [], [], []
    for run_, root, tint in zip((result, compare), ("twin", COMPARE_ROOT), (None, COMPARE_TINT), strict=True):
        if run_ is None:
            continue
        s = run_.scenario
        preset = s.preset
        joint = compile_joint(params=preset.params, payload_mass=s.payload, orientation=s.orientation,
                              timestep=preset.timestep)
        scene = JointScene(joint, supply_pressure=s.supply, root=root, tint=tint)
        frames, rows = replay_frames(scene, run_, fps)
        scenes.append(scene)
        all_frames.append(frames)
        all_rows.append(rows)
    frames = [Frame.merged(pictures) for pictures in zip(*all_frames, strict=False)]
    title = f"{title_of(result.scenario)}: RMSE {np.degrees(result.metrics.rmse):.2f} deg"
    if compare is not None:
        text = compare_label(compare_text or {})
        title += f"; compare {text}: RMSE {np.degrees(compare.metrics.rmse):.2f} deg"
    write_page(path, scenes=scenes, frames=frames, rows=all_rows, title=title, fps=fps)
