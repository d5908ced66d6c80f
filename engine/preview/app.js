// The preview page's script (docs/preview.md): polls /status, loads /frame.png when a new
// picture is out, and turns drags, the wheel and the arrow keys into camera moves posted to
// /camera. Nothing here loads from anywhere but this server.
"use strict";
const $ = (id) => document.getElementById(id);
let shown = 0;           // the frame on screen
let loading = false;
let camera = null;       // {eye, look, up, fov}: the server's, then the page's own while moving
let size = null;         // the full picture's width and height
let drag = null;         // {x, y, pan, camera} while a button is down
let moveTimer = null;
let statement = "";
let view = "picture";    // picture, samples (adaptive sampling's sample map) or profile
let hasSamples = false;

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a) => Math.sqrt(dot(a, a));
const norm = (a) => mul(a, 1 / len(a));
// Rodrigues: v turned by angle t about the unit axis k.
const rotate = (v, k, t) => add(add(mul(v, Math.cos(t)), mul(cross(k, v), Math.sin(t))), mul(k, dot(k, v) * (1 - Math.cos(t))));
const vec = (v) => v.map((x) => +x.toPrecision(6)).join(",");

function post(path, body) {
  return fetch(path, { method: "POST", body: body, headers: { "Content-Type": "text/plain" } })
    .then((r) => r.text().then((t) => { if (!r.ok) throw new Error(t.trim()); return t.trim(); }));
}

function say(text) { $("message").textContent = text; }

// One camera request at a time: a move made while one is on its way is sent when it returns
// (the latest only), so a fast drag does not cancel every picture before it is done.
let inFlight = false, pending = null;
function sendCamera(moving) {
  if (inFlight) { pending = moving; return; }
  inFlight = true;
  post("/camera", `eye=${vec(camera.eye)}&look=${vec(camera.look)}&up=${vec(camera.up)}&fov=${+camera.fov.toPrecision(6)}&moving=${moving ? 1 : 0}`)
    .catch((e) => say(e.message))
    .finally(() => {
      inFlight = false;
      if (pending !== null) { const m = pending; pending = null; sendCamera(m); }
    });
}

// While the camera moves: reduced passes at once; a moment after the last move, the full one.
function moved() {
  sendCamera(true);
  clearTimeout(moveTimer);
  moveTimer = setTimeout(() => { moveTimer = null; sendCamera(false); }, 250);
}

function orbit(dx, dy, from) {
  const up = norm(from.up);
  let offset = sub(from.eye, from.look);
  offset = rotate(offset, up, -dx * 0.01);
  const right = norm(cross(offset, up));
  const tilted = rotate(offset, right, dy * 0.01);
  // Not over the pole: the view must not become parallel to up.
  if (Math.abs(dot(norm(tilted), up)) < 0.995) offset = tilted;
  camera = { ...from, eye: add(from.look, offset) };
}

function pan(dx, dy, from) {
  const forward = sub(from.look, from.eye);
  const right = norm(cross(forward, from.up));
  const up = norm(cross(right, forward));
  const scale = len(forward) * 2 * Math.tan(from.fov * Math.PI / 360) / (size ? size[1] : 480);
  const shift = add(mul(right, -dx * scale), mul(up, dy * scale));
  camera = { ...from, eye: add(from.eye, shift), look: add(from.look, shift) };
}

function dolly(factor) {
  const offset = sub(camera.eye, camera.look);
  camera = { ...camera, eye: add(camera.look, mul(offset, factor)) };
}

$("view").addEventListener("mousedown", (e) => {
  if (!camera) return;
  drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey, camera: { ...camera } };
  e.preventDefault();
});
window.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  if (drag.pan) pan(dx, dy, drag.camera); else orbit(dx, dy, drag.camera);
  moved();
});
window.addEventListener("mouseup", () => { drag = null; });
$("view").addEventListener("wheel", (e) => {
  if (!camera) return;
  dolly(e.deltaY > 0 ? 1.1 : 1 / 1.1);
  moved();
  e.preventDefault();
}, { passive: false });
$("view").addEventListener("keydown", (e) => {
  if (!camera) return;
  const step = 20, from = { ...camera };
  const keys = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step] };
  if (e.key === "+" || e.key === "=") dolly(1 / 1.1);
  else if (e.key === "-") dolly(1.1);
  else if (keys[e.key]) { if (e.shiftKey) pan(...keys[e.key], from); else orbit(...keys[e.key], from); }
  else return;
  moved();
  e.preventDefault();
});

$("apply").addEventListener("click", () => {
  post("/settings", `degree=${$("degree").value}&spp=${$("spp").value}&engine=${$("engine").value}`)
    .then(() => say("")).catch((e) => say(e.message));
});
$("copy-camera").addEventListener("click", () => {
  const done = () => say("copied: " + statement);
  if (navigator.clipboard) navigator.clipboard.writeText(statement).then(done, () => say(statement));
  else say(statement);
});
$("render-full").addEventListener("click", () => {
  say("rendering the full-size picture...");
  post("/render-full", "").then(say).catch((e) => say(e.message));
});
$("view-select").addEventListener("change", () => {
  view = $("view-select").value;
  $("profile").style.display = view === "profile" ? "block" : "none";
  $("view").style.display = view === "profile" ? "none" : "inline-block";
  shown = 0;  // load the picture of the view chosen
});
$("reset-camera").addEventListener("click", () => { location.reload(); });

// A test hook (docs/preview.md): `?drag=DX,DY` drags the picture by DX, DY pixels once the
// first picture is shown, through synthetic mouse events on the picture, so the page's own
// handlers and orbit code above run as for a person's drag. The browser test uses it.
const dragHook = (/[?&]drag=(-?\d+),(-?\d+)(&|$)/.exec(location.search) || []).slice(1, 3).map(Number);
let dragDone = dragHook.length !== 2;
function scriptedDrag() {
  dragDone = true;
  const img = $("picture"), box = img.getBoundingClientRect();
  const x0 = box.left + box.width / 2, y0 = box.top + box.height / 2, steps = 5;
  const at = (type, x, y, target) => target.dispatchEvent(new MouseEvent(type,
    { bubbles: true, cancelable: true, view: window, clientX: x, clientY: y, button: 0, buttons: type === "mouseup" ? 0 : 1 }));
  at("mousedown", x0, y0, img);
  let i = 0;
  const step = () => {
    i++;
    const x = x0 + dragHook[0] * i / steps, y = y0 + dragHook[1] * i / steps;
    at("mousemove", x, y, img);
    if (i < steps) setTimeout(step, 20);
    else { at("mouseup", x, y, img); img.dataset.dragged = `${dragHook[0]},${dragHook[1]}`; }
  };
  setTimeout(step, 20);
}

function loadFrame(id) {
  loading = true;
  fetch(view === "samples" && hasSamples ? "/samples.png" : "/frame.png", { cache: "no-store" }).then((r) => {
    if (!r.ok) throw new Error("no picture");
    return r.blob();
  }).then((blob) => {
    const img = $("picture"), old = img.src;
    img.onload = () => {
      if (old) URL.revokeObjectURL(old);
      if (!dragDone && camera) scriptedDrag();
    };
    img.src = URL.createObjectURL(blob);
    if (size) { img.style.width = size[0] + "px"; img.style.height = size[1] + "px"; }
    shown = id;
    img.dataset.frame = String(id);
  }).catch(() => {}).finally(() => { loading = false; });
}

function poll() {
  fetch("/status", { cache: "no-store" }).then((r) => r.json()).then((s) => {
    size = [s.width, s.height];
    if (!drag && !moveTimer) camera = s.camera;
    statement = s.camera_statement;
    $("scene").textContent = s.scene;
    for (const k of ["degree", "spp"]) if (document.activeElement !== $(k)) $(k).value = s[k];
    if (document.activeElement !== $("engine")) $("engine").value = s.engine;
    const p = s.picture;
    hasSamples = !!(p && p.sample_map);
    $("profile").textContent = p && p.profile ? p.profile : "the profile comes with the stream engine's full pass";
    if (view === "samples" && !hasSamples) say("no sample map: the scene does not sample adaptively (image adaptive=)");
    let line = `frame ${s.frame} · ${s.pass}`;
    if (s.pass !== "idle") line += ` ${Math.round(s.progress * 100)}%`;
    if (p) line += ` · ${p.width}x${p.height} spp ${p.spp} · ${(p.rays_per_second / 1e6).toFixed(2)} Mrays/s · ${p.seconds.toFixed(3)} s`;
    if (p && p.estimated_error !== null) line += ` · estimated error ${p.estimated_error.toPrecision(3)}`;
    $("status").textContent = line;
    $("error").textContent = s.error;
    $("error").style.display = s.error ? "block" : "none";
    if (s.frame !== shown && !loading) loadFrame(s.frame);
  }).catch(() => { $("status").textContent = "the server does not answer"; })
    .finally(() => setTimeout(poll, drag || moveTimer ? 30 : 100));
}
poll();
