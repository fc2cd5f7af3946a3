// limn's page: pick or upload a mesh (or an implicit scene), choose a method and what to draw,
// orbit the camera, and compare the approximation with the exact reference. Every picture comes
// from the server (POST /v1/render; POST /v1/implicit for scenes); while the camera is dragged the page draws the approximation's triangles
// itself (POST /v1/tessellate, WebGL 2: glview.js), or, without WebGL or before they arrive,
// shows small renders, and the full-size picture follows when the drag ends. See docs/web.md.
import { ApiProblem, UploadedMesh, getJson, getText, meshFileFormats, post, postBinary } from "/api.js";
import { MeshView, parseGlb } from "/glview.js";
import { LOG_FLOOR, rescaleDiff } from "/diff.js";
import { formatNumber, metricsTables } from "/metrics.js";
import { panelSize, pixelSize } from "/layout.js";

const $ = (id) => document.getElementById(id);
const DEFAULT_VIEW = { azimuthDeg: 30, elevationDeg: 20, distance: null };
let firstView = DEFAULT_VIEW;  // the example's own view (examples.json "orbit"), else DEFAULT_VIEW
const PREVIEW_DIVISOR = 4;  // drag previews render at a quarter of the size in each direction
const LOCAL_MAX_TRIANGLES = 400_000;  // larger approximations are previewed by small renders
// The local view's level of detail while dragging: an approximation of more triangles is drawn
// coarser (fewer iterations, a coarser dicing rate: see dragParams), into a drawing buffer of at
// most LOCAL_MAX_SIDE a side (scaled up to fit the panel).
const DRAG_TRIANGLES = 20_000;
const LOCAL_MAX_SIDE = 768;
// The server's default limits (docs/api.md, "Limits"; configs/default.json). The number
// controls carry them as min/max, and a value outside them is refused here, at its control,
// instead of being sent (the server would answer 400 or 413 naming the same limit).
const LIMITS = { minDicingRate: 0.25, maxLevel: 6, maxIsolation: 8, maxImageSide: 4096,
                 maxResolution: 512 };
// Pictures are requested at the size they are shown, in device pixels, at most this long a side
// (half of maxImageSide: a compare render stays within a second or two).
const MAX_REQUEST_SIDE = Math.min(2048, LIMITS.maxImageSide);

// What the browser tests (and a curious person in the console) can read.
const page = (window.limnPage = {
  renders: 0,            // full-size pictures shown
  previews: 0,           // drag previews shown (small renders from the server)
  turntables: 0,         // turntable animations shown
  localFrames: 0,        // drag frames the page drew itself (WebGL)
  firstPictureMs: null,  // performance.now() when the first full-size picture was shown
  dragToFullMs: null,    // from the last drag's end to its full-size picture
  lastAnswer: null,
  get dragTriangles() { return state.glView?.triangles ?? 0; },  // what the local view draws
  get requestSize() { return requestSize(); },  // {width, height} of the next full picture
  get layout() { return { ...layout }; },        // the panels' picture size in CSS pixels
  // A full-size render (or a mesh's upload) is in flight.
  get busy() { return state.full !== null || state.uploads > 0; },
  // The local view holds the approximation the settings ask for (drags will draw it).
  get localReady() {
    return Boolean(state.glView?.ready && state.glView.key === tessellationKey() && state.frame);
  },
  // The local view at the current camera, drawn now, as a PNG data URL (tests compare it with
  // the server's picture of the same camera).
  localSnapshot() {
    state.glView.draw(orbitCamera(), requestSize(), {
      surface: $("draw-surface").checked, cage: $("draw-cage").checked,
      flat: $("shading").value === "flat", opaque: $("background").value !== "transparent",
    });
    return $("gl-canvas").toDataURL("image/png");
  },
});

const state = {
  examples: [],
  mesh: null,           // UploadedMesh
  meshText: null,       // OBJ text or JSON mesh object, for the client-side cage
  meshFile: null,       // {bytes, format, name} of a mesh file the server reads (glb, ply, ...)
  view: { ...DEFAULT_VIEW },
  full: null,           // AbortController of the full-size render in flight
  preview: { busy: false, again: false },
  dragEndedAt: null,
  frame: null,          // {target, radius, fovYDeg} of the mesh, from the last answer's camera
  glView: null,         // MeshView, when the browser has WebGL 2
  tessellation: null,   // AbortController of the POST /v1/tessellate in flight
  turntableTimer: null,  // the interval that plays a turntable's views
  scene: null,          // an implicit scene ({field, ...}: a /v1/implicit request) instead of a mesh
  uploads: 0,           // mesh uploads in flight
  diff: null,           // {image, scale}: the last answer's difference image and its top
  restoring: null,      // an address's parameters, applied once the first mesh is chosen
  shownExample: null,   // the example and scheme of the last picture (a refused upload's way back)
  shownScheme: null,
  dragging: false,
};

// An implicit scene sent whole with every request; it stands where an UploadedMesh would.
class SceneSource {
  constructor(request) { this.request = request; this.id = null; }
  withId(request) { return request(null); }
}

// ---------------------------------------------------------------- errors next to controls

const errorSlots = { mesh: "mesh-error", method: "method-error", draw: "draw-error",
                     view: "page-error", page: "page-error" };

function clearErrors() {
  for (const id of new Set(Object.values(errorSlots))) $(id).hidden = true;
}

function showError(problem) {
  const slot = problem instanceof ApiProblem ? errorSlots[problem.control] : "page-error";
  showMessage(slot, problem instanceof ApiProblem ? `${problem.status}: ${problem.text}`
                                                 : `Could not reach limn: ${problem.message}`);
}

function showMessage(slot, text) {
  $(slot).textContent = text;
  $("stale-text").textContent = `out of date: ${text}`;
  $(slot).hidden = false;
  if (getComputedStyle($("controls")).visibility !== "hidden") {
    $(slot).scrollIntoView({ block: "nearest" });
  }
}

function setBusy(text) {
  $("progress").hidden = !text;
  if (text) $("progress-text").textContent = text;
}

// ---------------------------------------------------------------- the request

function methodParams() {
  const method = $("method").value;
  if (method === "uniform") return { level: Number($("level").value), engine: $("engine").value };
  if (method === "adaptive") return { dicingRate: Number($("dicing-rate").value) };
  if (method === "patches") {
    return { dicingRate: Number($("patch-dicing-rate").value), isolation: Number($("isolation").value) };
  }
  if (method === "silhouette") {
    const p = $("presubdivide").value;
    return { contour: $("contour-mode").value, presubdivide: p === "auto" ? "auto" : Number(p) };
  }
  return {};
}

// The image the view shows: the cage drawn over the surface, or its wireframe, or its colour.
function mainOutput() {
  if ($("method").value === "patches" && $("show-patches").checked) return "patches";
  if ($("draw-cage").checked && $("method").value !== "limit") return "cage";
  if ($("draw-wireframe").checked) return "wireframe";
  return "color";
}

// size: {width, height} in pixels.
function cameraFor(size) {
  const orbit = { azimuthDeg: state.view.azimuthDeg, elevationDeg: state.view.elevationDeg };
  if (state.view.distance) orbit.distance = state.view.distance;
  const camera = { orbit, width: size.width, height: size.height };
  if ($("orthographic").checked) {
    camera.projection = "orthographic";
    const height = orthoHeight();
    if (height) camera.orthoHeight = height;
  }
  return camera;
}

// An orthographic view's height: the server's default (2.1 radii, the bounding sphere with a
// margin) scaled as the orbit's distance is, so the wheel zooms it too; null for the default.
function orthoHeight() {
  if (!state.view.distance || !state.frame) return null;
  return 2.1 * state.frame.radius * state.view.distance / framingRadii(state.frame.fovYDeg);
}

function renderBody(mesh, size, compare) {
  const outputs = [mainOutput()];
  // The reference panel shows colour: ask for it when the main picture is another output.
  if (compare && outputs[0] !== "color") outputs.push("color");
  if (compare) outputs.push("diff");
  const background = $("background").value;
  if (state.scene) {
    return { field: state.scene.field, camera: cameraFor(size), outputs, reference: compare, background,
             shading: $("shading").value === "flat" ? "flat" : "smooth",
             polygonizer: { method: $("polygonizer").value, resolution: Number($("resolution").value),
                            flatness: Number($("flatness").value) } };
  }
  const body = { mesh, camera: cameraFor(size), method: $("method").value, params: methodParams(),
                 shading: $("shading").value, outputs, reference: compare, background };
  const displacement = displacementOf(body.method);
  if (displacement) body.displacement = displacement;
  return body;
}

// The displacement the page asks for: drawn by adaptive and patches, ray-cast by limit.
function displacementOf(method) {
  const fn = $("displacement").value;
  if (fn === "none" || !["adaptive", "patches", "limit"].includes(method)) return null;
  return { function: fn, amplitude: Number($("displacement-amplitude").value),
           frequency: Number($("displacement-frequency").value) };
}

// Where the page's renders go: meshes to /v1/render, implicit scenes to /v1/implicit.
const renderPath = () => (state.scene ? "/v1/implicit" : "/v1/render");

const comparing = () =>
  $("compare").checked && (state.scene !== null || $("method").value !== "limit");
const sliderLayout = () =>
  document.querySelector("input[name=compare-layout]:checked").value === "slider";

// ---------------------------------------------------------------- layout

// The size (CSS pixels) of each picture: the space there is beside the controls, for one
// picture, or two (slider: the approximation and the difference), or three side by side or
// stacked, whichever leaves them largest; on a narrow screen each takes the whole width.
const layout = { w: 512, h: 512 };

function layoutPanels() {
  document.body.classList.toggle("comparing", comparing());
  const panels = $("panels");
  const top = panels.getBoundingClientRect().top + window.scrollY;
  Object.assign(layout, panelSize(panels.clientWidth - 2,  // the frames' borders
                                  window.innerHeight - top - 10,
                                  !comparing() ? 1 : sliderLayout() ? 2 : 3));
  panels.style.setProperty("--w", `${layout.w}px`);
  panels.style.setProperty("--h", `${layout.h}px`);
}

// The full picture's size in pixels: the panel's size in device pixels ("as shown"), or the
// chosen size along the longer side, within MAX_REQUEST_SIDE.
const requestSize = () => pixelSize(layout, $("size").value, window.devicePixelRatio || 1,
                                    MAX_REQUEST_SIDE);

const scaled = (size, factor) => ({ width: Math.max(16, Math.round(size.width * factor)),
                                    height: Math.max(16, Math.round(size.height * factor)) });

// ---------------------------------------------------------------- rendering

function imageUrl(image) { return `data:${image.mime};base64,${image.data}`; }

function showImage(img, image) {
  return new Promise((resolve) => {
    img.onload = img.onerror = () => resolve();
    img.src = imageUrl(image);
  });
}

// The full-size picture (and, comparing, the reference, the diff and the metrics). A newer
// call aborts the one in flight: only the latest camera and settings are worth finishing.
async function renderFull() {
  if (!state.mesh) return;
  offerWhatWorks();
  layoutPanels();
  applyLayout();
  state.full?.abort();
  if (refuseInvalidInput()) return;
  stopTurntable();
  const controller = (state.full = new AbortController());
  const compare = comparing();
  const sentView = { ...state.view };
  // A zoomed orthographic view's height needs the mesh's size, known from the first answer.
  const orthoUnknown = $("orthographic").checked && state.view.distance && !orthoHeight();
  setBusy(compare ? "rendering and ray-casting the reference…" : "rendering…");
  const contours = $("draw-contours").checked ? loadContours(controller.signal) : null;
  try {
    const answer = await state.mesh.withId(
        (mesh) => post(renderPath(), renderBody(mesh, requestSize(), compare),
                       { signal: controller.signal }),
        controller.signal);
    if (controller.signal.aborted) return;
    clearErrors();
    await showAnswer(answer, compare);
    if (controller.signal.aborted) return;
    page.renders += 1;
    page.lastAnswer = answer;
    rememberFrame(answer.camera, sentView);
    if (orthoUnknown) {  // now known: ask again (the first picture stays up meanwhile)
      renderFull();
      return;
    }
    loadTessellation(answer.stats.triangles);
    const now = performance.now();
    if (page.firstPictureMs === null) page.firstPictureMs = now;
    if (state.dragEndedAt !== null) {
      page.dragToFullMs = now - state.dragEndedAt;
      state.dragEndedAt = null;
    }
    $("view").dataset.renders = String(page.renders);
    state.shownExample = $("example").value;  // what an upload that fails goes back to
    state.shownScheme = $("scheme").value;
    rememberInAddress();
  } catch (problem) {
    if (problem.name === "AbortError") return;
    showError(problem);
    // What is shown no longer answers the settings: say so until a render succeeds.
    document.body.classList.add("stale");
    if (problem instanceof ApiProblem && problem.status === 429) {
      setTimeout(renderFull, problem.retryAfter * 1000);
    }
  } finally {
    if (state.full === controller) {
      state.full = null;
      setBusy(null);
    }
  }
  await contours;
}

async function showAnswer(answer, compare) {
  document.body.classList.remove("stale");
  showWarnings(answer.warnings);
  const image = answer.images[mainOutput()] || answer.images.color;
  const shown = [showImage($("picture"), image)];
  $("gl-canvas").hidden = true;
  $("picture").classList.toggle("hidden-surface", !$("draw-surface").checked);
  drawClientCage(answer.camera);
  const s = answer.stats, t = answer.timings;
  $("stats").textContent = `${s.triangles.toLocaleString("en")} triangles · ` +
      (state.scene ? `${s.closed ? "closed" : "not closed"} · ${s.implicit.primitives} primitives`
                   : `${s.controlFaces.toLocaleString("en")} control faces`) +
      ` · ${t.totalMs.toFixed(0)} ms`;
  $("stats").dataset.triangles = String(s.triangles);
  if (compare) {
    shown.push(showImage($("reference"), answer.reference.images.color));
    shown.push(showImage($("slider-reference"), answer.reference.images.color));
    state.diff = answer.images.diff ? { image: answer.images.diff, scale: answer.metrics.image?.diffScale }
                                    : null;
    if (state.diff) shown.push(showDiff());
    $("metrics").replaceChildren(...metricsTables(answer));
  }
  await Promise.all(shown);
}

// Drag previews: at most one in flight; when it lands, the newest camera goes next.
async function renderPreview() {
  if (!state.mesh) return;
  if (state.preview.busy) {
    state.preview.again = true;
    return;
  }
  state.preview.busy = true;
  try {
    const size = scaled(requestSize(), 1 / PREVIEW_DIVISOR);
    const answer = await state.mesh.withId(
        (mesh) => post(renderPath(), renderBody(mesh, size, false)));
    if ((state.dragging || state.full === null) && $("gl-canvas").hidden) {
      await showImage($("picture"), answer.images[mainOutput()] || answer.images.color);
      drawClientCage(answer.camera);
      page.previews += 1;
    }
  } catch (problem) {
    if (problem.name !== "AbortError") showError(problem);
  } finally {
    state.preview.busy = false;
    if (state.preview.again && state.dragging) {
      state.preview.again = false;
      renderPreview();
    }
  }
}

// ---------------------------------------------------------------- the local view while dragging

const framingRadii = (fovYDeg) => 1.05 / Math.sin((fovYDeg * Math.PI) / 360);

// The mesh's bounding sphere as the server sees it, from an answer's camera and the orbit the
// page asked for: target = its centre, |eye - target| = distance (in radii) * radius.
function rememberFrame(camera, sentView) {
  const d = Math.hypot(...camera.eye.map((e, i) => e - camera.target[i]));
  const radii = sentView.distance || framingRadii(camera.fovYDeg);
  state.frame = { target: camera.target, radius: d / radii, fovYDeg: camera.fovYDeg };
}

// What resolveCamera (render/core/camera.cpp) makes of the page's orbit.
function orbitCamera() {
  const { target, radius, fovYDeg } = state.frame;
  const az = (state.view.azimuthDeg * Math.PI) / 180, el = (state.view.elevationDeg * Math.PI) / 180;
  const dir = [Math.cos(el) * Math.sin(az), Math.sin(el), Math.cos(el) * Math.cos(az)];
  const distance = (state.view.distance || framingRadii(fovYDeg)) * radius;
  const ortho = $("orthographic").checked;
  return {
    eye: target.map((t, i) => t + dir[i] * distance),
    target,
    up: [-Math.sin(el) * Math.sin(az), Math.cos(el), -Math.sin(el) * Math.cos(az)],
    fovYDeg,
    projection: ortho ? "orthographic" : "perspective",
    orthoHeight: orthoHeight() || 2.1 * radius,
    near: ortho ? distance - 1.01 * radius : Math.max(distance - 1.01 * radius, radius * 1e-3),
    far: distance + 1.01 * radius,
  };
}

// The approximation's triangles for the local view: fetched after a full render whenever the
// mesh, method or parameters changed, unless they are too many to send quickly.
// Which approximation the local view would show now.
const tessellationKey = () =>
  JSON.stringify([state.mesh?.id, $("method").value, methodParams()]);

async function loadTessellation(triangles) {
  const view = state.glView;
  if (!view || !state.mesh || state.scene) return;  // scenes are previewed by small renders
  const key = tessellationKey();
  const method = $("method").value;
  if (view.key === key || method === "limit") return;
  if (!COARSENED.includes(method) && triangles > LOCAL_MAX_TRIANGLES) return;
  state.tessellation?.abort();
  const controller = (state.tessellation = new AbortController());
  try {
    const glb = await state.mesh.withId(
        (mesh) => postBinary("/v1/tessellate",
                             { mesh, camera: cameraFor(requestSize()), method,
                               params: dragParams(triangles) },
                             { signal: controller.signal, accept: "model/gltf-binary" }),
        controller.signal);
    view.setMesh(parseGlb(glb), key);
  } catch (problem) {
    if (problem.name !== "AbortError") console.warn("no local view:", problem.message);
  }
}

// The methods whose drag view can be coarser than the picture.
const COARSENED = ["uniform", "adaptive", "patches"];

// The parameters of the approximation the local view draws: the method's own, or, when it has
// more than DRAG_TRIANGLES triangles, fewer iterations (each one is 4 times the triangles) or a
// dicing rate coarser by the square root of the excess.
function dragParams(triangles) {
  const method = $("method").value, params = methodParams();
  const excess = triangles / DRAG_TRIANGLES;
  if (excess <= 1) return params;
  if (method === "uniform") {
    return { ...params, level: Math.max(0, params.level - Math.ceil(Math.log(excess) / Math.log(4))) };
  }
  if (method === "adaptive" || method === "patches") {
    return { ...params, dicingRate: params.dicingRate * Math.sqrt(excess) };
  }
  return params;
}

let frameRequested = false;
// One frame of the local view at the current orbit (at most one per display frame).
function drawLocal() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(() => {
    frameRequested = false;
    if (!state.glView?.ready || !state.frame) return;
    const full = requestSize();
    const fit = Math.min(1, LOCAL_MAX_SIDE / Math.max(full.width, full.height));
    state.glView.draw(orbitCamera(), scaled(full, fit), {
      surface: $("draw-surface").checked, cage: $("draw-cage").checked,
      flat: $("shading").value === "flat", opaque: $("background").value !== "transparent",
    });
    $("gl-canvas").hidden = false;
    $("picture").classList.add("hidden-surface");
    $("cage-canvas").hidden = true;
    page.localFrames += 1;
  });
}

// While the camera moves: the local view when it can, else a small render.
function previewMove() {
  hideContours();
  const local = state.glView?.ready && state.glView.key === tessellationKey() && state.frame;
  if (local) drawLocal(); else renderPreview();
}

// The contour of the limit surface (POST /v1/silhouette, SVG: hidden pieces dashed), laid over
// the picture and the reference with a multiply blend so its white background disappears.
async function loadContours(signal) {
  try {
    const svg = await state.mesh.withId(
        (mesh) => post("/v1/silhouette", { mesh, camera: cameraFor(requestSize()), format: "svg" },
                       { signal, accept: "image/svg+xml" }), signal);
    for (const id of ["contours-overlay", "reference-contours"]) {
      $(id).innerHTML = svg;
      $(id).hidden = false;
    }
  } catch (problem) {
    if (problem.name !== "AbortError") showError(problem);
  }
}

function hideContours() {
  for (const id of ["contours-overlay", "reference-contours"]) $(id).hidden = true;
}

// ---------------------------------------------------------------- the difference image

// Shows state.diff with the chosen scale (diff.js); the legend says which.
async function showDiff() {
  const { image, scale } = state.diff;
  const mode = $("diff-top").value;
  if (mode === "largest" || !(scale > 0)) {
    $("diff-scale").textContent = `${formatNumber(scale)} (the largest)`;
    return showImage($("diff"), image);
  }
  const { url, top } = await rescaleDiff(imageUrl(image), scale, mode);
  $("diff-scale").textContent = mode === "log"
      ? `${formatNumber(scale)} (logarithmic from ${formatNumber(LOG_FLOOR)})`
      : `${formatNumber(top)} (${mode}th percentile; brighter pixels clamped)`;
  return new Promise((resolve) => {
    $("diff").onload = $("diff").onerror = () => resolve();
    $("diff").src = url;
  });
}

// ---------------------------------------------------------------- the cage without the surface

// With the surface switched off the server has nothing to draw the cage over, so the page
// draws the control mesh's edges itself, projected with the camera the answer resolved.
function drawClientCage(camera) {
  const canvas = $("cage-canvas");
  const show = !$("draw-surface").checked && $("draw-cage").checked && state.meshText;
  canvas.hidden = !show;
  if (!show) return;
  const { points, faces } = cageOf(state.meshText);
  const w = (canvas.width = camera.width), h = (canvas.height = camera.height);
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                           a[0] * b[1] - a[1] * b[0]];
  const unit = (a) => { const l = Math.hypot(...a); return a.map((x) => x / l); };
  const forward = unit(sub(camera.target, camera.eye));
  const right = unit(cross(forward, camera.up)), up = cross(right, forward);
  const f = 1 / Math.tan((camera.fovYDeg * Math.PI) / 360);
  const project = (p) => {
    const d = sub(p, camera.eye), z = dot(d, forward);
    if (camera.projection === "orthographic") {
      const s = h / camera.orthoHeight;
      return [w / 2 + dot(d, right) * s, h / 2 - dot(d, up) * s];
    }
    return [w / 2 + (dot(d, right) / z) * f * (h / 2), h / 2 - (dot(d, up) / z) * f * (h / 2)];
  };
  const ctx = canvas.getContext("2d");
  ctx.clearRect(0, 0, w, h);
  ctx.strokeStyle = "#1f3a93";
  ctx.lineWidth = Math.max(1, w / 400);
  ctx.beginPath();
  const projected = points.map(project);
  for (const face of faces) {
    face.forEach((v, i) => {
      const [x, y] = projected[v];
      if (i === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
    });
    ctx.closePath();
  }
  ctx.stroke();
  ctx.fillStyle = "#1f3a93";
  for (const [x, y] of projected) ctx.fillRect(x - 1.5, y - 1.5, 3, 3);
}

// Points and faces (0-based) of an OBJ text or a JSON mesh.
function cageOf(mesh) {
  if (typeof mesh !== "string") {
    const faces = [];
    let k = 0;
    for (const n of mesh.faceVertexCounts || []) {
      faces.push(mesh.faceVertexIndices.slice(k, k + n));
      k += n;
    }
    return { points: mesh.points || [], faces };
  }
  const points = [], faces = [];
  for (const line of mesh.split(/\r\n|\r|\n/)) {
    const words = line.trim().split(/\s+/);
    if (words[0] === "v") points.push(words.slice(1, 4).map(Number));
    if (words[0] === "f") {
      faces.push(words.slice(1).map((w) => {
        const i = parseInt(w, 10);
        return i < 0 ? points.length + i : i - 1;
      }));
    }
  }
  return { points, faces };
}

// ---------------------------------------------------------------- meshes

// The mesh as sent, with the page's scheme and boundary/crease choices applied: for OBJ they
// replace the file's own tag lines, for the JSON form its fields.
function wireMesh(source) {
  const scheme = $("scheme").value, boundary = $("boundary").value;
  const creaseMethod = $("crease-method").value;
  if (typeof source !== "string") {
    const mesh = { ...source, scheme };
    if (boundary) mesh.interpolateBoundary = boundary;
    if (creaseMethod) mesh.creaseMethod = creaseMethod;
    return mesh;
  }
  let data = source;
  if (boundary) {
    const k = { none: 0, "edge-and-corner": 1, "edge-only": 2 }[boundary];
    data = data.replace(/^t\s+interpolateboundary\b.*$/gm, "") + `\nt interpolateboundary 1/0/0 ${k}\n`;
  }
  if (creaseMethod) {
    const name = creaseMethod === "chaikin" ? "chaikin" : "normal";
    data = data.replace(/^t\s+creasemethod\b.*$/gm, "") + `\nt creasemethod 0/0/1 ${name}\n`;
  }
  return { format: "obj", data, scheme };
}

// Shows the mesh controls or the implicit scene's polygoniser controls.
function showSourceControls() {
  const scene = Boolean(state.scene);
  $("polygonizer-params").hidden = !scene;
  for (const id of ["method", "scheme", "boundary", "crease-method"]) {
    $(id).closest("label").hidden = scene;
  }
  if (scene) {
    for (const group of document.querySelectorAll(".params")) group.hidden = true;
  } else {
    showMethodParams();
  }
  $("draw-contours").disabled = $("draw-cage").disabled = scene;
  $("reference-caption").textContent =
      `exact reference (ray-cast ${scene ? "isosurface" : "limit surface"})`;
}

// An implicit scene: a /v1/implicit request whose field (and polygonizer, as defaults for the
// controls) the page sends with its own camera, outputs and comparison.
async function useScene(request, label) {
  state.full?.abort();
  state.scene = request;
  state.mesh = new SceneSource(request);
  state.meshText = null;
  state.meshFile = null;
  stopTurntable();
  state.frame = null;
  if (state.glView) state.glView.setCage([], []);
  const polygonizer = request.polygonizer || {};
  if (polygonizer.method) $("polygonizer").value = polygonizer.method;
  if (polygonizer.resolution) $("resolution").value = polygonizer.resolution;
  if (polygonizer.flatness !== undefined) $("flatness").value = polygonizer.flatness;
  restoreAddress();
  $("draw-contours").checked = $("draw-cage").checked = false;
  showSourceControls();
  clearErrors();
  hideContours();
  $("mesh-info").textContent = `${label}: implicit field of ${request.field.primitives.length} ` +
      `primitives, iso ${request.field.iso ?? 0.5}`;
  await renderFull();
}

// What is shown, to go back to when an upload is refused.
function sourceSnapshot() {
  return { mesh: state.mesh, meshText: state.meshText, meshFile: state.meshFile,
           scene: state.scene, frame: state.frame, example: state.shownExample ?? $("example").value,
           scheme: state.shownScheme ?? $("scheme").value, info: $("mesh-info").textContent };
}

function restoreSource(before) {
  Object.assign(state, { mesh: before.mesh, meshText: before.meshText, meshFile: before.meshFile,
                         scene: before.scene, frame: before.frame });
  $("example").value = before.example;
  $("scheme").value = before.scheme;  // a scheme the server refused for this mesh is not kept
  $("mesh-info").textContent = before.info;
  if (state.glView) {
    const { points, faces } = state.meshText !== null ? cageOf(state.meshText) : { points: [], faces: [] };
    state.glView.setCage(points, faces);
  }
  showSourceControls();
}

async function useMesh(source, label) {
  const before = sourceSnapshot();
  state.meshFile = null;
  state.meshText = source;
  if (state.glView) {
    const { points, faces } = cageOf(source);
    state.glView.setCage(points, faces);
  }
  await uploadAndRender(new UploadedMesh(wireMesh(source)), label, before);
}

// A file of a format the server reads (glTF, PLY, STL, ...), sent as it is. The server chooses
// the scheme from its faces unless the person picked one for this file; the page has no cage
// of it to draw itself.
async function useMeshFile(file, scheme = null) {
  const before = sourceSnapshot();
  state.meshText = null;
  state.meshFile = file;
  if (state.glView) state.glView.setCage([], []);
  const uploaded = new UploadedMesh(null, { bytes: file.bytes, format: file.format, scheme });
  if (await uploadAndRender(uploaded, file.name, before)) $("scheme").value = uploaded.info.scheme;
}

// Uploads the mesh and renders it; false (the error shown under the mesh controls, and the
// mesh shown before back, so that the controls and the camera still work) when the upload was
// refused, and false, touching nothing, when a newer mesh (or scheme) was picked meanwhile.
async function uploadAndRender(uploaded, label, before) {
  state.full?.abort();
  stopTurntable();
  state.scene = null;
  showSourceControls();
  state.mesh = uploaded;
  state.frame = null;  // until the first answer for this mesh
  clearErrors();
  setBusy("uploading the mesh…");
  state.uploads += 1;
  try {
    const info = await uploaded.upload();
    if (state.mesh !== uploaded) return false;
    $("mesh-info").textContent = `${label}: ${info.vertices.toLocaleString("en")} vertices, ` +
        `${info.faces.toLocaleString("en")} faces` +
        (info.warnings.length ? ` (${info.warnings.length} warnings)` : "");
    $("mesh-info").title = info.warnings.join("\n");
  } catch (problem) {
    if (state.mesh !== uploaded) return false;
    setBusy(null);
    restoreSource(before);
    showError(problem);
    return false;
  } finally {
    state.uploads -= 1;
  }
  hideContours();
  await renderFull();
  return true;
}

async function loadExample(name) {
  if (name.startsWith("scene:")) {
    const scene = name.slice("scene:".length);
    state.view = { ...DEFAULT_VIEW };
    describeView();
    await useScene(await getJson(`/scenes/${encodeURIComponent(scene)}`), scene);
    return;
  }
  const example = state.examples.find((e) => e.name === name);
  if (!example) return;
  $("scheme").value = example.scheme;
  firstView = { ...DEFAULT_VIEW, ...(example.orbit || {}) };
  state.view = { ...firstView };
  describeView();
  restoreAddress();
  const text = await getText(`/examples/${encodeURIComponent(name)}`);
  await useMesh(text, example.title);
}

async function loadFile(file) {
  const extension = (file.name.match(/\.([^.]+)$/) || ["", ""])[1].toLowerCase();
  if (meshFileFormats.includes(extension)) {
    $("example").value = "";
    firstView = { ...DEFAULT_VIEW };
    state.view = { ...firstView };
    describeView();
    await useMeshFile({ bytes: await file.arrayBuffer(), format: extension, name: file.name });
    return;
  }
  const text = await file.text();
  let source = text;
  if (/\.json$/i.test(file.name) || /^\s*\{/.test(text)) {
    try {
      const parsed = JSON.parse(text);
      if (parsed.field) {  // a /v1/implicit request
        $("example").value = "";
        await useScene(parsed, file.name);
        return;
      }
      source = parsed.mesh || parsed;  // a whole /v1/render request, or a JSON mesh
    } catch (error) {
      showError(new ApiProblem(400, { error: { message: `${file.name} is not JSON: ${error.message}`,
                                               detail: { field: "mesh" } } }));
      return;
    }
    if (source.format === "obj") {
      if (source.scheme) $("scheme").value = source.scheme;
      source = source.data;
    } else if (source.scheme) {
      $("scheme").value = source.scheme === "catmullClark" ? "catmull-clark" : source.scheme;
    }
  }
  $("example").value = "";
  await useMesh(source, file.name);
}

// ---------------------------------------------------------------- turntable

// Views orbiting the mesh from the current one, played over the picture (each view's own PNG,
// anti-aliased like the picture: the answer's GIF, with its 256 colours, is for other clients)
// until the next render (a drag, a changed control).
async function playTurntable() {
  if (!state.mesh || state.scene) return;
  state.full?.abort();
  stopTurntable();
  const controller = (state.full = new AbortController());
  const frames = Number($("turntable-frames").value);
  setBusy(`rendering a turntable of ${frames} views…`);
  try {
    const full = requestSize();
    const size = scaled(full, Math.min(1, 384 / Math.max(full.width, full.height)));
    const answer = await state.mesh.withId(
        (mesh) => post("/v1/render", {
          ...renderBody(mesh, size, false),
          turntable: { frames, elevationDeg: state.view.elevationDeg },
        }, { signal: controller.signal }),
        controller.signal);
    if (controller.signal.aborted) return;
    clearErrors();
    const views = answer.frames.filter((f) => f.images).map((f) => imageUrl(
        f.images[mainOutput()] || f.images.color));
    let k = 0;
    const show = () => { $("turntable-picture").src = views[k++ % views.length]; };
    show();
    $("turntable-picture").hidden = false;
    state.turntableTimer = setInterval(show, 1000 / answer.turntable.fps);
    page.turntables += 1;
  } catch (problem) {
    if (problem.name !== "AbortError") showError(problem);
  } finally {
    if (state.full === controller) {
      state.full = null;
      setBusy(null);
    }
  }
}

function stopTurntable() {
  clearInterval(state.turntableTimer);
  $("turntable-picture").hidden = true;
}

// ---------------------------------------------------------------- camera

function describeView() {
  const v = state.view;
  $("camera-text").textContent = `azimuth ${v.azimuthDeg.toFixed(0)}°, elevation ` +
      `${v.elevationDeg.toFixed(0)}°` + (v.distance ? `, distance ${v.distance.toFixed(2)} r` : "") +
      ($("orthographic").checked ? ", orthographic" : "");
  $("view").dataset.azimuth = v.azimuthDeg.toFixed(1);
  $("view").dataset.elevation = v.elevationDeg.toFixed(1);
  $("view").dataset.distance = v.distance ? v.distance.toFixed(3) : "";
}

// Starts a camera move: the full picture in flight is stale, and while it lasts the reference
// and the difference (which answer the camera before) are dimmed.
function beginMove() {
  if (state.dragging) return;
  state.dragging = true;
  state.full?.abort();
  $("view").classList.add("dragging");
  document.body.classList.add("dragging");
}

function endMove() {
  if (!state.dragging) return;  // a click, not a drag
  state.dragging = false;
  $("view").classList.remove("dragging");
  document.body.classList.remove("dragging");
  state.dragEndedAt = performance.now();
  renderFull();
}

const defaultDistance = () => framingRadii(state.frame?.fovYDeg ?? 35);
const clampDistance = (d) => Math.max(1.05, Math.min(40, d));

// Mouse, pen and touch alike (pointer events): one pointer orbits, two pinch to zoom.
function bindCamera() {
  const view = $("view");
  const pointers = new Map();  // pointerId -> [x, y]
  let pinch = null;            // {spread, distance} when the second finger went down
  const spread = () => {
    const [a, b] = [...pointers.values()];
    return Math.hypot(a[0] - b[0], a[1] - b[1]) || 1;
  };
  view.addEventListener("pointerdown", (event) => {
    if (event.pointerType === "mouse" && event.button !== 0) return;
    if (event.target.closest("button")) return;  // the retry button over the picture
    try { view.setPointerCapture(event.pointerId); } catch { /* a synthetic pointer */ }
    pointers.set(event.pointerId, [event.clientX, event.clientY]);
    if (pointers.size === 2) {
      pinch = { spread: spread(), distance: state.view.distance || defaultDistance() };
    }
  });
  view.addEventListener("pointermove", (event) => {
    const last = pointers.get(event.pointerId);
    if (!last) return;
    const dx = event.clientX - last[0], dy = event.clientY - last[1];
    if (dx === 0 && dy === 0) return;
    pointers.set(event.pointerId, [event.clientX, event.clientY]);
    beginMove();
    const v = state.view;
    if (pointers.size >= 2) {
      if (pinch) v.distance = clampDistance(pinch.distance * pinch.spread / spread());
    } else {
      v.azimuthDeg = (((v.azimuthDeg - dx * 0.5) % 360) + 540) % 360 - 180;
      v.elevationDeg = Math.max(-89, Math.min(89, v.elevationDeg + dy * 0.5));
    }
    describeView();
    previewMove();
  });
  const end = (event) => {
    if (!pointers.delete(event.pointerId)) return;
    if (pointers.size < 2) pinch = null;
    if (pointers.size === 0) endMove();
  };
  view.addEventListener("pointerup", end);
  view.addEventListener("pointercancel", end);
  let wheelTimer = null;
  view.addEventListener("wheel", (event) => {
    event.preventDefault();
    const v = state.view;
    v.distance = clampDistance((v.distance || defaultDistance()) * Math.pow(1.0015, event.deltaY));
    describeView();
    previewMove();
    clearTimeout(wheelTimer);
    wheelTimer = setTimeout(renderFull, 250);
  }, { passive: false });
  view.addEventListener("dblclick", resetView);
  // Dropping a file anywhere on the picture loads it.
  view.addEventListener("dragover", (event) => { event.preventDefault(); view.classList.add("drop"); });
  view.addEventListener("dragleave", () => view.classList.remove("drop"));
  view.addEventListener("drop", (event) => {
    event.preventDefault();
    view.classList.remove("drop");
    const file = event.dataTransfer.files[0];
    if (file) loadFile(file);
  });
}

function resetView() {
  state.view = { ...firstView };
  describeView();
  renderFull();
}

// The standard views (azimuth and elevation, at the current distance) and "frame all" (the
// default framing of the bounding sphere, at the current angles).
const STANDARD_VIEWS = {
  front: { azimuthDeg: 0, elevationDeg: 0 },
  side: { azimuthDeg: 90, elevationDeg: 0 },
  top: { azimuthDeg: 0, elevationDeg: 90 },
  "three-quarter": { azimuthDeg: 45, elevationDeg: 30 },
};

function standardView(name) {
  Object.assign(state.view, STANDARD_VIEWS[name]);
  describeView();
  renderFull();
}

function frameAll() {
  state.view.distance = null;
  describeView();
  renderFull();
}

// ---------------------------------------------------------------- controls

function showMethodParams() {
  const method = $("method").value;
  for (const group of document.querySelectorAll(".params")) {
    group.hidden = !group.dataset.for.split(" ").includes(method);
  }
  offerWhatWorks();
}

// Options the server would refuse for the current method and scheme are not offered: normal-map
// shading is drawn by coarse and silhouette only, the factored engine refines Catmull–Clark
// only. A chosen option that stops working falls back to the default.
function offerWhatWorks() {
  const method = $("method").value, scheme = $("scheme").value;
  const normalMap = $("shading").querySelector("option[value=normal-map]");
  normalMap.disabled = !["coarse", "silhouette"].includes(method);
  if (normalMap.disabled && $("shading").value === "normal-map") $("shading").value = "smooth";
  const factored = $("engine").querySelector("option[value=factored]");
  factored.disabled = scheme !== "catmull-clark";
  if (factored.disabled && $("engine").value === "factored") $("engine").value = "auto";
  const scene = state.scene !== null;
  const cage = $("draw-cage").checked && !scene && method !== "limit";
  const patchColours = method === "patches" && $("show-patches").checked && !scene;
  offerIf("draw-wireframe",
          !$("draw-surface").checked ? "Wireframe: it is drawn on the surface; switch the surface on."
          : cage ? "Wireframe: the server draws either the control cage or the wireframe over " +
                   "the surface; switch the cage off."
          : patchColours ? "Wireframe: not with the patch colours; untick colour by patch level."
          : null);
  offerIf("compare", method === "limit" && !scene
      ? "Compare: the limit method is the exact reference itself; choose another method." : null);
  const exportWhy = method === "limit" && !scene
      ? "Mesh export: the limit is ray cast and has no triangles; choose another method."
      : null;
  for (const button of document.querySelectorAll("[data-mesh-format]")) {
    button.disabled = Boolean(exportWhy) || (scene && button.dataset.meshFormat === "glb");
    button.title = exportWhy || (button.disabled ? "implicit scenes are exported as PLY or OBJ" : "");
  }
  $("export-why").textContent = exportWhy || "";
  $("export-why").hidden = !exportWhy;
}

// Disables a checkbox that cannot apply now (unticking it) and shows why under it; enables it
// again when `reason` is null.
function offerIf(id, reason) {
  const input = $(id);
  input.disabled = Boolean(reason);
  if (reason) input.checked = false;
  input.closest("label").title = reason || "";
  $(`${id}-why`).textContent = reason || "";
  $(`${id}-why`).hidden = !reason;
}

// A number typed by hand outside what the server takes (its limits, docs/api.md) is refused
// here: the message goes under the control's section, the control is outlined, the pictures are
// marked out of date, and nothing is sent. True when something was refused.
function refuseInvalidInput() {
  let refused = false;
  for (const input of document.querySelectorAll("#controls input[type=number]")) {
    const bad = !input.closest("[hidden]") && whatIsWrong(input);
    input.setAttribute("aria-invalid", bad ? "true" : "false");
    if (!bad || refused) continue;
    refused = true;
    const name = input.closest("label").firstChild.textContent.trim();
    const slot = input.closest("section").querySelector(".error").id;
    clearErrors();
    showMessage(slot, `${name} ${bad}`);
    document.body.classList.add("stale");
    setBusy(null);
  }
  return refused;
}

function whatIsWrong(input) {
  const value = input.valueAsNumber, limit = input.dataset.limit;
  const why = limit ? ` (the server's limits.${limit})` : "";
  if (!Number.isFinite(value)) return "must be a number.";
  if (input.min !== "" && value < Number(input.min)) return `must be at least ${input.min}${why}.`;
  if (input.max !== "" && value > Number(input.max)) return `must be at most ${input.max}${why}.`;
  return null;
}

// The server's notes about the last answer (ignored fields, a chord error raised, hits that
// could not be refined), under the status line.
function showWarnings(warnings) {
  const list = warnings || [];
  $("warnings").hidden = list.length === 0;
  $("warnings").textContent = list.length === 1 ? `Note: ${list[0]}`
                                                : `${list.length} notes: ${list.join(" · ")}`;
}

function applyLayout() {
  const slider = sliderLayout();
  document.body.classList.toggle("slider", slider);
  const on = slider && comparing() && document.body.classList.contains("comparing");
  $("slider").hidden = !on;
  $("slider-reference").hidden = !on;
  $("slider-divider").hidden = !on;
  $("slider-reference").style.clipPath = `inset(0 0 0 ${$("slider").value}%)`;
  $("slider-divider").style.left = `${$("slider").value}%`;
  $("approx-caption").textContent = on ? "approximation (left) | exact reference (right)"
                                       : "approximation";
}

function bindControls() {
  $("example").addEventListener("change", () => loadExample($("example").value));
  $("upload").addEventListener("change", () => {
    const file = $("upload").files[0];
    if (file) loadFile(file);
  });
  $("scheme").addEventListener("change", offerWhatWorks);
  for (const id of ["scheme", "boundary", "crease-method"]) {
    $(id).addEventListener("change", () => {
      if (state.meshText !== null) useMesh(state.meshText, $("mesh-info").textContent.split(":")[0]);
      if (state.meshFile !== null && id === "scheme") useMeshFile(state.meshFile, $("scheme").value);
    });
  }
  $("background").addEventListener("change", () => {
    $("view").classList.toggle("transparent", $("background").value === "transparent");
    renderFull();
  });
  $("turntable").addEventListener("click", playTurntable);
  $("level").addEventListener("input", () => { $("level-value").textContent = $("level").value; });
  $("method").addEventListener("change", showMethodParams);
  for (const id of ["method", "level", "engine", "dicing-rate", "contour-mode", "presubdivide",
                    "patch-dicing-rate", "isolation", "show-patches", "displacement",
                    "displacement-amplitude", "displacement-frequency",
                    "draw-surface", "draw-cage", "draw-wireframe", "shading", "size",
                    "polygonizer", "resolution", "flatness"]) {
    $(id).addEventListener("change", renderFull);
  }
  $("draw-contours").addEventListener("change", () => {
    if ($("draw-contours").checked) loadContours(); else hideContours();
  });
  $("compare").addEventListener("change", async () => {
    if (comparing()) {  // the pictures of an earlier comparison are not shown as this one's
      for (const id of ["reference", "slider-reference", "diff"]) $(id).removeAttribute("src");
      $("metrics").replaceChildren();
    }
    await renderFull();
    applyLayout();
  });
  for (const radio of document.querySelectorAll("input[name=compare-layout]")) {
    radio.addEventListener("change", applyLayout);
  }
  $("slider").addEventListener("input", applyLayout);
  $("orthographic").addEventListener("change", () => { describeView(); renderFull(); });
  $("diff-top").addEventListener("change", () => { if (state.diff) showDiff(); });
  for (const button of document.querySelectorAll("[data-view]")) {
    button.addEventListener("click", () => standardView(button.dataset.view));
  }
  $("frame-all").addEventListener("click", frameAll);
  $("download-png").addEventListener("click", downloadPictures);
  $("download-json").addEventListener("click", () => downloadRecord("json"));
  $("download-csv").addEventListener("click", () => downloadRecord("csv"));
  for (const button of document.querySelectorAll("[data-mesh-format]")) {
    button.addEventListener("click", () => downloadMesh(button.dataset.meshFormat));
  }
  $("copy-link").addEventListener("click", copyLink);
  $("retry").addEventListener("click", renderFull);
}

// ---------------------------------------------------------------- export and share

function download(blob, name) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
}

// A short name for the files: the mesh and the method.
function fileStem() {
  const mesh = currentSource().value || "mesh";
  const method = state.scene ? $("polygonizer").value : $("method").value;
  return `limn-${mesh.replace(/[^A-Za-z0-9_.-]+/g, "_")}-${method}`;
}

// The pictures shown as one PNG: the approximation alone, or, comparing, the approximation,
// the reference and the difference side by side (each at the size the server drew it).
async function downloadPictures() {
  const images = [$("picture")];
  if (document.body.classList.contains("comparing")) images.push($("reference"), $("diff"));
  const shown = images.filter((img) => img.naturalWidth > 0);
  if (shown.length === 0) return;
  const canvas = document.createElement("canvas");
  canvas.width = shown.reduce((sum, img) => sum + img.naturalWidth, 0);
  canvas.height = Math.max(...shown.map((img) => img.naturalHeight));
  const ctx = canvas.getContext("2d");
  let x = 0;
  for (const img of shown) {
    ctx.drawImage(img, x, 0);
    x += img.naturalWidth;
  }
  const blob = await new Promise((resolve) => canvas.toBlob(resolve, "image/png"));
  download(blob, `${fileStem()}${shown.length > 1 ? "-compare" : ""}.png`);
}

// What the last answer measured: its request's method and parameters, the resolved camera, the
// metrics (comparing), the stats and the timings.
function answerRecord() {
  const a = page.lastAnswer;
  if (!a) return null;
  return { mesh: currentSource().value, method: state.scene ? "implicit" : $("method").value,
           params: state.scene ? null : methodParams(), camera: a.camera, metrics: a.metrics || {},
           stats: a.stats, timings: a.timings, warnings: a.warnings || [] };
}

// The record flattened into key,value rows ("metrics.silhouette.iou,0.998").
function recordCsv(record) {
  const rows = [["key", "value"]];
  const walk = (value, key) => {
    if (value === null || value === undefined) return;
    if (Array.isArray(value)) {
      value.forEach((v, i) => walk(v, `${key}[${i}]`));
    } else if (typeof value === "object") {
      for (const [k, v] of Object.entries(value)) walk(v, key ? `${key}.${k}` : k);
    } else {
      rows.push([key, String(value)]);
    }
  };
  walk(record, "");
  const quote = (x) => (/[",\n]/.test(x) ? `"${x.replace(/"/g, '""')}"` : x);
  return rows.map((r) => r.map(quote).join(",")).join("\n") + "\n";
}

function downloadRecord(format) {
  const record = answerRecord();
  if (!record) return;
  if (format === "json") {
    download(new Blob([JSON.stringify(record, null, 2)], { type: "application/json" }),
             `${fileStem()}-metrics.json`);
  } else {
    download(new Blob([recordCsv(record)], { type: "text/csv" }), `${fileStem()}-metrics.csv`);
  }
}

// The approximation's triangles as a file: POST /v1/tessellate (an implicit scene: POST
// /v1/implicit) with the Accept header of the format.
const MESH_FORMATS = {
  glb: { accept: "model/gltf-binary", type: "model/gltf-binary" },
  ply: { accept: "application/x-ply", type: "application/x-ply" },
  obj: { accept: "text/plain", type: "text/plain" },
};

async function downloadMesh(format) {
  if (!state.mesh) return;
  const { accept, type } = MESH_FORMATS[format];
  setBusy(`exporting ${format.toUpperCase()}…`);
  try {
    const body = await state.mesh.withId((mesh) => {
      const request = renderBody(mesh, requestSize(), false);
      return postBinary(state.scene ? "/v1/implicit" : "/v1/tessellate", request, { accept });
    });
    download(new Blob([body], { type }), `${fileStem()}.${format}`);
  } catch (problem) {
    showError(problem);
  } finally {
    setBusy(null);
  }
}

// The controls the address keeps, by parameter name; a control at its default is left out.
const SHARED_CONTROLS = {
  scheme: "scheme", boundary: "boundary", crease: "crease-method", method: "method",
  level: "level", engine: "engine", rate: "dicing-rate", prate: "patch-dicing-rate",
  isolation: "isolation", patches: "show-patches", disp: "displacement",
  amp: "displacement-amplitude", waves: "displacement-frequency", contour: "contour-mode",
  presub: "presubdivide", poly: "polygonizer", res: "resolution", flatness: "flatness",
  surface: "draw-surface", cage: "draw-cage", wire: "draw-wireframe", contours: "draw-contours",
  shading: "shading", size: "size", bg: "background", compare: "compare", ortho: "orthographic",
  dtop: "diff-top",
};
const controlDefaults = {};

const controlValue = (el) => (el.type === "checkbox" ? (el.checked ? "1" : "0") : el.value);

// What is shown: an example, an implicit scene, or an uploaded mesh by its server id.
function currentSource() {
  const picked = $("example").value;
  if (picked.startsWith("scene:")) return { key: "scene", value: picked.slice(6) };
  if (picked) return { key: "example", value: picked };
  if (state.mesh?.id) return { key: "mesh", value: state.mesh.id };
  return { key: null, value: null };
}

// The address of what is shown: the mesh, the controls that differ from their defaults and the
// camera. It is kept in the address bar (replaceState after each picture), so reloading or
// sharing it reopens the same state.
function shareUrl() {
  const q = new URLSearchParams();
  const source = currentSource();
  if (source.key) q.set(source.key, source.value);
  if (source.key === "mesh") q.set("name", $("mesh-info").textContent.split(":")[0]);
  for (const [name, id] of Object.entries(SHARED_CONTROLS)) {
    const value = controlValue($(id));
    if (value !== controlDefaults[name]) q.set(name, value);
  }
  if (sliderLayout()) q.set("layout", "slider");
  const v = state.view;
  q.set("az", v.azimuthDeg.toFixed(1));
  q.set("el", v.elevationDeg.toFixed(1));
  if (v.distance) q.set("d", v.distance.toFixed(3));
  const preview = new URLSearchParams(location.search).get("preview");
  if (preview) q.set("preview", preview);
  return `${location.origin}${location.pathname}?${q}`;
}

function rememberInAddress() {
  const url = shareUrl();
  if (url !== location.href) history.replaceState(null, "", url);
}

// Sets the controls from an address's parameters; the camera, if it names one.
function restoreControls(q) {
  for (const [name, id] of Object.entries(SHARED_CONTROLS)) {
    if (!q.has(name)) continue;
    const el = $(id);
    if (el.type === "checkbox") el.checked = q.get(name) === "1"; else el.value = q.get(name);
  }
  $("level-value").textContent = $("level").value;
  if (q.get("layout") === "slider") document.querySelector("input[value=slider]").checked = true;
  $("view").classList.toggle("transparent", $("background").value === "transparent");
  if (!q.has("az")) return null;
  const d = Number(q.get("d"));
  return { azimuthDeg: Number(q.get("az")) || 0, elevationDeg: Number(q.get("el")) || 0,
           distance: d > 0 ? d : null };
}

async function copyLink() {
  const url = shareUrl();
  history.replaceState(null, "", url);
  try {
    await navigator.clipboard.writeText(url);
    $("share-note").textContent = "link copied";
  } catch {
    $("share-note").textContent = "the address bar holds the link";
  }
}

// A mesh uploaded earlier, named by a shared address: its id is all the page has.
class SharedMesh {
  constructor(id) { this.id = id; }
  withId(request) { return request({ id: this.id }); }
}

// ---------------------------------------------------------------- keys

// Keys for what is changed most (listed in the page under "Mouse, touch and keys").
function toggle(id) {
  if ($(id).disabled) return;
  $(id).checked = !$(id).checked;
  $(id).dispatchEvent(new Event("change"));
}

function bindKeys() {
  document.addEventListener("keydown", (event) => {
    if (event.ctrlKey || event.metaKey || event.altKey) return;
    if (event.target.closest("input, select, textarea, button")) return;
    const key = event.key.toLowerCase();
    const level = (step) => {
      if ($("method").value !== "uniform" || state.scene) return;
      const next = Math.max(0, Math.min(LIMITS.maxLevel, Number($("level").value) + step));
      $("level").value = String(next);
      $("level-value").textContent = $("level").value;
      $("level").dispatchEvent(new Event("change"));
    };
    const actions = {
      "+": () => level(1), "=": () => level(1), "-": () => level(-1), "_": () => level(-1),
      w: () => toggle("draw-wireframe"), c: () => toggle("draw-cage"),
      o: () => toggle("orthographic"), r: resetView, f: frameAll,
      s: () => {
        $("shading").value = $("shading").value === "smooth" ? "flat" : "smooth";
        $("shading").dispatchEvent(new Event("change"));
      },
      1: () => standardView("front"), 2: () => standardView("side"), 3: () => standardView("top"),
      4: () => standardView("three-quarter"),
    };
    if (!actions[key]) return;
    event.preventDefault();
    actions[key]();
  });
}

// ---------------------------------------------------------------- window size

// A resized window (or a turned phone) lays the panels out again, and asks for a new picture
// when the size it would request has changed by more than a few pixels.
function bindResize() {
  let timer = null;
  window.addEventListener("resize", () => {
    const before = requestSize();
    layoutPanels();
    const after = requestSize();
    if (Math.abs(after.width - before.width) + Math.abs(after.height - before.height) < 8) return;
    clearTimeout(timer);
    timer = setTimeout(renderFull, 300);
  });
  const drawer = (open) => {
    document.body.classList.toggle("drawer-open", open);
    $("open-controls").setAttribute("aria-expanded", String(open));
  };
  $("open-controls").addEventListener("click", (event) => {
    event.stopPropagation();
    drawer(true);
  });
  $("close-controls").addEventListener("click", () => drawer(false));
  document.addEventListener("keydown", (event) => { if (event.key === "Escape") drawer(false); });
  // A tap on the picture side closes the drawer.
  document.querySelector("main").addEventListener("click", () => drawer(false));
}

async function start() {
  const options = new URLSearchParams(location.search);
  try {
    // ?preview=server: drag previews by small renders even where WebGL 2 works.
    if (options.get("preview") !== "server") state.glView = new MeshView($("gl-canvas"));
  } catch (error) {
    console.warn(`drag previews by small renders: ${error.message}`);
  }
  for (const [name, id] of Object.entries(SHARED_CONTROLS)) controlDefaults[name] = controlValue($(id));
  showMethodParams();
  describeView();
  bindControls();
  bindCamera();
  bindKeys();
  bindResize();
  layoutPanels();
  try {
    state.examples = await getJson("/examples");
  } catch (problem) {
    showError(problem);
    return;
  }
  for (const e of state.examples) $("example").add(new Option(e.title, e.name));
  try {
    const scenes = await getJson("/scenes");
    for (const name of scenes) $("example").add(new Option(`implicit: ${name}`, `scene:${name}`));
  } catch (problem) {
    console.warn("no implicit scenes:", problem.message);
  }
  $("example").add(new Option("(uploaded file)", ""));
  // An address from "copy link" (or the address bar after any picture) restores its state.
  state.restoring = options;
  if (options.has("mesh")) {
    $("example").value = "";
    const id = options.get("mesh");
    restoreAddress();
    showSourceControls();
    state.mesh = new SharedMesh(id);
    $("mesh-info").textContent = `${options.get("name") || "uploaded mesh"}: mesh ${id} on the server`;
    await renderFull();
    return;
  }
  const first = options.has("scene") ? `scene:${options.get("scene")}`
                                     : options.get("example") || "torus_creased";
  $("example").value = first;
  await loadExample(first);
}

// Applies the address's controls and camera once, after the example or scene set its own.
function restoreAddress() {
  if (!state.restoring) return;
  const view = restoreControls(state.restoring);
  state.restoring = null;
  if (view) state.view = view;
  describeView();
  showMethodParams();
}

start();
