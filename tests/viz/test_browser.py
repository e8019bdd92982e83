"""The viewer in a real browser: Debian's chromium driven by Python playwright.

Skips, with its reason, only when chromium is absent; with
``TWIN_REQUIRE_BROWSER=1`` (set by ``.ci/run``) a missing browser fails
instead. Screenshots go to ``artifacts/`` at the repository root.
"""

from __future__ import annotations

import csv
import math
import os
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from conftest import listening_addresses

ROOT = pathlib.Path(__file__).resolve().parents[2]
ARTIFACTS = ROOT / "artifacts"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-quic",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
R_SPUR = 9.525e-3 / 2  # m
R_PINION = 3.71e-3 / 2  # m

if CHROMIUM is None:
    if os.environ.get("TWIN_REQUIRE_BROWSER") == "1":
        raise RuntimeError("TWIN_REQUIRE_BROWSER=1 but chromium is not installed (apt-get install chromium)")
    pytest.skip("chromium is not installed (apt-get install chromium): browser tests skipped",
                allow_module_level=True)

from playwright.sync_api import sync_playwright  # noqa: E402


def twin_env() -> dict:
    return dict(os.environ, PYTHONPATH=str(ROOT), PYTHONIOENCODING="utf-8", MPLBACKEND="Agg")


@pytest.fixture(scope="module")
def browser():
    with sync_playwright() as p:
        launched = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        yield launched
        launched.close()


@pytest.fixture
def page(browser):
    opened = browser.new_page(viewport={"width": 1400, "height": 800})
    errors: list[str] = []
    opened.on("pageerror", lambda error: errors.append(str(error)))
    yield opened
    opened.close()
    assert not errors, f"errors in the page: {errors}"


def screenshot(page, name: str) -> np.ndarray:
    """Save a screenshot as an artefact; the 3D pane's pixels as an (h, w, 3) array."""
    from PIL import Image

    ARTIFACTS.mkdir(exist_ok=True)
    path = ARTIFACTS / name
    page.screenshot(path=str(path))
    box = page.locator("#meshcat-pane").bounding_box()
    image = np.asarray(Image.open(path).convert("RGB")).astype(int)
    return image[int(box["y"]):int(box["y"] + box["height"]), int(box["x"]):int(box["x"] + box["width"])]


def assert_scene_rendered(pixels: np.ndarray) -> None:
    """Not blank: the link's red and the gears' brass are on the screen."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    red = (r > 70) & (r > 2 * g) & (r > 2 * b)
    brass = (r > 90) & (g > 0.55 * r) & (b < 0.5 * g)
    assert red.sum() > 300, f"only {red.sum()} red pixels (link)"
    assert brass.sum() > 300, f"only {brass.sum()} brass pixels (gears, racks)"


def wait_for_animation(page) -> None:
    page.wait_for_function("window.viewer && viewer.animator.actions.length > 0", timeout=60_000)


def body_rotation(page, body: str) -> np.ndarray:
    """The 3x3 rotation of a body's node as three.js holds it (its ``matrix``, refreshed from its pose)."""
    elements = page.evaluate(f"(() => {{ const o = viewer.scene_tree.find(['twin', 'bodies', '{body}']).object; "
                             "o.updateMatrix(); return Array.from(o.matrix.elements); })()")
    return np.array(elements).reshape(4, 4).T[:3, :3]


def body_quaternion(page, path: list[str]) -> np.ndarray:
    q = page.evaluate(f"(() => {{ const q = viewer.scene_tree.find({path!r}).object.quaternion; "
                      "return [q.w, q.x, q.y, q.z]; })()")
    return np.array(q)


def turned(a: np.ndarray, b: np.ndarray) -> float:
    """Angle (deg) of the rotation from a to b."""
    relative = a.T @ b
    return math.degrees(math.acos(np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0)))


def quaternion_turn(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(2.0 * math.acos(min(1.0, abs(float(np.dot(a, b))))))


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_recording_plays_offline_and_moves_by_the_trace(tmp_path, page):
    html, trace = tmp_path / "out.html", tmp_path / "out.csv"
    proc = subprocess.run(
        [sys.executable, "-m", "twin", "run", "--controller", "ffpva", "--trajectory", "1", "--payload", "13.5",
         "--orientation", "vertical", "--html", str(html), "--trace", str(trace)],
        cwd=tmp_path, env=twin_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    with open(trace) as handle:
        rows = list(csv.DictReader(handle))

    page.route("**/*", lambda route: route.abort() if not route.request.url.startswith("file:") else route.continue_())
    page.goto(html.as_uri())
    wait_for_animation(page)
    poses = {}
    for t in (0.4, 0.6):
        page.evaluate(f"viewer.animator.pause(); viewer.animator.seek({t});")
        page.wait_for_timeout(400)  # a render, for the screenshot
        poses[t] = {body: body_rotation(page, body) for body in ("spur", "link", "pinion")}
        if t == 0.6:
            assert_scene_rendered(screenshot(page, "recording.png"))
    row = {t: rows[int(round(t * 1000))] for t in poses}
    assert float(row[0.4]["t_s"]) == pytest.approx(0.4)
    output = abs(float(row[0.6]["theta_deg"]) - float(row[0.4]["theta_deg"]))
    pinion = math.degrees(abs(float(row[0.6]["y_mm"]) - float(row[0.4]["y_mm"])) * 1e-3 / R_PINION)
    assert output > 30.0  # T1 is moving fast here
    assert pinion < 180.0  # a rotation's angle is only seen modulo a full turn
    assert turned(poses[0.4]["spur"], poses[0.6]["spur"]) == pytest.approx(output, abs=0.5)
    assert turned(poses[0.4]["link"], poses[0.6]["link"]) == pytest.approx(output, abs=0.5)
    assert turned(poses[0.4]["pinion"], poses[0.6]["pinion"]) == pytest.approx(pinion, abs=0.5)


@pytest.fixture
def live_twin():
    ARTIFACTS.mkdir(exist_ok=True)
    log = open(ARTIFACTS / "twin-view.stderr.txt", "w")  # read when a test fails; never a full pipe
    proc = subprocess.Popen(
        [sys.executable, "-m", "twin", "view", "--controller", "smc", "--trajectory", "4", "--port", "0",
         "--duration", "900"],
        cwd=ROOT, env=twin_env(), stdout=subprocess.PIPE, stderr=log, text=True)
    line = proc.stdout.readline()
    match = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
    assert match, f"no URL in {line!r}; stderr: {(ARTIFACTS / 'twin-view.stderr.txt').read_text()}"
    yield proc, match.group(0), int(match.group(1))
    if proc.poll() is None:
        proc.kill()
        proc.wait(10)
    log.close()


def readout(page) -> dict:
    return page.evaluate("window.twinLast")


def wait_until(page, condition, timeout: float = 180.0, what: str = "") -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        last = readout(page)
        if last is not None and condition(last):
            return last
        page.wait_for_timeout(200)
    raise AssertionError(f"timed out waiting for {what}; last readout {readout(page)}")


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_live_page_follows_the_slider_and_refuses_bad_messages(live_twin, page):
    proc, url, port = live_twin
    assert listening_addresses(port) == {"127.0.0.1"}
    page.goto(url)
    page.wait_for_function("window.twinLast !== null && window.twinState !== undefined", timeout=60_000)
    wait_until(page, lambda r: r["time"] > 6.3, what="T4 to finish (6 s)")
    link = ["twin", "bodies", "link"]
    before, angle_before = body_quaternion(page, link), readout(page)["angle_deg"]
    assert angle_before == pytest.approx(30.0, abs=1.5)
    assert_scene_rendered(screenshot(page, "live-start.png"))

    page.evaluate("const t = document.getElementById('target'); t.value = 120; t.dispatchEvent(new Event('input'));")
    started = readout(page)["time"]
    settled = wait_until(page, lambda r: r["time"] > started + 1.5 and abs(r["angle_deg"] - 120.0) < 1.0,
                         what="the joint to reach the slider's 120 deg")
    after = body_quaternion(page, link)
    angle_after = readout(page)["angle_deg"]
    assert settled["desired_deg"] == pytest.approx(120.0)
    assert quaternion_turn(before, after) == pytest.approx(angle_after - angle_before, abs=1.0)
    assert_scene_rendered(screenshot(page, "live-120deg.png"))

    for bad in ['{"type": "payload", "grams": 51}', "not json", '{"type": "target", "angle_deg": -5}',
                '{"type": "trajectory", "number": "T9"}']:
        page.evaluate(f"window.twinSocket.send({bad!r})")
    page.wait_for_function("window.twinErrors.length >= 4", timeout=10_000)
    assert page.evaluate("window.twinErrors") == [
        "payload: grams must be in [0, 50] g, got 51", "message is not JSON",
        "target: angle_deg must be in [0, 180] deg, got -5", "trajectory: number must be 1, 2, 3 or 4, got 'T9'"]
    assert "trajectory: number" in page.inner_text("#error")
    still = readout(page)["time"]
    wait_until(page, lambda r: r["time"] > still + 0.5, what="the simulation to keep running")

    page.evaluate("window.twinSend({type: 'target', angle_deg: 90, note: 'x'.repeat(5000)})")  # over 4 KiB
    assert page.evaluate("window.twinErrors").pop().startswith("not sent: message too long")
    page.evaluate("window.twinSocket.close()")  # a dropped connection, the twin still running
    page.wait_for_function("document.getElementById('state').textContent.startsWith('connection lost')",
                           timeout=5_000)
    page.wait_for_function("window.twinSocket.readyState === WebSocket.OPEN", timeout=15_000)
    back = readout(page)["time"]
    wait_until(page, lambda r: r["time"] > back + 0.5, what="readouts again after reconnecting")

    page.select_option("#orientation", "vertical")  # rebuild and restart
    page.wait_for_function("window.twinState.orientation === 'vertical'", timeout=30_000)
    wait_until(page, lambda r: r["time"] < 2.0, what="the restarted run")
    page.click("text=T1")
    wait_until(page, lambda r: r["desired_deg"] > 100.0, what="T1's replay to rise")
    assert_scene_rendered(screenshot(page, "live-vertical.png"))

    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert "twin view: stopped" in out
