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
import pathlib
import signal
import sys
import threading
import time
import urllib.parse

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

from twin.envs.live import Compare, LiveJoint, LiveJoints, Readout
from twin.exceptions import SimulationFailed, TwinError
from twin.sim.scenario import Scenario
from viz import live_messages
from viz.recording import FPS, MESHCAT_SCRIPT, STRIP_CHART_SCRIPT, TraceRows, compare_label, write_page
from viz.scene import COMPARE_ROOT, COMPARE_TINT, Frame, JointScene, frame_commands, scene_commands

FRAME_RATE = 30.0  # pictures per second of wall time (and plot updates)
SAMPLE_PERIOD = 5e-3  # s of simulated time between plotted samples (valves: every change)
MAX_TITLED_RUNS = 4  # a live recording's title names at most the last four things the joint ran
REPLAY_ON_CONNECT = 1  # the trajectory replayed when the first page connects, so the joint moves on open
STOP_GRACE = 0.3  # s for the last messages to leave before the server's loop ends
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
    """The frames and trace rows of the current model's run, for ``--html``: one row list per joint."""

    frames: list[Frame] = dataclasses.field(default_factory=list)
    rows: list[tuple] = dataclasses.field(default_factory=list)
    compare_rows: list[tuple] = dataclasses.field(default_factory=list)
    valves: tuple[list, list] = dataclasses.field(default_factory=lambda: ([], []))  # changes, per joint

    def add(self, frame: Frame, row: tuple, compare_row: tuple | None = None) -> None:
        self.frames.append(frame)
        self.rows.append(row)
        if compare_row is not None:
            self.compare_rows.append(compare_row)
        if len(self.frames) > MAX_RECORDED_FRAMES:
            del self.frames[0], self.rows[0]
            if self.compare_rows:
                del self.compare_rows[0]
            for changes in self.valves:
                while len(changes) > 1 and changes[1][0] <= self.rows[0][0]:
                    del changes[0]

    def trace_rows(self, *, compare: bool = False) -> TraceRows:
        rows = self.compare_rows if compare else self.rows
        columns = np.array(rows, dtype=float).reshape(-1, 7).T  # each row holds the seven columns
        time_, angle, desired, duty, pa, pb, supply = columns
        start = time_[0] if len(time_) else 0.0
        changes = [[max(t - start, 0.0), is_open] for t, is_open in self.valves[1 if compare else 0]]
        return TraceRows(time=time_ - start, angle=angle, desired_angle=desired, duty=duty, pressure_a=pa,
                         pressure_b=pb, supply_pressure=supply, valve_changes=changes)


def _row(r: Readout) -> tuple:
    return (r.time, r.angle, r.desired_angle, r.duty, r.pressure_a, r.pressure_b, r.supply_pressure)


def _edge_units(r: Readout) -> dict[str, float]:
    """A readout's numbers as the page shows them (degrees, %, kPa), named as :attr:`_Samples.FIELDS`."""
    return {"time": r.time, "angle_deg": math.degrees(r.angle), "desired_deg": math.degrees(r.desired_angle),
            "error_deg": math.degrees(r.error), "duty": r.duty, "pressure_a_kpa": r.pressure_a / 1e3,
            "pressure_b_kpa": r.pressure_b / 1e3, "supply_kpa": r.supply_pressure / 1e3}


class _Samples:
    """One joint's traces since the page's last frame, for its strip charts: every ``SAMPLE_TICKS``
    ticks a sample (degrees, %, kPa), and the valves' every change (tick exact: a 1 ms pulse shows)."""

    FIELDS = ("time", "angle_deg", "desired_deg", "error_deg", "duty", "pressure_a_kpa", "pressure_b_kpa",
              "supply_kpa")

    def __init__(self) -> None:
        self.columns: dict[str, list[float]] = {name: [] for name in self.FIELDS}
        self.valves: list[list] = []  # [time (s), [V1..V4 open]] at each change
        self.last_open = b""

    def take(self, joint: LiveJoint) -> None:
        for name, value in _edge_units(joint.readout()).items():
            self.columns[name].append(round(value, 4))

    def watch_valves(self, joint: LiveJoint) -> list | None:
        """The change ``[time, [V1..V4]]`` if the valves changed since the last call, else None."""
        is_open = joint.plant.conductance[0] > 0
        packed = is_open.tobytes()
        if packed == self.last_open:
            return None
        self.last_open = packed
        change = [round(joint.time, 4), [bool(x) for x in is_open]]
        self.valves.append(change)
        return change

    def drain(self) -> dict:
        taken = {**self.columns, "valves": self.valves}
        self.columns = {name: [] for name in self.FIELDS}
        self.valves = []
        return taken


class LiveSession:
    """What one ``twin view`` shows: :class:`LiveJoints` (one joint, or two in compare mode), their
    scene, the samples for the page's plots, and the page's commands."""

    def __init__(self, scenario: Scenario, *, record: bool = False, compare: Compare | None = None):
        self.record = record
        self.compare = compare
        self._rebuilt_at = -math.inf
        self._start(scenario)

    def _start(self, scenario: Scenario) -> None:
        self.joints = LiveJoints(scenario, self.compare)
        self.scenes = [JointScene(joint.joint, supply_pressure=joint.scenario.supply, root=root, tint=tint)
                       for joint, root, tint in zip(self.joints.joints, ("twin", COMPARE_ROOT), (None, COMPARE_TINT),
                                                    strict=False)]
        self.samples = [_Samples() for _ in self.joints.joints]
        self.recorder = _Recorder()
        self.runs: list[str] = []  # what the first joint ran since this model was built, in order: the recording's title
        self._note_run()
        self._debt = 0.0  # s of simulated time asked for but not yet a whole tick
        self.record_every = max(1, round(1.0 / (FPS * self.joint.tick)))
        self.sample_every = max(1, round(SAMPLE_PERIOD / self.joint.tick))
        self._sample()
        self._capture()

    @property
    def joint(self) -> LiveJoint:
        """The first joint."""
        return self.joints.first

    @property
    def scene(self) -> JointScene:
        return self.scenes[0]

    @property
    def scenario(self) -> Scenario:
        return self.joint.scenario

    def setup_commands(self) -> list[dict]:
        """The scene, and every body posed as now: the page fits its camera on the state that follows, which
        must see the bodies where they are (a joint on its side is turned by its pose, not by its scene)."""
        return [Delete(Path(("twin",))).lower(), Delete(Path((COMPARE_ROOT,))).lower(),
                *scene_commands(self.scenes), *frame_commands(self.frame())]

    def frame(self) -> Frame:
        """Every joint's picture as one frame."""
        pictures = []
        for joint, scene in zip(self.joints.joints, self.scenes, strict=True):
            r = joint.readout()
            pictures.append(scene.frame(joint.data, desired_angle=r.desired_angle,
                                        pressures=(r.pressure_a, r.pressure_b), valve_open=r.valve_open))
        return Frame.merged(pictures)

    def _capture(self) -> None:
        if self.record:
            second = self.joints.second
            self.recorder.add(self.frame(), _row(self.joint.readout()),
                              None if second is None else _row(second.readout()))

    def _sample(self) -> None:
        """Every joint's plotted sample now (after :meth:`_watch_valves`)."""
        self._watch_valves()
        for joint, samples in zip(self.joints.joints, self.samples, strict=True):
            samples.take(joint)

    def _watch_valves(self) -> None:
        """Every joint's valve change at this tick, for the plots and the recording."""
        for i, (joint, samples) in enumerate(zip(self.joints.joints, self.samples, strict=True)):
            change = samples.watch_valves(joint)
            if change is not None and self.record:
                self.recorder.valves[i].append(change)

    def advance(self, duration: float) -> None:
        """Step ``duration`` seconds; the fraction of a tick left over is carried to the next call.
        Raises SimulationFailed on a MuJoCo warning or a non-finite state."""
        self._debt += duration
        ticks = int(self._debt / self.joint.tick + 1e-9)
        self._debt -= ticks * self.joint.tick
        for _ in range(ticks):
            self.joints.step()
            steps = self.joint.steps
            if steps % self.sample_every == 0:
                self._sample()
            else:
                self._watch_valves()
            if steps % self.record_every == 0:
                self._capture()
        for joint in self.joints.joints:
            data = joint.data
            warned = [mujoco.mjtWarning(i).name for i, w in enumerate(data.warning) if w.number > 0]
            if warned or not np.all(np.isfinite(data.qpos)):
                which = "" if joint is self.joint else " (compare joint)"
                raise SimulationFailed(f"MuJoCo {', '.join(warned) or 'state not finite'} at "
                                       f"t = {joint.time:.3f} s{which}")

    def _note_run(self) -> None:
        """Add what the first joint runs now (its controller and plan) to :attr:`runs`, unless it is the last."""
        run = f"{self.scenario.controller} {self._playing()}"
        if not self.runs or self.runs[-1] != run:
            self.runs.append(run)

    def handle(self, text: str | bytes) -> bool:
        """Apply one message from the page; True if the model was rebuilt. Raises BadMessage."""
        command = live_messages.parse(text)
        if isinstance(command, live_messages.Target):
            self.joints.set_target(command.angle)
        elif isinstance(command, live_messages.PlayTrajectory):
            self.joints.play(command.number)
        elif isinstance(command, live_messages.SwitchController):
            self.joints.switch_controller(command.name)
        else:
            now = time.monotonic()
            if now - self._rebuilt_at < MIN_REBUILD_INTERVAL:
                raise live_messages.BadMessage(f"the model was rebuilt {now - self._rebuilt_at:.1f} s ago: "
                                               f"wait {MIN_REBUILD_INTERVAL:g} s between payload/orientation changes")
            changes = {k: v for k, v in dataclasses.asdict(command).items() if v is not None}
            self._start(dataclasses.replace(self.scenario, **changes))
            self._rebuilt_at = now
            return True
        self._note_run()
        return False

    def play(self, number: int) -> None:
        """Replay trajectory ``number`` on every joint (as the page's T buttons do)."""
        self.joints.play(number)
        self._note_run()

    def readout(self) -> dict:
        """The first joint's readout now (and the second's angle), with every joint's samples since
        the last call."""
        r = self.joint.readout()
        message = {"type": "readout", **_edge_units(r), "valves": list(r.valve_open),
                   "samples": [samples.drain() for samples in self.samples]}
        second = self.joints.second
        if second is not None:
            c = second.readout()
            message.update(compare_angle_deg=math.degrees(c.angle), compare_duty=c.duty)
        return message

    def _playing(self) -> str:
        """What the joints' plan is: a trajectory's replay, or a hold at a target."""
        plan = self.joint.plan
        return f"T{plan.number}" if plan.number else f"target {math.degrees(self.joints.target()):.0f} deg"

    def state(self) -> dict:
        s = self.scenario
        target = math.degrees(self.joints.target())
        state = {"type": "state", "controller": s.controller, "trajectory": s.trajectory, "playing": self._playing(),
                 "target_deg": round(target, 6), "payload_g": s.payload * 1e3, "orientation": s.orientation.value,
                 "plant": s.plant_name, "supply_kpa": s.supply / 1e3, "compare": None}
        second = self.joints.second
        if second is not None:
            c = second.scenario
            state["compare"] = {"settings": dict(self.compare.text), "controller": c.controller,
                                "payload_g": c.payload * 1e3, "orientation": c.orientation.value,
                                "plant": c.plant_name, "supply_kpa": c.supply / 1e3}
        return state

    def write_html(self, path: pathlib.Path) -> None:
        """The current model's run as a recording at ``path`` (``twin view`` stages it, so that it is
        written whole or not at all)."""
        rows = [self.recorder.trace_rows()]
        if self.joints.second is not None:
            rows.append(self.recorder.trace_rows(compare=True))
        s = self.scenario
        runs = ("" if len(self.runs) <= MAX_TITLED_RUNS else "... ") + ", then ".join(self.runs[-MAX_TITLED_RUNS:])
        title = f"live: {runs}; {s.payload * 1e3:g} g {s.orientation.value} ({s.plant_name}, seed {s.seed})"
        if self.compare is not None:
            title += f" vs {compare_label(self.compare.text)}"
        write_page(path, scenes=self.scenes, frames=self.recorder.frames, rows=rows, title=title)


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
    try:
        return urllib.parse.urlsplit("//" + handler.request.host).hostname in LOOPBACK_HOSTS
    except ValueError:  # a Host that is no host ("[::1"): not addressed to loopback
        return False


class _PageHandler(tornado.web.RequestHandler):
    def initialize(self, viewer: LiveViewer) -> None:
        self.viewer = viewer

    def get(self) -> None:
        if not _host_allowed(self, self.viewer):
            raise tornado.web.HTTPError(403)
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.write(PAGE.read_text())


class _ScriptHandler(tornado.web.RequestHandler):
    def initialize(self, script) -> None:
        self.script = script

    def get(self) -> None:
        self.set_header("Content-Type", "application/javascript")
        self.write(self.script.read_bytes())


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
        if not self.viewer.greeted:  # the first page sees the joint move: replay T1 for it
            self.viewer.greeted = True
            self.viewer.session.play(REPLAY_ON_CONNECT)  # its state goes with the setup below
        for message in [*_packed(self.viewer.session.setup_commands()), json.dumps(self.viewer.session.state())]:
            _send(self, message)

    def on_message(self, message: str | bytes) -> None:
        self.viewer.receive(self, message)

    def on_close(self) -> None:
        self.viewer.clients.discard(self)


class LiveViewer:
    """The server and the clock; ``start()`` serves until :meth:`stop` or Ctrl-C."""

    def __init__(self, session: LiveSession, *, host: str = "127.0.0.1", port: int = 7000, speed: float = 1.0):
        self.session, self.speed = session, speed
        self.clients: set[_SocketHandler] = set()
        app = tornado.web.Application([
            (r"/", _PageHandler, {"viewer": self}), (r"/meshcat.js", _ScriptHandler, {"script": MESHCAT_SCRIPT}),
            (r"/strip_chart.js", _ScriptHandler, {"script": STRIP_CHART_SCRIPT}),
            (r"/ws", _SocketHandler, {"viewer": self}),
        ], log_function=lambda handler: None, websocket_max_message_size=MAX_MESSAGE_BYTES)
        self.failure: str | None = None
        self.greeted = False  # a page has connected
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
        readout = json.dumps(self.session.readout())  # drains the samples, shown or not
        if self.clients:
            self.broadcast([*_packed(frame_commands(self.session.frame())), readout], droppable=True)

    def start(self, *, stop_after: float | None = None) -> None:
        """Serve until :meth:`stop`, :meth:`shutdown`, ``stop_after`` seconds (then a shutdown, whether
        the simulation still runs or has failed), or (on the main thread) SIGINT/SIGTERM, which
        shut down: the pages are told that the twin stopped before their sockets close."""
        self.server.add_sockets(self.sockets)
        self._last = time.perf_counter()
        self.loop = tornado.ioloop.IOLoop.current()
        self.clock = tornado.ioloop.PeriodicCallback(self._tick, 1000.0 / FRAME_RATE)
        self.clock.start()
        if stop_after is not None:
            self.loop.call_later(stop_after, self.shutdown)
        previous = {}
        if threading.current_thread() is threading.main_thread():
            for number in (signal.SIGINT, signal.SIGTERM):
                previous[number] = signal.signal(
                    number, lambda *_: self.loop.asyncio_loop.call_soon_threadsafe(self.shutdown))
        try:
            self.loop.start()
        finally:
            for number, handler in previous.items():
                signal.signal(number, handler)

    def shutdown(self) -> None:
        """Tell every page that the twin stopped (not a lost connection), then stop."""
        self.clock.stop()
        self.broadcast([json.dumps({"type": "stopped", "message": "the twin stopped"})])
        self.loop.call_later(STOP_GRACE, self.stop)

    def stop(self) -> None:
        self.clock.stop()
        self.server.stop()
        for client in list(self.clients):
            client.close()
        self.loop.stop()
