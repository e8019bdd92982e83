"""The viewer in a real browser: Debian's chromium driven by Python playwright.

Skips, with its reason, only when chromium is absent; with
``TWIN_REQUIRE_BROWSER=1`` (set by ``.ci/run``) a missing browser fails
instead. Screenshots go to ``artifacts/`` at the repository root; with
``TWIN_RETAKE_DOCS=1`` two of them also replace the docs' pictures
(``docs/viewer.png``, ``docs/viewer-compare.png``), so a test run leaves the
tracked files alone unless asked.
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


def retake_doc_picture(name: str, doc: str) -> None:
    """Copy artefact ``name`` over ``docs/<doc>`` when ``TWIN_RETAKE_DOCS=1``; otherwise leave the docs as they are."""
    if os.environ.get("TWIN_RETAKE_DOCS") == "1":
        shutil.copy(ARTIFACTS / name, ROOT / "docs" / doc)


def screenshot(page, name: str) -> np.ndarray:
    """Save a screenshot as an artefact; the 3D pane's pixels as an (h, w, 3) array."""
    from PIL import Image

    ARTIFACTS.mkdir(exist_ok=True)
    path = ARTIFACTS / name
    page.screenshot(path=str(path))
    box = page.locator("#meshcat-pane").bounding_box()
    image = np.asarray(Image.open(path).convert("RGB")).astype(int)
    return image[int(box["y"]):int(box["y"] + box["height"]), int(box["x"]):int(box["x"] + box["width"])]


def assert_scene_rendered(pixels: np.ndarray, least: int = 300) -> None:
    """Not blank: the link's red and the gears' brass are on the screen (``least`` pixels of each)."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    red = (r > 70) & (r > 2 * g) & (r > 2 * b)
    brass = (r > 90) & (g > 0.55 * r) & (b < 0.5 * g)
    assert red.sum() > least, f"only {red.sum()} red pixels (link)"
    assert brass.sum() > least, f"only {brass.sum()} brass pixels (gears, racks)"


def wait_for_animation(page) -> None:
    page.wait_for_function("window.viewer && viewer.animator.actions.length > 0", timeout=60_000)


def body_rotation(page, body: str, root: str = "twin") -> np.ndarray:
    """The 3x3 rotation of a body's node as three.js holds it (its ``matrix``, refreshed from its pose)."""
    elements = page.evaluate(f"(() => {{ const o = viewer.scene_tree.find(['{root}', 'bodies', '{body}']).object; "
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


def chart_pixels(page, chart: str, rgb: tuple[int, int, int], tolerance: int = 40) -> int:
    """How many pixels of strip chart ``chart``'s canvas are within ``tolerance`` of colour ``rgb``."""
    return page.evaluate(f"""(() => {{
        const c = document.querySelector('canvas[data-chart="{chart}"]');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4)
            if (Math.abs(d[i] - {rgb[0]}) + Math.abs(d[i + 1] - {rgb[1]}) + Math.abs(d[i + 2] - {rgb[2]}) < {tolerance}) n++;
        return n; }})()""")


def cursor_column(page, chart: str) -> float:
    """The CSS x (from the canvas's left) of the chart's red cursor: the column with most cursor-red pixels."""
    return page.evaluate(f"""(() => {{
        const c = document.querySelector('canvas[data-chart="{chart}"]');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        const counts = new Array(c.width).fill(0);
        for (let i = 0; i < d.length; i += 4)
            if (d[i] > 180 && d[i + 1] < 60 && d[i + 2] < 60) counts[(i / 4) % c.width]++;
        const best = counts.indexOf(Math.max(...counts));
        return best / (c.width / c.clientWidth); }})()""")


TEAL = (18, 165, 176)  # the compare joint's trace colour (viz/strip_chart.js TWIN_COMPARE_TINT)
ANGLE_RED = (192, 57, 43)  # the first joint's angle trace


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_recording_controls_seek_the_view_and_the_cursor_together(tmp_path, page):
    html, trace = tmp_path / "out.html", tmp_path / "out.csv"
    proc = subprocess.run(
        [sys.executable, "-m", "twin", "run", "--controller", "ffpva", "--trajectory", "1", "--payload", "13.5",
         "--orientation", "vertical", "--html", str(html), "--trace", str(trace), "--compare", "controller=smc"],
        cwd=tmp_path, env=twin_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    with open(trace) as handle:
        rows = list(csv.DictReader(handle))

    page.route("**/*", lambda route: route.abort() if not route.request.url.startswith("file:") else route.continue_())
    page.clock.install()  # the page's clock flows with the wall clock until the speed check below stops it
    page.goto(html.as_uri())
    wait_for_animation(page)
    page.wait_for_function("window.twinPlots && window.twinPlots.draws > 2", timeout=30_000)
    # the camera frames both joints, the first on its side: fitted before the first pose it cut the mechanism off
    # (its view box reached 1.36 of the half-height, found 2026-11-27)
    assert_fills(view_fit(page))
    page.click("#play")  # the page's own pause
    assert page.evaluate("window.twinClock.playing") is False
    poses, cursors = {}, {}
    for t in (0.4, 0.6):
        page.evaluate(f"const s = document.getElementById('scrub'); s.value = {t}; s.dispatchEvent(new Event('input'));")
        page.wait_for_timeout(500)  # renders, for the screenshot and the chart
        assert page.evaluate("window.twinClock.time") == pytest.approx(t, abs=1e-3)
        poses[t] = {body: body_rotation(page, body) for body in ("spur", "link", "pinion")}
        cursors[t] = cursor_column(page, "angle")
        assert cursors[t] == pytest.approx(page.evaluate(f"window.twinPlots.xOf('angle', {t})"), abs=2.0)
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
    width = page.evaluate("document.querySelector('canvas[data-chart=\"angle\"]').clientWidth")
    duration = page.evaluate("window.twinTrace.time[window.twinTrace.time.length - 1]")
    assert cursors[0.6] - cursors[0.4] == pytest.approx(0.2 / duration * (width - 48), abs=2.5)  # plot width: 48 px of axes
    # compare mode: the second joint is drawn and its traces overlaid
    assert page.evaluate("window.twinTraces.length") == 2
    assert chart_pixels(page, "angle", TEAL) > 100 and chart_pixels(page, "angle", ANGLE_RED) > 30  # mostly under the teal
    compare_link = body_rotation(page, "link", root="compare")
    assert turned(compare_link, poses[0.6]["link"]) < 20.0  # same trajectory, another controller
    # speed: the player advances its clock by the frame's time times the speed (at most 0.1 s a frame). On the
    # wall clock this was a band (1x over 0.5x within 1.4-4.0: a loaded CI machine once stalled a second); with
    # Playwright's clock stopped and run for one second of frames it is exact.
    page.clock.pause_at(page.evaluate("Date.now()") + 1000)

    def played(speed: str) -> float:
        """Recording seconds played in one second of the page's frames, from the start, at ``speed``."""
        page.select_option("#speed", speed)
        page.evaluate("const s = document.getElementById('scrub'); s.value = 0; s.dispatchEvent(new Event('input'));")
        if not page.evaluate("window.twinClock.playing"):
            page.click("#play")
        assert page.evaluate("window.twinClock.playing") is True
        page.clock.run_for(100)  # a frame or more from a standstill: the first one's step is capped, not measured
        start = page.evaluate("window.twinClock.time")
        page.clock.run_for(1000)
        return page.evaluate("window.twinClock.time") - start

    assert played("1") == pytest.approx(1.0, abs=0.02)  # a frame's worth at most: the last may not have run
    assert played("0.5") == pytest.approx(0.5, abs=0.02)
    page.clock.resume()


def start_twin(*flags: str):
    ARTIFACTS.mkdir(exist_ok=True)
    log = open(ARTIFACTS / "twin-view.stderr.txt", "w")  # read when a test fails; never a full pipe
    proc = subprocess.Popen([sys.executable, "-m", "twin", "view", "--port", "0", "--duration", "900", *flags],
                            cwd=ROOT, env=twin_env(), stdout=subprocess.PIPE, stderr=log, text=True)
    line = proc.stdout.readline()
    match = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
    assert match, f"no URL in {line!r}; stderr: {(ARTIFACTS / 'twin-view.stderr.txt').read_text()}"
    return proc, log, match.group(0), int(match.group(1))


@pytest.fixture
def live_twin():
    proc, log, url, port = start_twin("--controller", "smc", "--trajectory", "4")
    yield proc, url, port
    if proc.poll() is None:
        proc.kill()
        proc.wait(10)
    log.close()


@pytest.fixture
def compare_twin():
    proc, log, url, port = start_twin("--controller", "ffpva", "--trajectory", "1",
                                      "--compare", "controller=smc,payload=13.5")
    yield proc, url, port
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


def slider(page) -> float:
    return float(page.evaluate("document.getElementById('target').value"))


def view_fit(page) -> dict:
    """Where the joints' view boxes fall in the 3D canvas (normalised device coordinates, -1..1) and
    the canvas's and pane's sizes."""
    return page.evaluate("""(() => {
        const boxes = twinViewBoxes(viewer);
        const xs = [], ys = [];
        for (const b of boxes) for (const x of [b.min.x, b.max.x]) for (const y of [b.min.y, b.max.y])
            for (const z of [b.min.z, b.max.z]) {
                const p = new MeshCat.THREE.Vector3(x, y, z).project(viewer.camera); xs.push(p.x); ys.push(p.y); }
        const pane = document.getElementById('meshcat-pane').getBoundingClientRect();
        const canvas = viewer.renderer.domElement.getBoundingClientRect();
        const panel = (document.getElementById('panel') || document.body).getBoundingClientRect();  // none in a recording
        return {boxes: boxes.length, x: [Math.min(...xs), Math.max(...xs)], y: [Math.min(...ys), Math.max(...ys)],
                pane: [pane.width, pane.height], canvas: [canvas.width, canvas.height], panel: panel.width}; })()""")


def assert_fills(fit: dict) -> None:
    """Every corner of the view boxes inside the canvas, and the boxes filling most of one direction."""
    assert fit["boxes"] >= 1
    assert -1.0 <= fit["x"][0] and fit["x"][1] <= 1.0 and -1.0 <= fit["y"][0] and fit["y"][1] <= 1.0, fit
    assert max(fit["x"][1] - fit["x"][0], fit["y"][1] - fit["y"][0]) > 1.7, fit  # over 85 % of the width or height
    assert fit["canvas"][0] == pytest.approx(fit["pane"][0], abs=1) and fit["canvas"][1] == pytest.approx(fit["pane"][1], abs=1)


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_live_page_plots_follows_the_server_and_reflows(live_twin, browser, page):
    proc, url, port = live_twin
    assert listening_addresses(port) == {"127.0.0.1"}
    page.set_viewport_size({"width": 1280, "height": 720})
    page.goto(url)
    page.wait_for_function("window.twinLast !== null && window.twinState !== undefined", timeout=60_000)
    # the first page to connect replays T1 (the twin was started on T4): the joint moves on open. Its move
    # lasts 1 s, so it is read from every sample the page received (its charts' last 5 s), not from the last
    # readout: on 2026-11-26's slower machine the page handled readouts in bursts, 3-4 a second, and a poll of
    # the last one saw only the move's end
    page.wait_for_function("(() => { const d = window.twinTraces[0].data; return d.time.some((t, i) => "
                           "Math.abs(d.desired_deg[i] - d.angle_deg[i]) < 5 && d.desired_deg[i] > 40 "
                           "&& d.desired_deg[i] < 140); })()", timeout=60_000)
    assert page.evaluate("window.twinState.playing") == "T1"
    assert page.evaluate("window.twinState.target_deg") == pytest.approx(150.0)

    # the plots update as the joint moves: they redraw, and the pixels change. (The bar was 20 redraws a
    # second, then 5; on 2026-11-26's machine, loaded by other jobs, CI saw 4.2. How fast the page draws is a
    # matter for a benchmark, not for this test: a few more redraws say "updating", however long they take.)
    before = page.evaluate("window.twinPlots.draws")
    image = page.evaluate("document.querySelector('canvas[data-chart=\"angle\"]').toDataURL()")
    page.wait_for_timeout(2000)  # two seconds of the twin's motion for the pixels to change over
    page.wait_for_function(f"window.twinPlots.draws >= {before + 3}", timeout=30_000)  # however slowly it draws
    assert page.evaluate("document.querySelector('canvas[data-chart=\"angle\"]').toDataURL()") != image
    for chart, colour in (("angle", ANGLE_RED), ("duty", (36, 113, 163)), ("pressure", (211, 84, 0)),
                          ("valves", (44, 160, 44))):
        assert chart_pixels(page, chart, colour) > 20, chart
    assert_fills(view_fit(page))

    # after the T1 replay the slider shows the current target, here and in a second tab
    wait_until(page, lambda r: r["time"] > 4.0 and abs(r["angle_deg"] - 150.0) < 1.5, what="T1 to end at 150 deg")
    assert slider(page) == 150.0
    other = browser.new_page(viewport={"width": 800, "height": 600})
    other.goto(url)
    other.wait_for_function("window.twinState !== undefined && window.twinLast !== null", timeout=60_000)
    assert slider(other) == 150.0
    link = ["twin", "bodies", "link"]
    before, angle_before = body_quaternion(page, link), readout(page)["angle_deg"]
    other.evaluate("const t = document.getElementById('target'); t.value = 120; t.dispatchEvent(new Event('input'));")
    page.wait_for_function("window.twinState.target_deg === 120", timeout=10_000)
    assert slider(page) == 120.0
    started = readout(page)["time"]
    settled = wait_until(page, lambda r: r["time"] > started + 1.5 and abs(r["angle_deg"] - 120.0) < 1.0,
                         what="the joint to reach the slider's 120 deg")
    assert settled["desired_deg"] == pytest.approx(120.0)
    after = body_quaternion(page, link)
    assert quaternion_turn(before, after) == pytest.approx(abs(readout(page)["angle_deg"] - angle_before), abs=1.0)
    other.close()
    page.wait_for_timeout(300)
    pixels = screenshot(page, "live-120deg.png")
    assert_scene_rendered(pixels, least=200)  # about 480 brass pixels seen here: half, against pose and driver
    retake_doc_picture("live-120deg.png", "viewer.png")  # the docs' picture, 1280x720

    # 800x600 after a resize: the panel stays usable and the 3D view still shows the whole mechanism
    page.set_viewport_size({"width": 800, "height": 600})
    page.wait_for_timeout(600)
    fit = view_fit(page)
    assert fit["panel"] >= 240
    assert_fills(fit)
    assert_scene_rendered(screenshot(page, "live-800x600.png"), least=80)  # a smaller view (about 180 brass pixels seen)
    assert page.evaluate("document.querySelector('canvas[data-chart=\"angle\"]').clientWidth") > 150

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
    assert page.evaluate("window.twinConnection") == "lost"
    page.wait_for_function("window.twinSocket.readyState === WebSocket.OPEN", timeout=15_000)
    back = readout(page)["time"]
    wait_until(page, lambda r: r["time"] > back + 0.5, what="readouts again after reconnecting")
    assert page.evaluate("window.twinState.playing") == "target 120 deg"  # a reconnect replays nothing

    page.select_option("#orientation", "vertical")  # rebuild and restart
    page.wait_for_function("window.twinState.orientation === 'vertical'", timeout=30_000)
    wait_until(page, lambda r: r["time"] < 2.0, what="the restarted run")
    page.click("text=T1")
    wait_until(page, lambda r: r["desired_deg"] > 100.0, what="T1's replay to rise")
    page.wait_for_timeout(600)
    assert_fills(view_fit(page))
    # 800x600, the gears seen edge-on. Where the screenshot falls in the replay depends on the machine's speed: 59
    # brass pixels with the link at 131 deg over the gears (stop 55's CI run, which failed the bar of 60 then) and
    # 78 with it at 30 deg (a run after it). Half the lowest seen, as above; a blank or unlit scene has none.
    assert_scene_rendered(screenshot(page, "live-vertical.png"), least=30)

    proc.send_signal(signal.SIGINT)  # the twin stops: the page says so (not "connection lost")
    page.wait_for_function("window.twinConnection === 'stopped'", timeout=10_000)
    assert "the twin stopped" in page.inner_text("#state")
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert "twin view: stopped" in out


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_compare_mode_draws_two_joints_and_two_traces(compare_twin, page):
    proc, url, port = compare_twin
    page.set_viewport_size({"width": 1280, "height": 720})
    page.goto(url)
    page.wait_for_function("window.twinLast !== null && window.twinState !== undefined", timeout=60_000)
    state = page.evaluate("window.twinState")
    assert state["compare"]["settings"] == {"controller": "smc", "payload": "13.5"}
    assert state["compare"]["controller"] == "smc" and state["compare"]["payload_g"] == pytest.approx(13.5)
    assert state["controller"] == "ffpva" and state["payload_g"] == 0
    wait_until(page, lambda r: r["time"] > 3.0 and r["desired_deg"] > 100, what="T1 replayed on both")
    last = readout(page)
    assert last["compare_angle_deg"] == pytest.approx(last["angle_deg"], abs=10.0)  # same targets, same time
    # two joints: the second's link turned by its own angle, beside the first
    first = np.array(page.evaluate("viewer.scene_tree.find(['twin']).object.position.toArray()"))
    second = np.array(page.evaluate("viewer.scene_tree.find(['compare']).object.position.toArray()"))
    assert np.linalg.norm(first - second) > 0.5  # drawn 10x: over 50 mm apart
    wait_until(page, lambda r: r["time"] > 4.5, what="T1 to end")
    page.wait_for_timeout(400)
    last = readout(page)
    link = body_rotation(page, "link")
    compare_link = body_rotation(page, "link", root="compare")
    rest = body_rotation(page, "housing")  # the link's angle is measured from the housing frame
    assert turned(rest, link) == pytest.approx(abs(last["angle_deg"]), abs=2.0)
    assert turned(rest, compare_link) == pytest.approx(abs(last["compare_angle_deg"]), abs=2.0)
    assert_fills(view_fit(page))
    assert view_fit(page)["boxes"] == 2
    pixels = screenshot(page, "live-compare.png")
    # only the first joint is brass (the second is tinted teal) and each is drawn at about half the size of a
    # single joint's view: ~300-330 brass pixels, where a blank view has none (CI once saw 297 against 300)
    assert_scene_rendered(pixels, least=150)
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    teal = (g > 110) & (b > 110) & (r < 0.6 * g)
    assert teal.sum() > 300, f"only {teal.sum()} teal pixels (the compare joint)"
    retake_doc_picture("live-compare.png", "viewer-compare.png")
    # two traces in every line chart, with a legend naming the second
    for chart in ("angle", "error", "duty", "pressure", "valves"):
        assert chart_pixels(page, chart, TEAL) > 20, chart
    assert page.evaluate("window.twinPlots.labels") == ["ffpva", "compare"]
    assert "controller=smc, payload=13.5" in page.inner_text("#compare-info")


@pytest.mark.slow  # a live twin and a page: about 10 s on 2 cores
def test_a_live_joint_on_its_side_beside_another_is_framed_and_its_charts_read(page):
    """The camera is fitted on the state after the setup, which now poses the bodies: fitted unposed, a joint on
    its side beside another was cut off (found 2026-11-27). A short chart gets at least two labelled ticks."""
    proc, log, url, port = start_twin("--controller", "smc", "--trajectory", "1", "--orientation", "vertical",
                                      "--compare", "controller=pva")
    try:
        page.set_viewport_size({"width": 1280, "height": 720})
        page.goto(url)
        page.wait_for_function("window.twinLast !== null && window.twinState !== undefined", timeout=60_000)
        page.wait_for_timeout(500)  # a few frames: the fit must hold once the joints move, not only at the start
        assert_fills(view_fit(page))
        for lo, hi, count in ((14.0, 166.0, 2), (-1.2, 1.2, 2), (0.0, 330.0, 2), (0.0, 1.0, 5)):
            ticks = page.evaluate(f"window.twinPlots._ticks({lo}, {hi}, {count})")
            assert len(ticks) >= 2 and all(lo - 1e-9 <= t <= hi + 1e-9 for t in ticks), (lo, hi, ticks)
    finally:
        proc.kill()
        proc.wait(10)
        log.close()


@pytest.mark.slow  # a live twin and a page: about 10 s on 2 cores
def test_arrow_keys_on_the_target_slider_lose_no_step_and_meshcats_menu_stays_off_the_controls(live_twin, page):
    """Found by a helper in chromium (stop 40). Arrow keys on the slider lost steps: the twin's echo of an
    older step put the slider back, and the next step started from there (40 steps up from 90 ended at 118).
    meshcat's "Open Controls" menu sat at the page's top right, over the controller menu and the slider."""
    _, url, _ = live_twin
    page.set_viewport_size({"width": 1280, "height": 720})
    page.goto(url)
    page.wait_for_function("window.twinLast !== null && window.twinState !== undefined", timeout=60_000)
    page.evaluate("window.twinSend({type: 'target', angle_deg: 90})")
    page.wait_for_function("Math.round(window.twinState.target_deg) === 90", timeout=30_000)
    page.focus("#target")
    for _ in range(40):
        page.keyboard.press("ArrowRight")
        page.wait_for_timeout(20)
    page.wait_for_function("Math.round(window.twinState.target_deg) === 130", timeout=30_000)
    assert slider(page) == 130.0
    for _ in range(40):
        page.keyboard.press("ArrowLeft")
        page.wait_for_timeout(20)
    page.wait_for_function("Math.round(window.twinState.target_deg) === 90", timeout=30_000)
    page.wait_for_timeout(1200)  # past the slider's wait for an echo: it follows the twin again, and agrees
    assert slider(page) == 90.0
    # meshcat's menu, opened, is inside the 3D pane and covers none of the controls
    page.click("text=Open Controls")
    page.wait_for_timeout(300)
    for control in ("#controller", "#target", "#payload", "#orientation"):
        hit = page.evaluate(f"""(() => {{ const r = document.querySelector('{control}').getBoundingClientRect();
            const el = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
            return el === document.querySelector('{control}') || document.querySelector('{control}').contains(el); }})()""")
        assert hit, f"{control} is covered"


@pytest.mark.slow  # a recording and a page: about 8 s on 2 cores
def test_space_plays_a_recording_after_the_scrub_bar_was_used(tmp_path, page):
    """The scrub bar keeps the focus after a drag, and Space then did nothing (a helper in chromium, stop 40)."""
    html = tmp_path / "out.html"
    proc = subprocess.run([sys.executable, "-m", "twin", "run", "--controller", "ffpva", "--trajectory", "4",
                           "--html", str(html)], cwd=tmp_path, env=twin_env(), capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    page.goto(html.as_uri())
    wait_for_animation(page)
    page.wait_for_function("window.twinClock.playing && window.twinClock.time > 0", timeout=30_000)
    page.click("#play")  # paused by the page's own button (T4 plays 6 s: it has not ended by now)
    assert page.evaluate("window.twinClock.playing") is False
    page.focus("#scrub")
    page.keyboard.press("Home")
    assert page.evaluate("document.activeElement.id") == "scrub"
    page.keyboard.press("Space")
    assert page.evaluate("window.twinClock.playing") is True
    page.keyboard.press("Space")
    assert page.evaluate("window.twinClock.playing") is False


def sight_to_axis_deg(page, root: str = "twin") -> float:
    """Angle (deg) between the camera's line of sight and the spur's axis (the normal of the plane the link turns
    in): 0 sees that plane face-on, 90 edge-on."""
    return page.evaluate(f"""(() => {{
        const spur = viewer.scene_tree.find(['{root}', 'bodies', 'spur']).object;
        spur.updateMatrixWorld(true);
        const axis = new MeshCat.THREE.Vector3().setFromMatrixColumn(spur.matrixWorld, 2).normalize();
        const sight = viewer.camera.getWorldDirection(new MeshCat.THREE.Vector3());
        return Math.acos(Math.min(1, Math.abs(axis.dot(sight)))) * 180 / Math.PI; }})()""")


@pytest.mark.slow  # a live twin, rebuilt once, and a page: about 15 s on 2 cores
def test_each_orientation_is_framed_as_it_stands(page):
    """A joint lying flat (horizontal) is seen from in front and above, its plane of rotation at a slant; one on its
    side (vertical) nearly face-on, gravity down the screen. Both were seen about 30 deg off face-on (35 and 26
    deg), the same picture (a helper in chromium, stop 40). Each fit keeps the mechanism's box in view."""
    proc, log, url, port = start_twin("--controller", "smc", "--trajectory", "1")
    try:
        page.set_viewport_size({"width": 1280, "height": 720})
        page.goto(url)
        page.wait_for_function("window.twinLast !== null && window.twinState !== undefined", timeout=60_000)
        page.wait_for_timeout(500)
        assert page.evaluate("window.twinState.orientation") == "horizontal"
        flat = sight_to_axis_deg(page)
        assert_fills(view_fit(page))
        page.select_option("#orientation", "vertical")  # rebuilt: the new scene sets the camera, the page fits it
        page.wait_for_function("window.twinState.orientation === 'vertical'", timeout=30_000)
        page.wait_for_timeout(800)
        upright = sight_to_axis_deg(page)
        assert_fills(view_fit(page))
        assert flat >= 40.0, flat  # at a slant (the scene's camera: 45 deg above the bench, 45 deg off face-on)
        assert upright <= 15.0, upright  # nearly face-on (10 deg above the joint's middle)
        assert_scene_rendered(screenshot(page, "live-vertical-framed.png"), least=100)
    finally:
        proc.kill()
        proc.wait(10)
        log.close()


def record(directory: pathlib.Path, *flags: str) -> pathlib.Path:
    """An ``--html`` recording of ``twin run`` with ``flags``."""
    html = directory / "run.html"
    proc = subprocess.run([sys.executable, "-m", "twin", "run", *flags, "--html", str(html)], cwd=directory,
                          env=twin_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return html


def open_recording(page, html: pathlib.Path) -> None:
    """Open a recording offline and pause it at 0.6 s."""
    page.route("**/*", lambda route: route.abort() if not route.request.url.startswith("file:") else route.continue_())
    page.goto(html.as_uri())
    wait_for_animation(page)
    page.wait_for_function("window.twinPlots && window.twinPlots.draws > 2", timeout=30_000)
    if page.evaluate("window.twinClock.playing"):
        page.click("#play")
    scrub_to(page, 0.6)


def scrub_to(page, t: float) -> None:
    page.evaluate(f"const s = document.getElementById('scrub'); s.value = {t}; s.dispatchEvent(new Event('input'));")
    page.wait_for_timeout(200)


COMPARE_B_TEAL = (11, 107, 115)  # the compare joint's chamber B (viz/strip_chart.js TWIN_COMPARE_DARK)


@pytest.mark.slow  # a compare recording and a page: about 10 s on 2 cores
def test_the_compare_joints_chambers_are_told_apart(tmp_path, page):
    """The second joint's chamber A and B pressures were both dashed teal, told apart only by where they ran (a
    helper in chromium, stop 40): B is now a darker teal, dash-dotted, and the legend names "compare A" and
    "compare B", and (stop 42) the supply's entry shows the second joint's dotted teal line beside the first's; a
    legend short of room still keeps the compare entries and the first series, dropping the first joint's later
    ones first."""
    html = record(tmp_path, "--controller", "ffpva", "--trajectory", "1", "--compare", "controller=smc,payload=13.5")
    open_recording(page, html)
    assert chart_pixels(page, "pressure", TEAL) > 20  # chamber A
    assert chart_pixels(page, "pressure", COMPARE_B_TEAL) > 20  # chamber B
    assert chart_pixels(page, "angle", COMPARE_B_TEAL) < 5  # the darker teal is chamber B's alone
    legends = dict(page.evaluate("window.twinPlots.charts.map((c) => [c.spec.id, c.legend])"))
    assert legends["pressure"] == ["chamber A", "chamber B", "supply", "compare A", "compare B"]
    both = dict(page.evaluate("""window.twinPlots.charts.map((c) => [c.spec.id,  // names drawn with two lines
        [...new Set((c.legendSwatches || []).map((s) => s[0]))].filter(
            (name) => c.legendSwatches.filter((s) => s[0] === name).length === 2)])"""))
    assert both["pressure"] == ["supply"] and not any(both[c] for c in ("angle", "error", "duty"))
    teal_in_swatch = page.evaluate("""(() => {  // teal pixels along the supply entry's second swatch
        const chart = window.twinPlots.charts.find((c) => c.spec.id === 'pressure'), c = chart.canvas;
        const ratio = c.width / c.clientWidth;
        const [, , x0, x1, y] = chart.legendSwatches.filter((s) => s[0] === 'supply')[1];
        const d = c.getContext('2d').getImageData(Math.floor(x0 * ratio), Math.floor((y - 1) * ratio),
                                                   Math.ceil((x1 - x0) * ratio), Math.ceil(2 * ratio)).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) if (d[i] < 90 && d[i + 1] > 120 && d[i + 2] > 130) n++;
        return n;
    })()""")
    assert teal_in_swatch > 0  # the second joint's dotted teal, drawn
    page.set_viewport_size({"width": 1100, "height": 720})  # short of room: the supply's entry shows one line
    page.wait_for_timeout(500)                                  # rather than go (a review's width, stop 42)
    shown = dict(page.evaluate("window.twinPlots.charts.map((c) => [c.spec.id, c.legend])"))["pressure"]
    assert "supply" in shown, shown
    assert all(legends[chart][-1] == "compare" for chart in ("angle", "error", "duty", "valves"))
    page.set_viewport_size({"width": 800, "height": 600})  # a narrow panel: the legend gives up the first's later series
    page.wait_for_timeout(500)
    narrow = dict(page.evaluate("window.twinPlots.charts.map((c) => [c.spec.id, c.legend])"))["pressure"]
    assert narrow[0] == "chamber A" and narrow[-2:] == ["compare A", "compare B"], narrow
    assert chart_pixels(page, "pressure", COMPARE_B_TEAL) > 10


def chart_rows(page, chart: str, test: str) -> list[float]:
    """The CSS rows (from the canvas's top) where chart ``chart``'s plot has a pixel whose r, g, b pass ``test``
    (a JavaScript expression)."""
    return page.evaluate(f"""(() => {{
        const chart = window.twinPlots.charts.find((c) => c.spec.id === '{chart}'), L = chart.layout, c = chart.canvas;
        const ratio = c.width / c.clientWidth, d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        const rows = [];
        for (let y = Math.ceil(L.top * ratio); y < (L.top + L.height) * ratio; y++)
            for (let x = Math.ceil(L.left * ratio); x < (L.left + L.width) * ratio; x++) {{
                const i = 4 * (y * c.width + x), r = d[i], g = d[i + 1], b = d[i + 2];
                if ({test}) {{ rows.push(y / ratio); break; }}
            }}
        return rows; }})()""")


def layouts(page) -> dict:
    return dict(page.evaluate("window.twinPlots.charts.map((c) => [c.spec.id, c.layout])"))


@pytest.mark.slow  # a recording and a page: about 10 s on 2 cores
def test_a_recordings_charts_zoom_to_a_dragged_span_and_back(tmp_path, page):
    """A recording's charts showed the whole run only (a helper in chromium, stop 40). A drag across any chart
    zooms every chart to the span it swept, each value axis fitted to that span's samples and each one's peaks
    drawn; scrubbing and playing go on (the cursor where its time falls in the span, none outside it); a
    double-click, or the "whole run" button, shows the whole run again."""
    html = record(tmp_path, "--controller", "ffpva", "--trajectory", "1")
    open_recording(page, html)
    duration = page.evaluate("window.twinTrace.time[window.twinTrace.time.length - 1]")
    assert all(L["t0"] == 0 and L["t1"] == pytest.approx(duration) for L in layouts(page).values())
    assert page.is_disabled("#whole-run")
    box = page.locator('canvas[data-chart="error"]').bounding_box()
    x_at = lambda t: box["x"] + page.evaluate(f"window.twinPlots.xOf('error', {t})")  # noqa: E731
    y = box["y"] + box["height"] / 2
    page.mouse.move(x_at(0.3), y)
    page.mouse.down()
    page.mouse.move(x_at(0.9), y, steps=6)
    page.mouse.up()
    page.wait_for_timeout(200)
    seconds_per_px = duration / layouts(page)["error"]["width"]
    for chart, L in layouts(page).items():
        assert L["t0"] == pytest.approx(0.3, abs=2 * seconds_per_px), chart
        assert L["t1"] == pytest.approx(0.9, abs=2 * seconds_per_px), chart
    assert page.is_enabled("#whole-run")
    assert page.evaluate("window.twinClock.time") == pytest.approx(0.6) and not page.evaluate("window.twinClock.playing")

    # the value axes fit the span's samples, and the error's highest and lowest in the span are drawn
    L = layouts(page)
    trace = page.evaluate("window.twinTrace")
    inside = [i for i, t in enumerate(trace["time"]) if L["angle"]["t0"] <= t <= L["angle"]["t1"]]
    angles = [trace[key][i] for key in ("angle_deg", "desired_deg") for i in inside]
    low, high = min(angles), max(angles)
    pad = 0.06 * (high - low)
    assert (L["angle"]["lo"], L["angle"]["hi"]) == (pytest.approx(low - pad), pytest.approx(high + pad))
    assert high - low < 0.9 * (max(trace["angle_deg"]) - min(trace["angle_deg"]))  # not the whole run's range
    errors = [trace["error_deg"][i] for i in inside]
    E = L["error"]
    y_of = lambda v: E["top"] + E["height"] - (v - E["lo"]) / (E["hi"] - E["lo"]) * E["height"]  # noqa: E731
    rows = chart_rows(page, "error", "b - g > 25 && r - g > 15")  # the error's purple, even a spike's faint tip
    assert min(rows) <= y_of(max(errors)) + 1.5 and max(rows) >= y_of(min(errors)) - 1.5, (rows[0], rows[-1])

    # scrubbing: the cursor where its time falls in the span; outside the span, none
    scrub_to(page, 0.75)
    expected = E["left"] + (0.75 - E["t0"]) / (E["t1"] - E["t0"]) * E["width"]
    assert cursor_column(page, "error") == pytest.approx(expected, abs=2.0)
    scrub_to(page, 2.0)
    assert page.evaluate("""(() => {
        const c = document.querySelector('canvas[data-chart="error"]');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        const counts = new Array(c.width).fill(0);
        for (let i = 0; i < d.length; i += 4) if (d[i] > 180 && d[i + 1] < 60 && d[i + 2] < 60) counts[(i / 4) % c.width]++;
        return Math.max(...counts); })()""") < 5
    # playing: the clock runs, the charts stay zoomed
    scrub_to(page, 0.4)
    page.click("#play")
    page.wait_for_timeout(400)
    assert page.evaluate("window.twinClock.time") > 0.45
    assert layouts(page)["duty"]["t0"] == pytest.approx(L["duty"]["t0"])
    page.click("#play")

    # back to the whole run: a double-click; zoomed again, the button
    page.mouse.dblclick(x_at(0.5), y)
    page.wait_for_timeout(200)
    assert all(L["t0"] == 0 and L["t1"] == pytest.approx(duration) for L in layouts(page).values())
    assert page.is_disabled("#whole-run")
    page.mouse.move(x_at(1.0), y)
    page.mouse.down()
    page.mouse.move(x_at(2.0), y, steps=4)
    page.mouse.up()
    page.wait_for_timeout(200)
    assert layouts(page)["valves"]["t0"] == pytest.approx(1.0, abs=0.02)
    page.click("#whole-run")
    page.wait_for_timeout(200)
    assert all(L["t0"] == 0 and L["t1"] == pytest.approx(duration) for L in layouts(page).values())
