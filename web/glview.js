// The page's local view while the camera is dragged: the approximation's triangles (from
// POST /v1/tessellate, binary glTF) drawn with WebGL 2 in the browser, with limn's own shading
// model (a headlight, Blinn-Phong, the constants of render/core/shading.h) and the control cage
// over it, so that orbiting runs at the display's frame rate without a request per frame. The
// server's full-size picture replaces it when the drag ends.

// render/core/shading.h: sRGB albedos, shaded in linear light, written as sRGB (the canvas
// shows its values as sRGB, as the server's PNGs hold them).
const FRONT = [0.80, 0.62, 0.38], BACK = [0.40, 0.55, 0.80];
const AMBIENT = 0.12, DIFFUSE = 0.78, SPECULAR = 0.25, SHININESS = 40.0;
const CAGE = [0.12, 0.23, 0.58];

const SURFACE_VS = `#version 300 es
uniform mat4 uViewProj;
in vec3 aPosition;
in vec3 aNormal;
out vec3 vPosition;
out vec3 vNormal;
void main() {
  vPosition = aPosition;
  vNormal = aNormal;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}`;

const SURFACE_FS = `#version 300 es
precision highp float;
uniform vec3 uEye;
uniform vec3 uForward;  // the view direction
uniform bool uPerspective;
uniform bool uFlat;
in vec3 vPosition;
in vec3 vNormal;
out vec4 color;
vec3 toLinear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}
vec3 toSrgb(vec3 c) {
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() {
  vec3 n = uFlat ? normalize(cross(dFdx(vPosition), dFdy(vPosition))) : normalize(vNormal);
  // Orthographic: every ray runs along the view direction (render/raster/shaders.cpp).
  vec3 toEye = uPerspective ? normalize(uEye - vPosition) : -uForward;
  float ndotv = dot(n, toEye);
  // The winding says front or back, as in limn's rasteriser (render/raster/shaders.cpp): a
  // smooth normal turned a little away near the outline must not paint a back-coloured fringe.
  // Flat: the screen-space normal faces the eye.
  if (uFlat) ndotv = abs(ndotv);
  else if (!gl_FrontFacing) ndotv = -ndotv;
  vec3 albedo = toLinear(gl_FrontFacing ? vec3(${FRONT}) : vec3(${BACK}));
  float c = max(ndotv, 0.0);
  vec3 rgb = albedo * (${AMBIENT} + ${DIFFUSE} * c) + ${SPECULAR} * pow(c, ${SHININESS.toFixed(1)});
  color = vec4(toSrgb(clamp(rgb, 0.0, 1.0)), 1.0);
}`;

const LINE_VS = `#version 300 es
uniform mat4 uViewProj;
in vec3 aPosition;
void main() { gl_Position = uViewProj * vec4(aPosition, 1.0); }`;

const LINE_FS = `#version 300 es
precision mediump float;
out vec4 color;
void main() { color = vec4(${CAGE}, 1.0); }`;

function compile(gl, vs, fs) {
  const program = gl.createProgram();
  for (const [type, source] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) {
      throw new Error(gl.getShaderInfoLog(shader));
    }
    gl.attachShader(program, shader);
  }
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
  return program;
}

// The positions, normals and indices of a GLB as limn writes it (one triangle primitive).
export function parseGlb(buffer) {
  const view = new DataView(buffer);
  if (view.getUint32(0, true) !== 0x46546c67) throw new Error("not a binary glTF");
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 20, jsonLength)));
  const binStart = 20 + jsonLength + 8;
  const primitive = json.meshes?.[0]?.primitives?.[0];
  if (!primitive) return { positions: new Float32Array(0), normals: null, indices: new Uint32Array(0) };
  const read = (index, Type, components) => {
    const accessor = json.accessors[index];
    const bufferView = json.bufferViews[accessor.bufferView];
    return new Type(buffer, binStart + (bufferView.byteOffset || 0), accessor.count * components);
  };
  return {
    positions: read(primitive.attributes.POSITION, Float32Array, 3),
    normals: primitive.attributes.NORMAL === undefined ? null
                                                       : read(primitive.attributes.NORMAL, Float32Array, 3),
    indices: read(primitive.indices, Uint32Array, 1),
    extras: json.asset.extras,
  };
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => { const l = Math.hypot(...a); return a.map((x) => x / l); };

// Column-major projection * view for a perspective or orthographic camera, as limn's Camera
// builds them.
function viewProjection(camera, aspect) {
  const f = unit(sub(camera.target, camera.eye));
  const r = unit(cross(f, camera.up));
  const u = cross(r, f);
  const e = camera.eye;
  const view = [r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
                -dot(r, e), -dot(u, e), dot(f, e), 1];
  const t = 1 / Math.tan((camera.fovYDeg * Math.PI) / 360);
  const n = camera.near, fa = camera.far;
  const h = camera.orthoHeight / 2;
  const proj = camera.projection === "orthographic"
      ? [1 / (h * aspect), 0, 0, 0, 0, 1 / h, 0, 0, 0, 0, 2 / (n - fa), 0,
         0, 0, (fa + n) / (n - fa), 1]
      : [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (fa + n) / (n - fa), -1,
         0, 0, (2 * fa * n) / (n - fa), 0];
  const out = new Float32Array(16);
  for (let c = 0; c < 4; c++) {
    for (let row = 0; row < 4; row++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += proj[k * 4 + row] * view[c * 4 + k];
      out[c * 4 + row] = s;
    }
  }
  return out;
}

export class MeshView {
  // Throws when the browser has no WebGL 2 (the page then previews with small renders).
  constructor(canvas) {
    const gl = canvas.getContext("webgl2", { antialias: true, premultipliedAlpha: true });
    if (!gl) throw new Error("no WebGL 2");
    this.canvas = canvas;
    this.gl = gl;
    this.surface = compile(gl, SURFACE_VS, SURFACE_FS);
    this.lines = compile(gl, LINE_VS, LINE_FS);
    this.triangles = 0;
    this.cageLines = 0;
    this.key = null;  // what the loaded mesh is the tessellation of
  }

  get ready() { return this.triangles > 0; }

  // The tessellation to draw (parseGlb's result).
  setMesh(mesh, key) {
    const gl = this.gl;
    this.release("surfaceBuffers", "vao");
    this.vao = gl.createVertexArray();
    this.surfaceBuffers = [];
    gl.bindVertexArray(this.vao);
    const attribute = (program, name, data) => {
      const location = gl.getAttribLocation(program, name);
      if (location < 0 || !data) return;
      gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer("surfaceBuffers"));
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
    };
    attribute(this.surface, "aPosition", mesh.positions);
    attribute(this.surface, "aNormal", mesh.normals);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffer("surfaceBuffers"));
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, mesh.indices, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    this.triangles = mesh.indices.length / 3;
    this.key = key;
  }

  // The control cage's edges: points [[x, y, z], ...] and faces [[i, j, k, ...], ...].
  setCage(points, faces) {
    const gl = this.gl;
    const edges = new Set(), pairs = [];
    for (const face of faces) {
      face.forEach((a, i) => {
        const b = face[(i + 1) % face.length];
        const key = a < b ? `${a},${b}` : `${b},${a}`;
        if (!edges.has(key)) { edges.add(key); pairs.push(a, b); }
      });
    }
    this.release("cageBuffers", "cageVao");
    this.cageBuffers = [];
    this.cageVao = gl.createVertexArray();
    gl.bindVertexArray(this.cageVao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer("cageBuffers"));
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(points.flat()), gl.STATIC_DRAW);
    const location = gl.getAttribLocation(this.lines, "aPosition");
    gl.enableVertexAttribArray(location);
    gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.buffer("cageBuffers"));
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(pairs), gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    this.cageLines = pairs.length / 2;
  }

  buffer(list) {
    const b = this.gl.createBuffer();
    this[list].push(b);
    return b;
  }

  // Frees the previous mesh's (or cage's) buffers and vertex array.
  release(list, vao) {
    for (const b of this[list] || []) this.gl.deleteBuffer(b);
    if (this[vao]) this.gl.deleteVertexArray(this[vao]);
  }

  // camera: {eye, target, up, fovYDeg, near, far, projection, orthoHeight}; size: {width,
  // height} in pixels; what: {surface, cage, flat, opaque} (opaque: a white background, as the
  // server's "background": "white").
  draw(camera, size, what) {
    const gl = this.gl, canvas = this.canvas;
    if (canvas.width !== size.width) canvas.width = size.width;
    if (canvas.height !== size.height) canvas.height = size.height;
    gl.viewport(0, 0, size.width, size.height);
    if (what.opaque) gl.clearColor(1, 1, 1, 1); else gl.clearColor(0, 0, 0, 0);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const viewProj = viewProjection(camera, size.width / size.height);
    if (what.surface && this.ready) {
      gl.useProgram(this.surface);
      gl.uniformMatrix4fv(gl.getUniformLocation(this.surface, "uViewProj"), false, viewProj);
      gl.uniform3fv(gl.getUniformLocation(this.surface, "uEye"), camera.eye);
      gl.uniform3fv(gl.getUniformLocation(this.surface, "uForward"), unit(sub(camera.target, camera.eye)));
      gl.uniform1i(gl.getUniformLocation(this.surface, "uPerspective"),
                   camera.projection === "orthographic" ? 0 : 1);
      gl.uniform1i(gl.getUniformLocation(this.surface, "uFlat"), what.flat ? 1 : 0);
      // The cage's lines win over the surface they lie on.
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
      gl.bindVertexArray(this.vao);
      gl.drawElements(gl.TRIANGLES, this.triangles * 3, gl.UNSIGNED_INT, 0);
      gl.disable(gl.POLYGON_OFFSET_FILL);
    }
    if (what.cage && this.cageLines > 0) {
      gl.useProgram(this.lines);
      gl.uniformMatrix4fv(gl.getUniformLocation(this.lines, "uViewProj"), false, viewProj);
      gl.bindVertexArray(this.cageVao);
      gl.drawElements(gl.LINES, this.cageLines * 2, gl.UNSIGNED_INT, 0);
    }
    gl.bindVertexArray(null);
  }
}
