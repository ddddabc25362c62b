// neepp view's page: shows the frames the server sends (linear RGB, tonemapped here at the chosen
// exposure), turns mouse and keys into camera commands, and the option menus into option changes. The
// server holds the view (camera, integrator): every page open on it shows the same one.
"use strict";

const $ = (id) => document.getElementById(id);
const canvas = $("image");
const ctx = canvas.getContext("2d");
let ws = null;
let state = null;           // the server's latest "state" message
let frame = null;           // {header, pixels: Float32Array} of the newest frame
let mapView = null;         // {header, pixels: Float32Array} of the last map view (a clicked point)
let reference = null;       // {header, pixels: Float32Array}: the image the relMSE is measured against
let overlay = null;         // what draw() last laid over the image: {view, known, min, max}
const listeners = [];       // the self-test's waits: functions called with each frame
const mapListeners = [];    // ... and with each map view

// ---- frames -------------------------------------------------------------------------------------------

function decodeFrame(buffer) {
  const view = new DataView(buffer);
  const n = view.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, n)));
  const pixels = new Float32Array(buffer, 4 + n, header.width * header.height * (header.channels || 3));
  return { header, pixels };
}

// sRGB encoding of a linear value in [0, 1].
function srgb(v) {
  return v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
}

function draw() {
  if (!frame) return;
  const { width, height } = frame.header;
  if (canvas.width !== width || canvas.height !== height) {
    canvas.width = width;
    canvas.height = height;
  }
  // The coarse first frame is drawn at the full image's size, enlarged.
  if (state) canvas.style.width = state.width + "px";
  const scale = Math.pow(2, Number($("exposure").value));
  const img = ctx.createImageData(width, height);
  const src = frame.pixels, dst = img.data;
  for (let i = 0, j = 0; i < src.length; i += 3, j += 4) {
    dst[j] = 255 * srgb(Math.min(1, Math.max(0, src[i] * scale))) + 0.5;
    dst[j + 1] = 255 * srgb(Math.min(1, Math.max(0, src[i + 1] * scale))) + 0.5;
    dst[j + 2] = 255 * srgb(Math.min(1, Math.max(0, src[i + 2] * scale))) + 0.5;
    dst[j + 3] = 255;
  }
  overlay = null;
  if ($("mode").value === "map") drawMap(img.data, width, height);
  else if ($("mode").value === "relmse") drawRelmse(img.data, width, height);
  ctx.putImageData(img, 0, 0);
}

// Ṽ in [0, 1] as a colour: dark blue (the map says occluded) through red to pale yellow (visible).
const HEAT_STOPS = [[0, [20, 24, 110]], [0.5, [200, 55, 60]], [1, [255, 240, 130]]];
function heatColor(v) {
  for (let i = 1; i < HEAT_STOPS.length; i++) {
    const [t1, c1] = HEAT_STOPS[i], [t0, c0] = HEAT_STOPS[i - 1];
    if (v <= t1 || i === HEAT_STOPS.length - 1) {
      const f = Math.min(1, Math.max(0, (v - t0) / (t1 - t0)));
      return [c0[0] + f * (c1[0] - c0[0]), c0[1] + f * (c1[1] - c0[1]), c0[2] + f * (c1[2] - c0[2])];
    }
  }
}

// The map view over the image: each pixel tinted by Ṽ from the cell of what it sees to the cells the
// clicked point sees (the light cells its shadow rays reach): the clicked point's light as the map sees it.
// The image, in grey, shows through; pixels the map knows nothing of stay grey and dim. Only over a full
// frame of the view it was computed for: after a move, the pixels see other cells.
function drawMap(dst, width, height) {
  if (!mapView || !mapView.header.width) return;
  const h = mapView.header;
  if (h.view !== frame.header.view || h.width !== width || h.height !== height) return;
  const heat = mapView.pixels;
  let known = 0, min = Infinity, max = -Infinity;
  for (let i = 0, j = 0; i < heat.length; i++, j += 4) {
    const grey = 0.3 * dst[j] + 0.55 * dst[j + 1] + 0.15 * dst[j + 2];
    const v = heat[i];
    if (Number.isNaN(v)) {
      dst[j] = dst[j + 1] = dst[j + 2] = 0.4 * grey;
      continue;
    }
    known++;
    min = Math.min(min, v);
    max = Math.max(max, v);
    const c = heatColor(v);
    dst[j] = 0.3 * grey + 0.7 * c[0];
    dst[j + 1] = 0.3 * grey + 0.7 * c[1];
    dst[j + 2] = 0.3 * grey + 0.7 * c[2];
  }
  // The clicked pixel: a small white cross.
  for (let d = -3; d <= 3; d++) {
    for (const [x, y] of [[h.x + d, h.y], [h.x, h.y + d]]) {
      if (x < 0 || y < 0 || x >= width || y >= height) continue;
      const j = 4 * (y * width + x);
      dst[j] = dst[j + 1] = dst[j + 2] = 255;
    }
  }
  overlay = { view: h.view, known, min, max };
}

// The per-pixel relMSE against the reference, as neepp compare's relMSE map defines it (squared error over
// reference² + 0.01, averaged over the channels), on a log scale from 1e-4 (dark) to 1 (bright); the mean
// of these is the relMSE the statistics show.
const RELMSE_EPS = 0.01;
function drawRelmse(dst, width, height) {
  if (!reference || reference.header.width !== width || reference.header.height !== height) return;
  const a = frame.pixels, r = reference.pixels;
  let sum = 0;
  for (let i = 0, j = 0; i < a.length; i += 3, j += 4) {
    let e = 0;
    for (let c = 0; c < 3; c++) {
      const d = a[i + c] - r[i + c];
      e += d * d / (r[i + c] * r[i + c] + RELMSE_EPS);
    }
    e /= 3;
    sum += e;
    const col = heatColor((Math.log10(Math.max(e, 1e-4)) + 4) / 4);
    dst[j] = col[0];
    dst[j + 1] = col[1];
    dst[j + 2] = col[2];
  }
  overlay = { view: frame.header.view, relmse: sum / (width * height) };
}

function showReference(m) {
  reference = m.header.width ? m : null;
  $("reference").textContent = reference ? "reference: " + m.header.name
    : "no reference (neepp view --reference FILE, or a saved image)";
  draw();
}

function showMap(m) {
  mapView = m;
  const h = m.header;
  $("map-panel").hidden = false;
  const fmt = (v) => v.map((x) => x.toFixed(3)).join(", ");
  $("map-point").textContent = h.hit
    ? `pixel (${h.x}, ${h.y}) of view ${h.view}: point (${fmt(h.point)})` + (h.cell >= 0 ? `, cell ${h.cell}` : "")
    : `pixel (${h.x}, ${h.y}) of view ${h.view}: its ray leaves the scene`;
  let summary = "";
  if (!h.map) summary = "This integrator keeps no visibility map (choose a NEE++ shadow-ray policy).";
  else if (h.hit) summary = `This cell sees ${h.seen_cells} cells; Ṽ to them known for ` +
      `${(100 * h.known_fraction).toFixed(1)} % of the pixels` +
      (h.heat_mean !== null ? `, mean ${h.heat_mean.toFixed(3)}` : "") +
      ` (map ${h.map.resolution}³ voxels, ${formatCount(h.map.known_pairs)} pairs known)`;
  $("map-summary").textContent = summary;
  const rows = [];
  if (h.lights) {
    const head = document.createElement("tr");
    head.innerHTML = "<th>light</th><th>type</th><th>probability</th>";
    rows.push(head);
    for (const l of h.lights) {
      const tr = document.createElement("tr");
      for (const text of ["#" + l.index, l.type, (100 * l.pmf).toFixed(2) + " %"]) {
        const td = document.createElement("td");
        td.textContent = text;
        tr.append(td);
      }
      if (l.center) tr.title = "centre " + fmt(l.center);
      rows.push(tr);
    }
    const note = document.createElement("tr");
    const td = document.createElement("td");
    td.colSpan = 3;
    td.className = "dim";
    td.textContent = `${h.light_sampler}: the ${h.lights.length} most probable of ${h.light_count} lights`;
    note.append(td);
    rows.push(note);
  }
  $("map-lights").replaceChildren(...rows);
  if (h.width) $("mode").value = "map";
  draw();
  for (const f of mapListeners.slice()) f(h);
}

function formatCount(n) {
  if (n >= 1e9) return (n / 1e9).toFixed(2) + " G";
  if (n >= 1e6) return (n / 1e6).toFixed(2) + " M";
  if (n >= 1e3) return (n / 1e3).toFixed(1) + " k";
  return String(n);
}

function percent(part, whole) {
  return whole > 0 ? " (" + (100 * part / whole).toFixed(1) + " %)" : "";
}

function showStats(h) {
  const tested = h.shadow_rays + h.shadow_rays_skipped;
  const text = {
    // Within the first full pass its finished tiles are drawn over the coarse image.
    view: h.view + (h.coarse ? " (coarse)" : h.composed ? " (tiles over the coarse)" : ""),
    // Within a pass the tiles it finished have its samples too.
    spp: h.spp_max > h.spp ? `${h.spp}–${h.spp_max} (mean ${h.spp_mean.toFixed(2)})` : String(h.spp),
    samples_per_s: formatCount(h.samples_per_s),
    render_time_s: h.render_time_s.toFixed(2) + " s",
    rays: formatCount(h.rays),
    shadow_rays: formatCount(h.shadow_rays),
    shadow_rays_skipped: formatCount(h.shadow_rays_skipped) + percent(h.shadow_rays_skipped, tested),
    shadow_rays_occluded: formatCount(h.shadow_rays_occluded) + percent(h.shadow_rays_occluded, h.shadow_rays),
    fov: h.fov.toFixed(1) + "°",
    relmse: h.relmse === undefined ? "–" : h.relmse.toExponential(3),
  };
  for (const td of document.querySelectorAll("#stats td")) {
    const key = td.dataset.key;
    td.textContent = text[key];
    td.dataset.value = String(h[key]);
  }
}

// ---- options ------------------------------------------------------------------------------------------

function fill(select, names, value) {
  select.replaceChildren(...names.map((n) => new Option(n, n)));
  if (value !== undefined && !names.includes(value)) select.append(new Option(value, value));
  if (value !== undefined) select.value = value;
}

function integratorDoc(name) {
  return state.catalog.integrators.find((d) => d.name === name);
}

// An option's value as the render uses it: the page's or the command line's, else the scene's, else the
// integrator's default.
function effective(key) {
  if (key in state.options) return state.options[key];
  if (key in state.scene_options) return state.scene_options[key];
  const doc = integratorDoc(state.integrator);
  const o = doc && doc.options.find((x) => x.name === key);
  return o ? o.default : undefined;
}

function showState(s) {
  state = s;
  $("scene").textContent = s.scene + " (" + s.width + "×" + s.height + ")";
  fill($("integrator"), s.catalog.integrators.map((d) => d.name), s.integrator);
  fill($("shadow_rays"), s.catalog.shadow_ray_policies.map((p) => p[0]), effective("shadow_rays"));
  fill($("light_sampler"), s.catalog.light_samplers, effective("light_sampler"));
  const doc = integratorDoc(s.integrator);
  for (const key of ["shadow_rays", "light_sampler"])
    $(key).disabled = !(doc && doc.options.some((o) => o.name === key));
  draw();
}

function sendOptions() {
  const integrator = $("integrator").value;
  const doc = integratorDoc(integrator);
  const options = {};
  for (const key of ["shadow_rays", "light_sampler"]) {
    if (doc && doc.options.some((o) => o.name === key) && !$(key).disabled) options[key] = $(key).value;
  }
  $("error").textContent = "";
  send({ type: "options", integrator, options });
}

// ---- the server ---------------------------------------------------------------------------------------

function send(msg) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(msg));
}

function connect() {
  ws = new WebSocket("ws://" + location.host + "/ws");
  ws.binaryType = "arraybuffer";
  ws.onopen = () => { $("connection").textContent = "connected"; };
  ws.onclose = () => {
    $("connection").textContent = "disconnected: is neepp view still running? (reload to reconnect)";
  };
  ws.onmessage = (event) => {
    if (event.data instanceof ArrayBuffer) {
      const decoded = decodeFrame(event.data);
      if (decoded.header.kind === "map") { showMap(decoded); return; }
      if (decoded.header.kind === "reference") { showReference(decoded); return; }
      frame = decoded;
      draw();
      showStats(frame.header);
      for (const f of listeners.slice()) f(frame.header);
      return;
    }
    const msg = JSON.parse(event.data);
    if (msg.type === "state") showState(msg);
    else if (msg.type === "error") $("error").textContent = msg.message;
    else if (msg.type === "saved") $("saved").textContent = "saved " + msg.files.join(", ");
  };
}

// ---- mouse and keys -----------------------------------------------------------------------------------

// Movements add up here and go to the server at most every 30 ms: one restart per batch, not per event.
const pending = { orbit: [0, 0], pan: [0, 0], dolly: 0, zoom: 0 };
let flushTimer = null;

function queue(apply) {
  apply(pending);
  if (flushTimer === null) flushTimer = setTimeout(flush, 30);
}

function flush() {
  flushTimer = null;
  if (pending.orbit[0] || pending.orbit[1]) send({ type: "orbit", dx: pending.orbit[0], dy: pending.orbit[1] });
  if (pending.pan[0] || pending.pan[1]) send({ type: "pan", dx: pending.pan[0], dy: pending.pan[1] });
  if (pending.dolly) send({ type: "dolly", amount: pending.dolly });
  if (pending.zoom) send({ type: "zoom", delta: pending.zoom });
  pending.orbit = [0, 0];
  pending.pan = [0, 0];
  pending.dolly = pending.zoom = 0;
}

let drag = null;

// A press and release without moving (fewer than CLICK_SLOP pixels) is a click: it asks for the map view
// from the pixel clicked; a larger movement is a drag, which moves the camera.
const CLICK_SLOP = 3;

function pick(clientX, clientY) {
  if (!state) return;
  const r = canvas.getBoundingClientRect();
  const x = Math.floor((clientX - r.left) / r.width * state.width);
  const y = Math.floor((clientY - r.top) / r.height * state.height);
  if (x >= 0 && y >= 0 && x < state.width && y < state.height) send({ type: "pick", x, y });
}

canvas.addEventListener("pointerdown", (e) => {
  drag = { x: e.clientX, y: e.clientY, x0: e.clientX, y0: e.clientY, moved: false, button: e.button,
           pan: e.button === 2 || e.shiftKey };
  if (canvas.setPointerCapture && e.pointerId !== undefined) {
    try { canvas.setPointerCapture(e.pointerId); } catch (_) { /* a synthetic pointer */ }
  }
  $("viewport").focus();
  e.preventDefault();
});
canvas.addEventListener("pointermove", (e) => {
  if (!drag) return;
  if (!drag.moved && Math.abs(e.clientX - drag.x0) + Math.abs(e.clientY - drag.y0) < CLICK_SLOP) return;
  drag.moved = true;
  const h = canvas.clientHeight || 1, w = canvas.clientWidth || 1;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.pan || e.shiftKey) queue((p) => { p.pan[0] += dx / h; p.pan[1] += dy / h; });
  else queue((p) => { p.orbit[0] += Math.PI * dx / w; p.orbit[1] += Math.PI * dy / h; });
});
const endDrag = () => { drag = null; };
canvas.addEventListener("pointerup", (e) => {
  if (drag && !drag.moved && drag.button === 0 && !e.shiftKey) pick(e.clientX, e.clientY);
  endDrag();
});
canvas.addEventListener("pointercancel", endDrag);
canvas.addEventListener("contextmenu", (e) => e.preventDefault());
canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const lines = e.deltaMode === 1 ? 40 : e.deltaMode === 2 ? 800 : 1;
  queue((p) => { p.dolly -= 0.002 * e.deltaY * lines; });
}, { passive: false });

const WALK = { w: [1, 0, 0], s: [-1, 0, 0], d: [0, 1, 0], a: [0, -1, 0], e: [0, 0, 1], q: [0, 0, -1] };
document.addEventListener("keydown", (e) => {
  if (e.target instanceof HTMLSelectElement || e.target instanceof HTMLInputElement) return;
  const k = e.key.toLowerCase();
  if ((e.ctrlKey || e.metaKey) && k === "s") { e.preventDefault(); save(); return; }
  if (e.ctrlKey || e.metaKey || e.altKey) return;
  if (k in WALK) send({ type: "move", forward: WALK[k][0], right: WALK[k][1], up: WALK[k][2] });
  else if (k === "arrowleft") queue((p) => { p.orbit[0] -= 0.1; });
  else if (k === "arrowright") queue((p) => { p.orbit[0] += 0.1; });
  else if (k === "arrowup") queue((p) => { p.orbit[1] -= 0.1; });
  else if (k === "arrowdown") queue((p) => { p.orbit[1] += 0.1; });
  else if (k === "+" || k === "=") queue((p) => { p.zoom -= 0.1; });
  else if (k === "-" || k === "_") queue((p) => { p.zoom += 0.1; });
  else if (k === "r") send({ type: "reset" });
  else if (k === "m") { $("mode").value = $("mode").value === "map" ? "image" : "map"; draw(); }
  else return;
  e.preventDefault();
});

function save() {
  $("saved").textContent = "saving…";
  send({ type: "save", exposure: Number($("exposure").value) });
}

$("exposure").addEventListener("input", () => {
  $("exposure-value").textContent = $("exposure").value;
  draw();
});
$("save").addEventListener("click", save);
$("mode").addEventListener("change", draw);
$("reference-saved").addEventListener("click", () => send({ type: "reference", source: "saved" }));
$("reference-none").addEventListener("click", () => send({ type: "reference", source: "none" }));
for (const id of ["integrator", "shadow_rays", "light_sampler"]) $(id).addEventListener("change", sendOptions);

// ---- self-test (#selftest): what the tests check in a real browser ---------------------------------------

// Resolves with the first frame header for which test(header) holds.
function waitFrame(test, what, timeoutMs) {
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => { remove(); reject(new Error("timed out waiting for " + what)); }, timeoutMs);
    const f = (h) => { if (test(h)) { clearTimeout(timer); remove(); resolve(h); } };
    const remove = () => { const i = listeners.indexOf(f); if (i >= 0) listeners.splice(i, 1); };
    listeners.push(f);
  });
}

function waitMap(what, timeoutMs) {
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => { remove(); reject(new Error("timed out waiting for " + what)); }, timeoutMs);
    const f = (h) => { clearTimeout(timer); remove(); resolve(h); };
    const remove = () => { const i = mapListeners.indexOf(f); if (i >= 0) mapListeners.splice(i, 1); };
    mapListeners.push(f);
  });
}

function fire(type, x, y, buttons) {
  canvas.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, buttons, button: 0, bubbles: true,
                                                pointerId: 1, pointerType: "mouse" }));
}

async function selftest() {
  const out = $("selftest");
  out.hidden = false;
  out.textContent = "selftest running";
  const log = [];
  try {
    // The image converges: two full frames of the first view, the second with more samples.
    const a = await waitFrame((h) => !h.coarse, "a first full frame", 15000);
    const b = await waitFrame((h) => !h.coarse && h.view === a.view && h.spp > a.spp, "a converging frame", 15000);
    log.push(`view ${a.view}: ${a.spp} -> ${b.spp} spp`);
    // A drag moves the camera: a new view, which starts again from few samples and converges.
    const r = canvas.getBoundingClientRect();
    const x = r.left + r.width / 2, y = r.top + r.height / 2;
    fire("pointerdown", x, y, 1);
    fire("pointermove", x - 3, y + 1, 1);
    fire("pointerup", x - 3, y + 1, 0);
    const c = await waitFrame((h) => h.view > b.view, "a frame of the moved view", 15000);
    if (!(c.coarse || c.spp < b.spp)) throw new Error(`the moved view did not restart (${c.spp} spp)`);
    const d = await waitFrame((h) => !h.coarse && h.view === c.view && h.spp > 1, "the moved view converging", 15000);
    log.push(`drag: view ${c.view} restarted at ${c.spp} spp${c.coarse ? " (coarse)" : ""}, then ${d.spp} spp`);
    // An option changes the statistics: NEE++'s adaptive policy skips shadow rays.
    $("shadow_rays").value = "neepp-adaptive";
    $("shadow_rays").dispatchEvent(new Event("change"));
    const e = await waitFrame((h) => h.options.shadow_rays === "neepp-adaptive" && !h.coarse && h.shadow_rays_skipped > 0,
                              "shadow rays skipped with neepp-adaptive", 15000);
    const shown = Number(document.querySelector('#stats td[data-key="shadow_rays_skipped"]').dataset.value);
    if (shown !== e.shadow_rays_skipped) throw new Error("the statistics table does not show the frame's numbers");
    log.push(`neepp-adaptive: ${e.shadow_rays_skipped} shadow rays skipped at ${e.spp} spp`);
    // A click (no movement) shows the map from the point clicked: a heat map of Ṽ over the image, with
    // values that differ (the room's walls see the clicked point, the corridor behind the door does not).
    const now = canvas.getBoundingClientRect();
    const cx = now.left + now.width * 0.4, cy = now.top + now.height * 0.6;
    const mapped = waitMap("the map view", 15000);
    fire("pointerdown", cx, cy, 1);
    fire("pointerup", cx, cy, 0);
    const m = await mapped;
    if (!m.hit || !m.map || !m.width) throw new Error("the click gave no map view: " + JSON.stringify(m).slice(0, 300));
    if ($("mode").value !== "map") throw new Error("the click did not switch to the map view");
    if (m.view !== frame.header.view || frame.header.coarse) await waitFrame((h) => !h.coarse && h.view === m.view, "a frame to draw the map over", 15000);
    draw();
    if (!overlay || overlay.view !== m.view || !(overlay.known > 0) || !(overlay.max > overlay.min))
      throw new Error("no heat map over the image: " + JSON.stringify(overlay));
    if (!$("map-summary").textContent.includes("known for")) throw new Error("the map panel says nothing");
    log.push(`map from cell ${m.cell}: ${overlay.known} pixels, V~ ${overlay.min.toFixed(3)}..${overlay.max.toFixed(3)}, ${m.lights.length} light(s)`);
    // The relMSE view (the server was started with a reference): the map drawn here averages to the relMSE
    // the server measured for the frame.
    $("mode").value = "relmse";
    $("mode").dispatchEvent(new Event("change"));
    const f = await waitFrame((h) => !h.coarse && h.relmse !== undefined, "a frame with its relMSE", 15000);
    draw();
    if (!overlay || !(Math.abs(overlay.relmse - f.relmse) <= 1e-3 * f.relmse))
      throw new Error(`the relMSE map averages to ${overlay && overlay.relmse}, the server says ${f.relmse}`);
    if (document.querySelector('#stats td[data-key="relmse"]').textContent === "–")
      throw new Error("the statistics do not show the relMSE");
    log.push(`relMSE ${f.relmse.toExponential(3)} at ${f.spp} spp`);
    out.textContent = "selftest ok: " + log.join("; ");
  } catch (err) {
    out.textContent = "selftest FAILED: " + err.message + " (" + log.join("; ") + ")";
  }
}

connect();
if (location.hash === "#selftest") selftest();
