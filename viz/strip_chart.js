// Strip charts and the camera fit for the twin's pages (viz/live_page.html, viz/recording_page.html): a small canvas
// drawer with no dependencies, so that the pages work offline and a recording stays one file.
//
// A trace is columns of samples, the field names of viz/live_server.py's samples and of
// viz/recording.py's TraceRows.as_json():
//   {time: [s], angle_deg, desired_deg, error_deg, duty (%), pressure_a_kpa, pressure_b_kpa,
//    supply_kpa, valves: [[time, [V1, V2, V3, V4]], ...] (each change)}
// Every chart draws every trace over the same time window [t0, t1]: the first joint in solid lines,
// compare mode's second joint dashed and in a tint, with a legend. A series that the second joint draws otherwise
// says how (``compare``: its legend name, colour and dash): its chambers A and B, in one tint, looked alike; its
// supply, dotted teal, shares the first's legend entry (``both``).
"use strict";

const TWIN_COMPARE_TINT = "#12a5b0";  // teal, as the second joint in the 3D view (viz/scene.py COMPARE_TINT)
const TWIN_COMPARE_DARK = "#0b6b73";  // a darker teal: the second joint's chamber B, beside its chamber A in teal
const TWIN_CHARTS = [
  {id: "angle", title: "angle", unit: "deg", series: [
    {key: "angle_deg", label: "angle", color: "#c0392b"},
    {key: "desired_deg", label: "desired", color: "#222222", dash: [2, 2]}]},
  {id: "error", title: "error (desired - angle)", unit: "deg", symmetric: true, minSpan: 2, series: [
    {key: "error_deg", label: "error", color: "#8e44ad"}]},
  {id: "duty", title: "duty", unit: "%", symmetric: true, minSpan: 20, series: [
    {key: "duty", label: "duty", color: "#2471a3"}]},
  {id: "pressure", title: "pressure", unit: "kPa", fromZero: true, series: [
    {key: "pressure_a_kpa", label: "chamber A", color: "#d35400", compare: {label: "A"}},
    {key: "pressure_b_kpa", label: "chamber B", color: "#1e8449",
     compare: {label: "B", color: TWIN_COMPARE_DARK, dash: [8, 2, 2, 2]}},
    {key: "supply_kpa", label: "supply", color: "#555555", dash: [1, 3], compare: {both: true}}]},
  {id: "valves", title: "valves (open)", unit: "", kind: "valves"},
];

// How the second joint draws series ``s``: teal, dashed (dotted where the first joint's is), unless it says otherwise.
function twinCompareStyle(s) {
  const own = s.compare || {};
  return {color: own.color || TWIN_COMPARE_TINT, dash: own.dash || (s.dash ? [1, 3] : [5, 3])};
}

// A number with ``digits`` decimals, never "-0" (a small negative duty or pressure reads 0): both pages' readouts.
function twinFixed(x, digits) {
  const text = x.toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}
const TWIN_CAMERA_FOV = 35;  // deg, vertical field of view of the 3D view

class StripCharts {
  // container: an element to fill with one canvas per chart; labels: a name per trace (legend).
  constructor(container, labels) {
    this.container = container;
    this.labels = labels;
    this.charts = TWIN_CHARTS.map((spec) => {
      const box = document.createElement("div");
      box.className = "chart chart-" + spec.id;
      const canvas = document.createElement("canvas");
      canvas.dataset.chart = spec.id;
      box.appendChild(canvas);
      container.appendChild(box);
      return {spec, canvas, layout: null, legend: []};
    });
    this.draws = 0;
    this.selection = null;  // [t0, t1] s swept by a drag under way (enableZoom), drawn as a band
  }

  // Draw ``traces`` (one per joint) over [t0, t1] s, with a cursor at ``cursor`` s (or none).
  draw(traces, t0, t1, cursor) {
    for (const chart of this.charts) this._drawChart(chart, traces, t0, t1, cursor);
    this.draws += 1;
  }

  // Where time t (s) falls across a chart's canvas, in CSS pixels from its left edge.
  xOf(id, t) {
    const chart = this.charts.find((c) => c.spec.id === id);
    const L = chart.layout;
    return L.left + (t - L.t0) / Math.max(L.t1 - L.t0, 1e-9) * L.width;
  }

  // The time (s) at CSS x pixels from a chart's left edge, within the time shown.
  timeAt(id, x) {
    const L = this.charts.find((c) => c.spec.id === id).layout;
    return L.t0 + Math.min(Math.max((x - L.left) / L.width, 0), 1) * (L.t1 - L.t0);
  }

  // Let the charts be zoomed (a recording's): a drag across any chart asks for the time span it swept, drawn as a
  // band meanwhile; a double-click asks for the whole run. ``zoom(span)`` gets [t0, t1] s, or null for the whole
  // run, and draws; ``redraw()`` draws as they are (the band moved).
  enableZoom(zoom, redraw) {
    for (const chart of this.charts) {
      const canvas = chart.canvas, id = chart.spec.id;
      canvas.style.cursor = "crosshair";
      canvas.style.touchAction = "pan-y";  // a finger across zooms; up or down still scrolls the panel (a phone)
      canvas.title = "drag across to zoom every chart; double-click for the whole run";
      let start = null;  // the drag's first x (CSS px from the canvas's left) and time
      const x = (e) => e.clientX - canvas.getBoundingClientRect().left;
      const swept = (e) => {
        const t = this.timeAt(id, x(e));
        return [Math.min(start.t, t), Math.max(start.t, t)];
      };
      canvas.addEventListener("pointerdown", (e) => {
        if (e.button !== 0 || !chart.layout) return;
        start = {x: x(e), t: this.timeAt(id, x(e))};
        canvas.setPointerCapture(e.pointerId);
      });
      canvas.addEventListener("pointermove", (e) => {
        if (start === null) return;
        this.selection = swept(e);
        redraw();
      });
      canvas.addEventListener("pointerup", (e) => {
        if (start === null) return;
        const span = swept(e), dragged = Math.abs(x(e) - start.x) >= 4;  // a click (or a double-click's) is no zoom
        start = null;
        this.selection = null;
        if (dragged) zoom(span); else redraw();
      });
      canvas.addEventListener("pointercancel", () => { start = null; this.selection = null; redraw(); });
      canvas.addEventListener("dblclick", () => zoom(null));
    }
  }

  _size(canvas) {
    const ratio = window.devicePixelRatio || 1;
    const w = Math.max(50, canvas.clientWidth), h = Math.max(40, canvas.clientHeight);
    if (canvas.width !== Math.round(w * ratio) || canvas.height !== Math.round(h * ratio)) {
      canvas.width = Math.round(w * ratio);
      canvas.height = Math.round(h * ratio);
    }
    const ctx = canvas.getContext("2d");
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    return [ctx, w, h];
  }

  _range(spec, traces, t0, t1) {
    let lo = Infinity, hi = -Infinity;
    for (const tr of traces) {
      const time = tr.time;
      for (const s of spec.series) {
        const ys = tr[s.key];
        if (!ys) continue;
        for (let i = 0; i < time.length; i++) {
          if (time[i] < t0 || time[i] > t1) continue;
          const y = ys[i];
          if (y < lo) lo = y;
          if (y > hi) hi = y;
        }
      }
    }
    if (!isFinite(lo)) { lo = 0; hi = 1; }
    if (spec.symmetric) { const m = Math.max(Math.abs(lo), Math.abs(hi), (spec.minSpan || 1) / 2); lo = -m; hi = m; }
    if (spec.fromZero) lo = Math.min(0, lo);
    const span = Math.max(hi - lo, spec.minSpan || 1);
    const mid = (hi + lo) / 2;
    lo = spec.fromZero ? lo : mid - span / 2;
    hi = spec.fromZero ? lo + span : mid + span / 2;
    const pad = 0.06 * (hi - lo);
    return [spec.fromZero ? lo : lo - pad, hi + pad];
  }

  // Round ticks over [lo, hi], about ``count`` of them, and never fewer than two (a short chart with one
  // labelled tick cannot be read: the step is halved or so until two fit).
  _ticks(lo, hi, count) {
    const raw = (hi - lo) / count;
    const power = Math.pow(10, Math.floor(Math.log10(raw)));
    const steps = [0.1, 0.2, 0.5, 1, 2, 5, 10].map((m) => m * power);
    const at = (step) => {
      const ticks = [];
      for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi + 1e-9; k++) ticks.push(Math.abs(k * step) < 1e-9 ? 0 : k * step);
      return ticks;
    };
    let i = steps.findIndex((s) => s >= raw);
    if (i < 0) i = steps.length - 1;
    let ticks = at(steps[i]);
    while (ticks.length < 2 && i > 0) ticks = at(steps[--i]);
    return ticks;
  }

  _drawChart(chart, traces, t0, t1, cursor) {
    const {spec, canvas} = chart;
    const [ctx, w, h] = this._size(canvas);
    const left = 42, right = 6, top = 15, bottom = 16;
    const width = w - left - right, height = h - top - bottom;
    chart.layout = {left, top, width, height, t0, t1};
    ctx.clearRect(0, 0, w, h);
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(left, top, width, height);
    ctx.font = "10px sans-serif";
    ctx.fillStyle = "#222";
    ctx.textBaseline = "alphabetic";
    ctx.textAlign = "left";
    ctx.fillText(spec.title + (spec.unit ? ` (${spec.unit})` : ""), left, 11);
    const xOf = (t) => left + (t - t0) / Math.max(t1 - t0, 1e-9) * width;
    // time axis: ticks in s
    ctx.strokeStyle = "#e3e3e3";
    ctx.lineWidth = 1;
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    const times = this._ticks(t0, t1, Math.max(2, Math.floor(width / 60)));
    // as many decimals as the step needs (0.5 s: one; a zoomed 0.05 s: two), and one under a 4 s window
    const step = times.length > 1 ? times[1] - times[0] : 1;
    const digits = Math.max(Math.abs(t1 - t0) < 4 ? 1 : 0, Math.ceil(-Math.log10(step) - 1e-9));
    for (const t of times) {
      const x = xOf(t);
      ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, top + height); ctx.stroke();
      ctx.fillStyle = "#444";
      ctx.fillText(t.toFixed(digits) + (x > left + width - 30 ? " s" : ""), x, top + height + 2);
    }
    if (spec.kind === "valves") {
      chart.legend = this._drawValves(ctx, traces, t0, t1, xOf, left, top, width, height);
    } else {
      const [lo, hi] = this._range(spec, traces, t0, t1);
      Object.assign(chart.layout, {lo, hi});  // the value span shown, bottom to top
      const yOf = (v) => top + height - (v - lo) / (hi - lo) * height;
      ctx.textAlign = "right";
      ctx.textBaseline = "middle";
      for (const v of this._ticks(lo, hi, Math.max(2, Math.floor(height / 22)))) {
        const y = yOf(v);
        ctx.strokeStyle = "#e3e3e3";
        ctx.beginPath(); ctx.moveTo(left, y); ctx.lineTo(left + width, y); ctx.stroke();
        ctx.fillStyle = "#444";
        ctx.fillText(String(Math.round(v * 100) / 100), left - 3, y);
      }
      ctx.save();
      ctx.beginPath(); ctx.rect(left, top, width, height); ctx.clip();
      traces.forEach((tr, j) => {
        for (const s of spec.series) {
          const ys = tr[s.key];
          if (!ys) continue;
          const style = j === 0 ? {color: s.color, dash: s.dash || []} : twinCompareStyle(s);
          ctx.strokeStyle = style.color;
          ctx.lineWidth = j === 0 ? 1.4 : 1.6;
          ctx.setLineDash(style.dash);
          ctx.beginPath();
          let started = false;
          const time = tr.time;
          const line = (x, y) => { if (started) ctx.lineTo(x, y); else { ctx.moveTo(x, y); started = true; } };
          // Each pixel column draws its samples' lowest and highest value, in the order they came: a long
          // run keeps its peaks (every n-th sample hid them: 0.45 deg drawn of a 0.66 deg largest error).
          let column = null, low = 0, high = 0, lowFirst = true;
          const flush = () => {
            if (column === null) return;
            line(column, yOf(lowFirst ? low : high));
            if (high !== low) line(column, yOf(lowFirst ? high : low));
          };
          for (let i = 0; i < time.length; i++) {
            if (time[i] < t0 - 0.05 || time[i] > t1 + 0.05) continue;
            const x = Math.round(xOf(time[i])), v = ys[i];
            if (x !== column) { flush(); column = x; low = high = v; lowFirst = true; continue; }
            if (v < low) { low = v; lowFirst = false; }
            if (v > high) { high = v; lowFirst = true; }
          }
          flush();
          ctx.stroke();
        }
      });
      ctx.setLineDash([]);
      ctx.restore();
      chart.legendSwatches = [];
      chart.legend = this._legend(ctx, spec, traces.length, left + width, 11,
                                  left + ctx.measureText(spec.title + " (" + spec.unit + ")").width + 8,
                                  chart.legendSwatches);
    }
    if (this.selection) {  // a drag under way: the span it will zoom to
      const [a, b] = this.selection.map((t) => Math.min(Math.max(xOf(t), left), left + width));
      ctx.fillStyle = "rgba(36, 113, 163, 0.18)";
      ctx.fillRect(a, top, b - a, height);
    }
    ctx.strokeStyle = "#999";
    ctx.lineWidth = 1;
    ctx.strokeRect(left + 0.5, top + 0.5, width - 1, height - 1);
    if (cursor !== null && cursor !== undefined && cursor >= t0 && cursor <= t1) {  // none outside a zoomed span
      const x = xOf(cursor);
      ctx.strokeStyle = "rgba(200, 0, 0, 0.85)";
      ctx.lineWidth = 2;
      ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, top + height); ctx.stroke();
    }
  }

  // The legend, right-aligned between ``leftmost`` (the title's end) and ``right``: in a smaller font when
  // it does not fit, and only then without its last series (the first series, as chamber A, stays; so do
  // the compare joint's entries: "compare" on both pages, the page's title and info say what it is, or one per
  // series the second joint draws its own way, "compare A" and "compare B"). A series marked ``compare.both``
  // (the supply) takes no entry of its own for the second joint: its entry shows the second joint's line beside
  // the first's, unless the legend is short of room, when it shows the first's alone before any entry is
  // dropped. Returns the names drawn; ``swatches`` gets [label, colour, left x, right x, y] of each line drawn
  // (CSS px; a name drawn with both lines has two).
  _legend(ctx, spec, count, right, y, leftmost = 0, swatches = []) {
    ctx.textAlign = "right";
    ctx.textBaseline = "alphabetic";
    let x = right;
    const items = [];
    for (const s of spec.series) {
      const both = count > 1 && s.compare && s.compare.both ? twinCompareStyle(s) : null;
      items.push([s.label, s.color, s.dash || [], both]);
    }
    const compares = [];
    if (count > 1) {
      const name = this.labels[1] || "compare";
      for (const s of spec.series) {
        if (!s.compare || !s.compare.label) continue;
        const style = twinCompareStyle(s);
        compares.push([`${name} ${s.compare.label}`, style.color, style.dash, null]);
      }
      if (!compares.length) compares.push([name, TWIN_COMPARE_TINT, [5, 3], null]);
    }
    items.push(...compares);
    const kept = 1 + compares.length;  // the first series, and the compare entries when there are any
    const needs = () => items.reduce((w, [label, , , both]) => w + ctx.measureText(label).width + 23 + (both ? 16 : 0), 0);
    for (let size = 9; size >= 8 && needs() > right - leftmost; size--) ctx.font = `${size}px sans-serif`;
    for (const item of items) if (needs() > right - leftmost) item[3] = null;  // short of room: one line per entry
    while (items.length > kept && needs() > right - leftmost) items.splice(items.length - compares.length - 1, 1);
    const drawn = [];
    const swatch = (color, dash, at, label) => {
      swatches.push([label, color, at - 14, at, y - 3]);
      ctx.strokeStyle = color;
      ctx.lineWidth = 1.6;
      ctx.setLineDash(dash);
      ctx.beginPath(); ctx.moveTo(at - 14, y - 3); ctx.lineTo(at, y - 3); ctx.stroke();
      ctx.setLineDash([]);
    };
    for (const [label, color, dash, both] of items.reverse()) {
      if (x - ctx.measureText(label).width - 20 - (both ? 16 : 0) < leftmost) break;  // no room even for one
      ctx.fillStyle = "#333";
      ctx.fillText(label, x, y);
      drawn.unshift(label);
      x -= ctx.measureText(label).width + 3;
      swatch(color, dash, x, label);
      if (both) {  // the second joint's line, left of the first's
        swatch(both.color, both.dash, x - 16, label);
        x -= 16;
      }
      x -= 20;
    }
    ctx.font = "10px sans-serif";
    return drawn;
  }

  _drawValves(ctx, traces, t0, t1, xOf, left, top, width, height) {
    const rows = 4, rowHeight = height / rows;
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    ctx.font = `${Math.max(7, Math.min(10, Math.floor(rowHeight)))}px sans-serif`;  // V1-V4 apart on a short chart
    for (let v = 0; v < rows; v++) {
      ctx.fillStyle = "#444";
      ctx.fillText("V" + (v + 1), left - 3, top + (v + 0.5) * rowHeight);
      if (v > 0) {
        ctx.strokeStyle = "#e3e3e3";
        ctx.beginPath(); ctx.moveTo(left, top + v * rowHeight); ctx.lineTo(left + width, top + v * rowHeight); ctx.stroke();
      }
    }
    const share = traces.length;
    traces.forEach((tr, j) => {
      const changes = tr.valves || [];
      ctx.fillStyle = j === 0 ? "#2ca02c" : TWIN_COMPARE_TINT;
      for (let v = 0; v < rows; v++) {
        const y = top + v * rowHeight + 2 + j * (rowHeight - 4) / share;
        const hBar = (rowHeight - 4) / share;
        for (let i = 0; i < changes.length; i++) {
          if (!changes[i][1][v]) continue;
          const start = changes[i][0];
          const end = i + 1 < changes.length ? changes[i + 1][0] : (tr.time.length ? tr.time[tr.time.length - 1] : start);
          if (end < t0 || start > t1) continue;
          const x0 = Math.max(left, xOf(start)), x1 = Math.min(left + width, xOf(end));
          ctx.fillRect(x0, y, Math.max(1, x1 - x0), hBar);
        }
      }
    });
    ctx.font = "10px sans-serif";
    const legend = {spec: {series: [{label: "open", color: "#2ca02c"}]}};
    return this._legend(ctx, legend.spec, share, left + width, 11, left + 80);
  }
}

// A trace that keeps only its last ``seconds`` (the live page's rolling window).
class RollingTrace {
  constructor(seconds) {
    this.seconds = seconds;
    this.data = RollingTrace.empty();
  }
  static empty() {
    return {time: [], angle_deg: [], desired_deg: [], error_deg: [], duty: [], pressure_a_kpa: [],
            pressure_b_kpa: [], supply_kpa: [], valves: []};
  }
  clear() { this.data = RollingTrace.empty(); }
  push(samples) {
    const d = this.data;
    if (samples.time.length && d.time.length && samples.time[0] < d.time[d.time.length - 1]) this.clear();  // restarted
    for (const key of Object.keys(d)) if (key !== "valves") for (const v of samples[key]) d[key].push(v);
    for (const change of samples.valves) d.valves.push(change);
    const latest = d.time.length ? d.time[d.time.length - 1] : 0;
    let cut = 0;
    while (cut < d.time.length && d.time[cut] < latest - this.seconds) cut++;
    if (cut > 200) for (const key of Object.keys(d)) if (key !== "valves") d[key].splice(0, cut);
    let vcut = 0;
    while (vcut + 1 < d.valves.length && d.valves[vcut + 1][0] < latest - this.seconds) vcut++;
    if (vcut > 50) d.valves.splice(0, vcut);
  }
}

// The 3D view (meshcat's): the camera keeps its direction and moves in or out until every joint's view box fills the pane.
function twinViewBoxes(viewer) {
  const boxes = [];
  viewer.scene.updateMatrixWorld(true);  // the scene may have changed since the last render
  for (const root of ["twin", "compare"]) {
    const node = viewer.scene_tree.children[root];
    if (!node) continue;
    const path = ["bodies", "housing", "view_box", "<object>"];
    let n = node;
    for (const name of path) { n = n && n.children[name]; }
    if (!n || !n.object.children.length && !n.object.geometry) continue;
    boxes.push(new MeshCat.THREE.Box3().setFromObject(n.object));
  }
  return boxes;
}
function fitCameraToViewBoxes(viewer) {
  viewer.set_3d_pane_size();  // the camera's aspect from the pane as laid out now
  const boxes = twinViewBoxes(viewer);
  if (!boxes.length) return;
  const camera = viewer.camera;
  camera.fov = TWIN_CAMERA_FOV;  // narrower than meshcat's 75 deg: near and far parts drawn more alike
  camera.updateProjectionMatrix();
  const corners = [];
  for (const b of boxes) for (const x of [b.min.x, b.max.x]) for (const y of [b.min.y, b.max.y]) for (const z of [b.min.z, b.max.z])
    corners.push(new MeshCat.THREE.Vector3(x, y, z));
  const target = viewer.controls.target;
  const direction = camera.position.clone().sub(target).normalize();
  const project = () => corners.map((c) => c.clone().project(camera));
  const fits = (d) => {
    camera.position.copy(target).addScaledVector(direction, d);
    camera.lookAt(target);
    camera.updateMatrixWorld(true);
    return corners.every((c) => {
      if (c.clone().applyMatrix4(camera.matrixWorldInverse).z > -camera.near) return false;  // behind the camera
      const p = c.clone().project(camera);
      return Math.abs(p.x) <= 0.96 && Math.abs(p.y) <= 0.96;
    });
  };
  const fitDistance = () => {
    let lo = 0.02, hi = 50;
    for (let i = 0; i < 40; i++) { const mid = Math.sqrt(lo * hi); if (fits(mid)) hi = mid; else lo = mid; }
    fits(hi);
    return hi;
  };
  // Perspective draws the near side larger: pan (camera and target together) until the boxes sit
  // in the middle of the view, then move in as far as they still fit.
  for (let round = 0; round < 4; round++) {
    const d = fitDistance();
    const p = project();
    const cx = (Math.min(...p.map((q) => q.x)) + Math.max(...p.map((q) => q.x))) / 2;
    const cy = (Math.min(...p.map((q) => q.y)) + Math.max(...p.map((q) => q.y))) / 2;
    const halfHeight = d * Math.tan(camera.fov * Math.PI / 360), halfWidth = halfHeight * camera.aspect;
    const right = new MeshCat.THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new MeshCat.THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    target.addScaledVector(right, cx * halfWidth).addScaledVector(up, cy * halfHeight);
  }
  fitDistance();
  viewer.controls.update();
  viewer.set_dirty();
}
