"""A run as one self-contained HTML file: the 3D animation with meshcat's
play/pause/scrub controls beside a plot of the run's key traces, with a cursor
that follows the animation's clock. Works offline: meshcat's viewer script,
the scene, the animation and the plot are all inside the file.
"""

from __future__ import annotations

import base64
import dataclasses
import html
import importlib.resources
import io
import json
import pathlib
from collections.abc import Sequence

import numpy as np
import umsgpack
from meshcat.transformations import quaternion_from_matrix

from twin.physics.model import compile_joint
from twin.sim.simulation import Result
from viz.scene import Frame, JointScene

FPS = 50  # animation frames per second of simulated time
PAGE = importlib.resources.files("viz") / "recording_page.html"  # package data
MESHCAT_SCRIPT = importlib.resources.files("meshcat") / "viewer" / "dist" / "main.min.js"


@dataclasses.dataclass(frozen=True)
class TraceRows:
    """The traces a recording plots, one row per animation frame; SI units."""

    time: np.ndarray  # s
    angle: np.ndarray  # rad
    desired_angle: np.ndarray  # rad
    duty: np.ndarray  # %
    pressure_a: np.ndarray  # Pa
    pressure_b: np.ndarray  # Pa
    supply_pressure: np.ndarray  # Pa

    def as_json(self) -> dict:
        """Degrees and kPa for the page's readout."""
        return {"time": self.time.tolist(), "angle_deg": np.degrees(self.angle).tolist(),
                "desired_deg": np.degrees(self.desired_angle).tolist(), "duty": self.duty.tolist(),
                "pressure_a_kpa": (self.pressure_a / 1e3).tolist(),
                "pressure_b_kpa": (self.pressure_b / 1e3).tolist()}


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
                             supply_pressure=tr.supply_pressure[rows])


def plot_png(rows: TraceRows, title: str) -> tuple[bytes, dict]:
    """The key traces as a PNG, and where its time axis lies across the image (fractions of its width)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(6.0, 6.4), dpi=100)
    axes[0].plot(rows.time, np.degrees(rows.desired_angle), "k--", lw=1, label="desired")
    axes[0].plot(rows.time, np.degrees(rows.angle), color="tab:red", lw=1, label="actual")
    axes[0].set_ylabel("angle (deg)")
    axes[0].legend(loc="best", fontsize=8)
    axes[1].step(rows.time, rows.duty, where="post", color="tab:blue", lw=0.8)
    axes[1].set_ylabel("duty (%)")
    axes[2].plot(rows.time, rows.pressure_a / 1e3, lw=0.8, label="chamber A")
    axes[2].plot(rows.time, rows.pressure_b / 1e3, lw=0.8, label="chamber B")
    axes[2].plot(rows.time, rows.supply_pressure / 1e3, "k:", lw=0.8, label="supply")
    axes[2].set_ylabel("pressure (kPa)")
    axes[2].set_xlabel("time (s)")
    axes[2].legend(loc="best", fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    box = axes[0].get_position()
    t0, t1 = axes[0].get_xlim()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    return buffer.getvalue(), {"left": box.x0, "right": box.x1, "t0": t0, "t1": t1}


def page(*, title: str, commands: Sequence[dict], rows: TraceRows) -> str:
    """The HTML text of a recording of ``commands`` (scene + animation) and ``rows``."""
    png, axis = plot_png(rows, title)
    packed = [base64.b64encode(umsgpack.packb(c)).decode("ascii") for c in commands]
    return (PAGE.read_text()
            .replace("{{title}}", html.escape(title))
            .replace("{{commands}}", json.dumps(packed))
            .replace("{{plot}}", base64.b64encode(png).decode("ascii"))
            .replace("{{axis}}", json.dumps(axis))
            .replace("{{trace}}", json.dumps(rows.as_json()))
            .replace("{{meshcat_script}}", MESHCAT_SCRIPT.read_text().replace("</script>", "<\\/script>")))


def write_page(path: pathlib.Path, *, scene: JointScene, frames: Sequence[Frame], rows: TraceRows,
               title: str, fps: int = FPS) -> None:
    path.write_text(page(title=title, commands=[*scene.setup_commands(), animation_command(frames, fps)],
                         rows=rows))


def title_of(scenario) -> str:
    return (f"{scenario.controller} T{scenario.trajectory}, {scenario.payload * 1e3:g} g "
            f"{scenario.orientation.value} ({scenario.plant_name}, seed {scenario.seed})")


def write_recording(result: Result, path: pathlib.Path, *, fps: int = FPS) -> None:
    """Write ``result`` as a self-contained HTML recording at ``path``."""
    s = result.scenario
    preset = s.preset
    joint = compile_joint(params=preset.params, payload_mass=s.payload, orientation=s.orientation,
                          timestep=preset.timestep)
    scene = JointScene(joint, supply_pressure=s.supply)
    frames, rows = replay_frames(scene, result, fps)
    rmse = np.degrees(result.metrics.rmse)
    write_page(path, scene=scene, frames=frames, rows=rows, title=f"{title_of(s)}: RMSE {rmse:.2f} deg", fps=fps)
