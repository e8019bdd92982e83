"""``twin view``: the joint live in a browser.

One tornado server, bound to 127.0.0.1 unless ``host`` says otherwise (meshcat's
stock server listens on every interface, so the twin does not use it), serves:

``/``            the page: meshcat's 3D view and a control panel;
``/meshcat.js``  meshcat's viewer script (from the installed meshcat package);
``/ws``          a WebSocket. Server to page: meshcat commands (binary msgpack,
                 as meshcat's own server sends them) and JSON readouts, state and
                 errors. Page to server: the JSON messages of :mod:`viz.live_messages`,
                 each checked; a bad one gets an error back and the run goes on.

The simulation advances on the server's clock at ``speed`` times real time,
``FRAME_RATE`` times a second; if the machine cannot keep up it runs slower
rather than skipping physics.
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import json
import math
import os
import pathlib
import sys
import time
import urllib.parse
from collections.abc import Callable

import mujoco
import numpy as np
import tornado.httpserver
import tornado.ioloop
import tornado.netutil
import tornado.web
import tornado.websocket
import umsgpack
from meshcat.commands import Delete
from meshcat.path import Path

from twin.envs.live import LiveJoint, Readout
from twin.exceptions import SimulationFailed, TwinError
from twin.sim.scenario import Scenario
from viz import live_messages
from viz.recording import FPS, MESHCAT_SCRIPT, TraceRows, title_of, write_page
from viz.scene import Frame, JointScene, frame_commands

FRAME_RATE = 30.0  # pictures per second of wall time
MIN_REBUILD_INTERVAL = 0.5  # s between model rebuilds (each compiles the model on the server's thread)
MAX_LAG_FRAMES = 3.0  # a late picture catches up at most this many frames of simulated time
# Tornado closes the socket on a larger WebSocket message without reading it; below this, an oversized
# command (live_messages.MAX_MESSAGE_BYTES) is read and answered with an error, and the socket stays open.
MAX_MESSAGE_BYTES = 64 * 1024
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "::1")
MAX_RECORDED_FRAMES = 10 * 60 * FPS  # a --html recording keeps the last 10 minutes
PAGE = importlib.resources.files("viz") / "live_page.html"  # package data


class ServerError(TwinError):
    """The viewer server could not start (say, its port is taken)."""


@dataclasses.dataclass
class _Recorder:
    """The frames and trace rows of the current model's run, for ``--html``."""

    frames: list[Frame] = dataclasses.field(default_factory=list)
    rows: list[tuple] = dataclasses.field(default_factory=list)

    def add(self, frame: Frame, row: tuple) -> None:
        self.frames.append(frame)
        self.rows.append(row)
        if len(self.frames) > MAX_RECORDED_FRAMES:
            del self.frames[0], self.rows[0]

    def trace_rows(self) -> TraceRows:
        columns = np.array(self.rows, dtype=float).reshape(-1, 7).T
        time_, angle, desired, duty, pa, pb, supply = columns
        return TraceRows(time=time_ - time_[0] if len(time_) else time_, angle=angle, desired_angle=desired,
                         duty=duty, pressure_a=pa, pressure_b=pb, supply_pressure=supply)


class LiveSession:
    """What one ``twin view`` shows: a :class:`LiveJoint`, its scene, and the page's commands."""

    def __init__(self, scenario: Scenario, *, record: bool = False):
        self.record = record
        self._rebuilt_at = -math.inf
        self._start(scenario)

    def _start(self, scenario: Scenario) -> None:
        self.joint = LiveJoint(scenario)
        self.scene = JointScene(self.joint.joint, supply_pressure=scenario.supply)
        self.recorder = _Recorder()
        self._debt = 0.0  # s of simulated time asked for but not yet a whole tick
        self.record_every = max(1, round(1.0 / (FPS * self.joint.tick)))
        self._capture()

    @property
    def scenario(self) -> Scenario:
        return self.joint.scenario

    def setup_commands(self) -> list[dict]:
        return [Delete(Path(("twin",))).lower(), *self.scene.setup_commands()]

    def frame(self, r: Readout | None = None) -> Frame:
        r = self.joint.readout() if r is None else r
        return self.scene.frame(self.joint.data, desired_angle=r.desired_angle,
                                pressures=(r.pressure_a, r.pressure_b), valve_open=r.valve_open)

    def _capture(self) -> None:
        if self.record:
            r = self.joint.readout()
            self.recorder.add(self.frame(r), (r.time, r.angle, r.desired_angle, r.duty, r.pressure_a,
                                             r.pressure_b, r.supply_pressure))

    def advance(self, duration: float) -> None:
        """Step ``duration`` seconds; the fraction of a tick left over is carried to the next call.
        Raises SimulationFailed on a MuJoCo warning or a non-finite state."""
        self._debt += duration
        ticks = int(self._debt / self.joint.tick + 1e-9)
        self._debt -= ticks * self.joint.tick
        for _ in range(ticks):
            self.joint.step()
            if self.joint.steps % self.record_every == 0:
                self._capture()
        data = self.joint.data
        warned = [mujoco.mjtWarning(i).name for i, w in enumerate(data.warning) if w.number > 0]
        if warned or not np.all(np.isfinite(data.qpos)):
            raise SimulationFailed(f"MuJoCo {', '.join(warned) or 'state not finite'} at "
                                   f"t = {self.joint.time:.3f} s")

    def handle(self, text: str | bytes) -> bool:
        """Apply one message from the page; True if the model was rebuilt. Raises BadMessage."""
        command = live_messages.parse(text)
        if isinstance(command, live_messages.Target):
            self.joint.set_target(command.angle)
        elif isinstance(command, live_messages.PlayTrajectory):
            self.joint.play(command.number)
        elif isinstance(command, live_messages.SwitchController):
            self.joint.switch_controller(command.name)
        else:
            now = time.monotonic()
            if now - self._rebuilt_at < MIN_REBUILD_INTERVAL:
                raise live_messages.BadMessage(f"the model was rebuilt {now - self._rebuilt_at:.1f} s ago: "
                                               f"wait {MIN_REBUILD_INTERVAL:g} s between payload/orientation changes")
            changes = {k: v for k, v in dataclasses.asdict(command).items() if v is not None}
            self._start(dataclasses.replace(self.scenario, **changes))
            self._rebuilt_at = now
            return True
        return False

    def readout(self) -> dict:
        r = self.joint.readout()
        return {"type": "readout", "time": r.time, "angle_deg": math.degrees(r.angle),
                "desired_deg": math.degrees(r.desired_angle), "error_deg": math.degrees(r.error),
                "duty": r.duty, "pressure_a_kpa": r.pressure_a / 1e3, "pressure_b_kpa": r.pressure_b / 1e3,
                "supply_kpa": r.supply_pressure / 1e3, "valves": list(r.valve_open)}

    def state(self) -> dict:
        s, plan = self.scenario, self.joint.plan
        target = math.degrees(plan.start + sum(seg.delta for seg in plan.segments))
        playing = f"T{plan.number}" if plan.number else f"target {target:.0f} deg"
        return {"type": "state", "controller": s.controller, "trajectory": s.trajectory, "playing": playing,
                "payload_g": s.payload * 1e3, "orientation": s.orientation.value, "plant": s.plant_name}

    def write_html(self, path: pathlib.Path) -> None:
        """The current model's run as a recording, written whole (a temporary file, then renamed)."""
        tmp = path.with_name(path.name + ".tmp")
        write_page(tmp, scene=self.scene, frames=self.recorder.frames, rows=self.recorder.trace_rows(),
                   title=f"live: {title_of(self.scenario)}")
        os.replace(tmp, path)


def _packed(commands: list[dict]) -> list[bytes]:
    return [umsgpack.packb(c) for c in commands]


def _send(client: tornado.websocket.WebSocketHandler, message: bytes | str):
    """Queue ``message`` to ``client``: the write's future, or None if the page has gone (a page
    closed mid-write is not an error)."""
    try:
        sent = client.write_message(message, binary=isinstance(message, bytes))
    except tornado.websocket.WebSocketClosedError:
        return None
    sent.add_done_callback(lambda future: future.exception())  # a late close: seen, and ignored
    return sent


def _host_allowed(handler: tornado.web.RequestHandler, viewer: LiveViewer) -> bool:
    """Bound to loopback, answer only requests addressed to loopback (no DNS rebinding)."""
    if viewer.host not in ("127.0.0.1", "::1", "localhost"):
        return True
    return urllib.parse.urlsplit("//" + handler.request.host).hostname in LOOPBACK_HOSTS


class _PageHandler(tornado.web.RequestHandler):
    def initialize(self, viewer: LiveViewer) -> None:
        self.viewer = viewer

    def get(self) -> None:
        if not _host_allowed(self, self.viewer):
            raise tornado.web.HTTPError(403)
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.write(PAGE.read_text())


class _ScriptHandler(tornado.web.RequestHandler):
    def get(self) -> None:
        self.set_header("Content-Type", "application/javascript")
        self.write(MESHCAT_SCRIPT.read_bytes())


class _SocketHandler(tornado.websocket.WebSocketHandler):
    def initialize(self, viewer: LiveViewer) -> None:
        self.viewer = viewer
        self.pending_frame = None  # the write of the last frame sent, while it is in flight

    def prepare(self):
        if not _host_allowed(self, self.viewer):
            raise tornado.web.HTTPError(403)
        return super().prepare()

    def open(self) -> None:
        self.viewer.clients.add(self)
        for message in [*_packed(self.viewer.session.setup_commands()), json.dumps(self.viewer.session.state())]:
            _send(self, message)

    def on_message(self, message: str | bytes) -> None:
        self.viewer.receive(self, message)

    def on_close(self) -> None:
        self.viewer.clients.discard(self)


class LiveViewer:
    """The server and the clock; ``start()`` serves until :meth:`stop` or Ctrl-C."""

    def __init__(self, session: LiveSession, *, host: str = "127.0.0.1", port: int = 7000, speed: float = 1.0,
                 on_frame: Callable[[], None] | None = None):
        self.session, self.speed, self.on_frame = session, speed, on_frame
        self.clients: set[_SocketHandler] = set()
        app = tornado.web.Application([
            (r"/", _PageHandler, {"viewer": self}), (r"/meshcat.js", _ScriptHandler),
            (r"/ws", _SocketHandler, {"viewer": self}),
        ], log_function=lambda handler: None, websocket_max_message_size=MAX_MESSAGE_BYTES)
        self.failure: str | None = None
        try:
            self.sockets = tornado.netutil.bind_sockets(port, address=host)
        except OSError as error:
            raise ServerError(f"cannot listen on {host}:{port}: {error.strerror}") from None
        self.server = tornado.httpserver.HTTPServer(app)
        self.host, self.port = host, self.sockets[0].getsockname()[1]

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}/"

    def broadcast(self, messages: list[bytes | str], *, droppable: bool = False) -> None:
        """Send ``messages`` to every page; ``droppable`` ones (a frame) skip a page that has not
        yet taken the previous frame, so a stalled tab cannot pile up memory."""
        for client in list(self.clients):
            if droppable and client.pending_frame is not None and not client.pending_frame.done():
                continue
            for message in messages:
                sent = _send(client, message)
                if sent is None:
                    self.clients.discard(client)
                    break
                if droppable:
                    client.pending_frame = sent

    def receive(self, client: _SocketHandler, message: str | bytes) -> None:
        try:
            rebuilt = self.session.handle(message)
        except live_messages.BadMessage as error:
            _send(client, json.dumps({"type": "error", "message": str(error)}))
            return
        except TwinError as error:  # a valid message the twin cannot run (e.g. a rejected model)
            _send(client, json.dumps({"type": "error", "message": str(error)}))
            return
        except Exception as error:  # noqa: BLE001 - answer, never drop the page's connection
            _send(client, json.dumps({"type": "error", "message": f"cannot apply that: {type(error).__name__}"}))
            return
        if rebuilt:
            self.broadcast(_packed(self.session.setup_commands()))
        self.broadcast([json.dumps(self.session.state())])

    def _tick(self) -> None:
        now = time.perf_counter()
        elapsed, self._last = now - self._last, now
        try:
            self.session.advance(min(elapsed, MAX_LAG_FRAMES / FRAME_RATE) * self.speed)
        except Exception as error:  # noqa: BLE001 - stop once, tell the page and the terminal
            self.clock.stop()
            self.failure = f"simulation stopped: {error}"
            print(f"twin view: {self.failure}", file=sys.stderr, flush=True)
            self.broadcast([json.dumps({"type": "error", "message": self.failure})])
            return
        if self.clients:
            self.broadcast([*_packed(frame_commands(self.session.frame())), json.dumps(self.session.readout())],
                           droppable=True)
        if self.on_frame is not None:
            self.on_frame()

    def start(self) -> None:
        self.server.add_sockets(self.sockets)
        self._last = time.perf_counter()
        self.loop = tornado.ioloop.IOLoop.current()
        self.clock = tornado.ioloop.PeriodicCallback(self._tick, 1000.0 / FRAME_RATE)
        self.clock.start()
        self.loop.start()

    def stop(self) -> None:
        self.clock.stop()
        self.server.stop()
        for client in list(self.clients):
            client.close()
        self.loop.stop()
