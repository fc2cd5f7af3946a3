// limn's page: pick or upload a mesh (or an implicit scene), choose a method and what to draw,
// orbit the camera, and compare the approximation with the exact reference. Every picture comes
// from the server (POST /v1/render; POST /v1/implicit for scenes); while the camera is dragged the page draws the approximation's triangles
// itself (POST /v1/tessellate, WebGL 2: glview.js), or, without WebGL or before they arrive,
// shows small renders, and the full-size picture follows when the drag ends. See docs/web.md.
import { ApiProblem, UploadedMesh, getJson, getText, meshFileFormats, post, postBinary } from "/api.js";
import { MeshView, parseGlb } from "/glview.js";

const $ = (id) => document.getElementById(id);
const DEFAULT_VIEW = { azimuthDeg: 30, elevationDeg: 20, distance: null };
let firstView = DEFAULT_VIEW;  // the example's own view (examples.json "orbit"), else DEFAULT_VIEW
const PREVIEW_DIVISOR = 4;  // drag previews render at a quarter of the size in each direction
const LOCAL_MAX_TRIANGLES = 400_000;  // larger approximations are previewed by small renders

// What the browser tests (and a curious person in the console) can read.
const page = (window.limnPage = {
  renders: 0,            // full-size pictures shown
  previews: 0,           // drag previews shown (small renders from the server)
  turntables: 0,         // turntable animations shown
  localFrames: 0,        // drag frames the page drew itself (WebGL)
  firstPictureMs: null,  // performance.now() when the first full-size picture was shown
  dragToFullMs: null,    // from the last drag's end to its full-size picture
  lastAnswer: null,
  get busy() { return state.full !== null; },  // a full-size render is in flight
  // The local view holds the approximation the settings ask for (drags will draw it).
  get localReady() {
    return Boolean(state.glView?.ready && state.glView.key === tessellationKey() && state.frame);
  },
  // The local view at the current camera, drawn now, as a PNG data URL (tests compare it with
  // the server's picture of the same camera).
  localSnapshot() {
    state.glView.draw(orbitCamera(), fullSize(), {
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
  const text = problem instanceof ApiProblem ? `${problem.status}: ${problem.text}`
                                             : `Could not reach limn: ${problem.message}`;
  $(slot).textContent = text;
  $(slot).hidden = false;
  $(slot).scrollIntoView({ block: "nearest" });
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

function cameraFor(size) {
  const orbit = { azimuthDeg: state.view.azimuthDeg, elevationDeg: state.view.elevationDeg };
  if (state.view.distance) orbit.distance = state.view.distance;
  return { orbit, width: size, height: size };
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

const fullSize = () => Number($("size").value);
const comparing = () =>
  $("compare").checked && (state.scene !== null || $("method").value !== "limit");

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
  state.full?.abort();
  stopTurntable();
  const controller = (state.full = new AbortController());
  const compare = comparing();
  const sentView = { ...state.view };
  setBusy(compare ? "rendering and ray-casting the reference…" : "rendering…");
  const contours = $("draw-contours").checked ? loadContours(controller.signal) : null;
  try {
    const answer = await state.mesh.withId(
        (mesh) => post(renderPath(), renderBody(mesh, fullSize(), compare),
                       { signal: controller.signal }),
        controller.signal);
    if (controller.signal.aborted) return;
    clearErrors();
    await showAnswer(answer, compare);
    if (controller.signal.aborted) return;
    page.renders += 1;
    page.lastAnswer = answer;
    rememberFrame(answer.camera, sentView);
    loadTessellation(answer.stats.triangles);
    const now = performance.now();
    if (page.firstPictureMs === null) page.firstPictureMs = now;
    if (state.dragEndedAt !== null) {
      page.dragToFullMs = now - state.dragEndedAt;
      state.dragEndedAt = null;
    }
    $("view").dataset.renders = String(page.renders);
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
                   : `${s.controlFaces} control faces`) + ` · ${t.totalMs.toFixed(0)} ms`;
  $("stats").dataset.triangles = String(s.triangles);
  document.body.classList.toggle("comparing", compare);
  if (compare) {
    shown.push(showImage($("reference"), answer.reference.images.color));
    shown.push(showImage($("slider-reference"), answer.reference.images.color));
    if (answer.images.diff) shown.push(showImage($("diff"), answer.images.diff));
    $("diff-scale").textContent = formatNumber(answer.metrics.image?.diffScale);
    fillMetrics(answer);
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
    const size = Math.max(64, Math.round(fullSize() / PREVIEW_DIVISOR));
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
  return {
    eye: target.map((t, i) => t + dir[i] * distance),
    target,
    up: [-Math.sin(el) * Math.sin(az), Math.cos(el), -Math.sin(el) * Math.cos(az)],
    fovYDeg,
    near: Math.max(distance - 1.01 * radius, radius * 1e-3),
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
  if (view.key === key || $("method").value === "limit" || triangles > LOCAL_MAX_TRIANGLES) return;
  state.tessellation?.abort();
  const controller = (state.tessellation = new AbortController());
  try {
    const glb = await state.mesh.withId(
        (mesh) => postBinary("/v1/tessellate",
                             { mesh, camera: cameraFor(fullSize()), method: $("method").value,
                               params: methodParams() },
                             { signal: controller.signal, accept: "model/gltf-binary" }),
        controller.signal);
    view.setMesh(parseGlb(glb), key);
  } catch (problem) {
    if (problem.name !== "AbortError") console.warn("no local view:", problem.message);
  }
}

let frameRequested = false;
// One frame of the local view at the current orbit (at most one per display frame).
function drawLocal() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(() => {
    frameRequested = false;
    if (!state.glView?.ready || !state.frame) return;
    state.glView.draw(orbitCamera(), fullSize(), {
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
        (mesh) => post("/v1/silhouette", { mesh, camera: cameraFor(fullSize()), format: "svg" },
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

// ---------------------------------------------------------------- metrics table

function formatNumber(x) {
  if (x === undefined || x === null) return "–";
  if (Number.isInteger(x)) return x.toLocaleString("en");
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e6) ? x.toExponential(2) : x.toPrecision(4);
}

function fillMetrics(answer) {
  const m = answer.metrics, s = answer.stats, t = answer.timings;
  const rows = [
    ["silhouette", null],
    ["outline Hausdorff (px)", m.silhouette?.outlineHausdorffPx],
    ["outline mean (px)", m.silhouette?.outlineMeanPx],
    ["mask Hausdorff (px)", m.silhouette?.hausdorffPx],
    ["IoU", m.silhouette?.iou],
    ["mismatched pixels", m.silhouette?.mismatchPx],
    ["image, depth, normals", null],
    ["colour RMSE", m.image?.rmse],
    ["PSNR (dB)", m.image?.psnr],
    ["diff scale (top of ramp)", m.image?.diffScale],
    ["depth max (rel.)", m.depth?.maxRel],
    ["normal mean (deg)", m.normal?.meanDeg],
    ["normal max (deg)", m.normal?.maxDeg],
    ["geometry max dist (rel.)", m.geometry?.relMaxDist],
    ["size", null],
    ["triangles", s.triangles],
    ["reference triangles", s.referenceTriangles],
    ["times (ms)", null],
    ["surface", t.surfaceMs], ["approximation", t.approxMs], ["raster", t.rasterMs],
    ["reference", t.referenceMs], ["metrics", t.metricsMs], ["encode", t.encodeMs],
    ["total", t.totalMs],
  ];
  // One small table per group, side by side.
  const tables = [];
  for (const [name, value] of rows) {
    if (value === null) {
      const table = document.createElement("table");
      table.createCaption().textContent = name;
      tables.push(table);
      continue;
    }
    const tr = tables.at(-1).insertRow();
    tr.insertCell().textContent = name;
    tr.insertCell().textContent = formatNumber(value);
  }
  $("metrics").replaceChildren(...tables);
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
  $("draw-contours").checked = $("draw-cage").checked = false;
  showSourceControls();
  clearErrors();
  hideContours();
  $("mesh-info").textContent = `${label}: implicit field of ${request.field.primitives.length} ` +
      `primitives, iso ${request.field.iso ?? 0.5}`;
  await renderFull();
}

async function useMesh(source, label) {
  state.meshFile = null;
  state.meshText = source;
  if (state.glView) {
    const { points, faces } = cageOf(source);
    state.glView.setCage(points, faces);
  }
  await uploadAndRender(new UploadedMesh(wireMesh(source)), label);
}

// A file of a format the server reads (glTF, PLY, STL, ...), sent as it is. The server chooses
// the scheme from its faces unless the person picked one for this file; the page has no cage
// of it to draw itself.
async function useMeshFile(file, scheme = null) {
  state.meshText = null;
  state.meshFile = file;
  if (state.glView) state.glView.setCage([], []);
  const uploaded = new UploadedMesh(null, { bytes: file.bytes, format: file.format, scheme });
  if (await uploadAndRender(uploaded, file.name)) $("scheme").value = uploaded.info.scheme;
}

// Uploads the mesh and renders it; false (the error shown) when the upload was refused.
async function uploadAndRender(uploaded, label) {
  state.full?.abort();
  stopTurntable();
  state.scene = null;
  showSourceControls();
  state.mesh = uploaded;
  state.frame = null;  // until the first answer for this mesh
  clearErrors();
  setBusy("uploading the mesh…");
  try {
    const info = await uploaded.upload();
    $("mesh-info").textContent = `${label}: ${info.vertices} vertices, ${info.faces} faces` +
        (info.warnings.length ? ` (${info.warnings.length} warnings)` : "");
    $("mesh-info").title = info.warnings.join("\n");
  } catch (problem) {
    setBusy(null);
    state.mesh = null;
    $("mesh-info").textContent = "";
    showError(problem);
    return false;
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
    const size = Math.min(fullSize(), 384);
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
      `${v.elevationDeg.toFixed(0)}°` + (v.distance ? `, distance ${v.distance.toFixed(2)} r` : "");
  $("view").dataset.azimuth = v.azimuthDeg.toFixed(1);
  $("view").dataset.elevation = v.elevationDeg.toFixed(1);
}

function bindCamera() {
  const view = $("view");
  let last = null;
  view.addEventListener("pointerdown", (event) => {
    if (event.button !== 0) return;
    view.setPointerCapture(event.pointerId);
    last = [event.clientX, event.clientY];
  });
  view.addEventListener("pointermove", (event) => {
    if (!last) return;
    const dx = event.clientX - last[0], dy = event.clientY - last[1];
    if (dx === 0 && dy === 0) return;
    last = [event.clientX, event.clientY];
    if (!state.dragging) {  // the first move: a drag, and the full picture in flight is stale
      state.dragging = true;
      state.full?.abort();
      view.classList.add("dragging");
    }
    const v = state.view;
    v.azimuthDeg = (((v.azimuthDeg - dx * 0.5) % 360) + 540) % 360 - 180;
    v.elevationDeg = Math.max(-89, Math.min(89, v.elevationDeg + dy * 0.5));
    describeView();
    previewMove();
  });
  const end = () => {
    if (!last) return;
    last = null;
    if (!state.dragging) return;  // a click, not a drag
    state.dragging = false;
    view.classList.remove("dragging");
    state.dragEndedAt = performance.now();
    renderFull();
  };
  view.addEventListener("pointerup", end);
  view.addEventListener("pointercancel", end);
  let wheelTimer = null;
  view.addEventListener("wheel", (event) => {
    event.preventDefault();
    const v = state.view;
    const current = v.distance || 3.5;  // about the default framing at 35 degrees
    v.distance = Math.max(1.05, Math.min(40, current * Math.pow(1.0015, event.deltaY)));
    describeView();
    previewMove();
    clearTimeout(wheelTimer);
    wheelTimer = setTimeout(renderFull, 250);
  }, { passive: false });
  view.addEventListener("dblclick", () => {
    state.view = { ...firstView };
    describeView();
    renderFull();
  });
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
  const slider = document.querySelector("input[name=compare-layout]:checked").value === "slider";
  document.body.classList.toggle("slider", slider);
  const on = slider && comparing() && document.body.classList.contains("comparing");
  $("slider").hidden = !on;
  $("slider-reference").hidden = !on;
  $("slider-reference").style.clipPath = `inset(0 0 0 ${$("slider").value}%)`;
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
    if (!comparing()) document.body.classList.remove("comparing");
    await renderFull();
    applyLayout();
  });
  for (const radio of document.querySelectorAll("input[name=compare-layout]")) {
    radio.addEventListener("change", applyLayout);
  }
  $("slider").addEventListener("input", applyLayout);
}

async function start() {
  const options = new URLSearchParams(location.search);
  try {
    // ?preview=server: drag previews by small renders even where WebGL 2 works.
    if (options.get("preview") !== "server") state.glView = new MeshView($("gl-canvas"));
  } catch (error) {
    console.warn(`drag previews by small renders: ${error.message}`);
  }
  showMethodParams();
  describeView();
  bindControls();
  bindCamera();
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
  const first = options.get("example") || "torus_creased";
  $("example").value = first;
  await loadExample(first);
}

start();
