// The page's client of limn's HTTP API: JSON requests that can be aborted, errors as values
// that say which control caused them, and meshes uploaded once (POST /v1/meshes) and then sent
// by id, re-uploaded when the server no longer holds them.

// A refusal from the API: status, code and message as the server wrote them, and `control`,
// the part of the page whose input caused it ("mesh", "method", "draw", "view" or "page").
export class ApiProblem extends Error {
  constructor(status, body, retryAfter) {
    const error = (body && body.error) || {};
    super(error.message || `HTTP ${status}`);
    this.status = status;
    this.code = error.code || "http_" + status;
    this.detail = error.detail || {};
    this.retryAfter = retryAfter;
    this.control = controlFor(status, this.code, this.detail);
  }

  // What the person reads: the server's message, with what to do about the few that need it.
  get text() {
    if (this.status === 429) return `The server is busy (${this.message}); retrying shortly.`;
    if (this.status === 504) return `${this.message} Try fewer iterations or a coarser rate.`;
    return this.message;
  }
}

const meshLimits = new Set(["maxVertices", "maxFaces", "maxFaceSize", "maxValence",
                            "maxBodyBytes", "meshCacheBytes"]);

function controlFor(status, code, detail) {
  const field = detail.field || "";
  if (code === "invalid_mesh" || code === "unknown_mesh" || field.startsWith("mesh")) return "mesh";
  if (status === 413 && meshLimits.has(detail.limit)) return "mesh";
  if (field.startsWith("camera")) return "view";
  if (field === "shading" || field.startsWith("outputs")) return "draw";
  if (field === "method" || field.startsWith("params") || status === 504) return "method";
  if (status === 413) return detail.limit === "maxImageSide" ? "view" : "method";
  return "page";
}

// POSTs `body` as JSON; resolves to the parsed answer (or text for non-JSON answers), rejects
// with an ApiProblem for 4xx/5xx, or with the AbortError of `signal`.
export async function post(path, body, { signal, accept } = {}) {
  const headers = { "Content-Type": "application/json" };
  if (accept) headers.Accept = accept;
  const response = await fetch(path, { method: "POST", headers, body: JSON.stringify(body), signal });
  const type = response.headers.get("Content-Type") || "";
  const answer = type.startsWith("application/json") ? await response.json() : await response.text();
  if (!response.ok) {
    throw new ApiProblem(response.status, typeof answer === "object" ? answer : null,
                         Number(response.headers.get("Retry-After")) || 1);
  }
  return answer;
}

// The same for a binary answer (a mesh from /v1/tessellate): an ArrayBuffer.
export async function postBinary(path, body, { signal, accept } = {}) {
  const headers = { "Content-Type": "application/json" };
  if (accept) headers.Accept = accept;
  const response = await fetch(path, { method: "POST", headers, body: JSON.stringify(body), signal });
  if (!response.ok) {
    throw new ApiProblem(response.status, await response.json().catch(() => null),
                         Number(response.headers.get("Retry-After")) || 1);
  }
  return response.arrayBuffer();
}

export async function getJson(path) {
  const response = await fetch(path);
  if (!response.ok) throw new ApiProblem(response.status, await response.json().catch(() => null));
  return response.json();
}

export async function getText(path) {
  const response = await fetch(path);
  if (!response.ok) throw new ApiProblem(response.status, null);
  return response.text();
}

// POSTs a file's bytes as they are (`query`: "?format=glb&scheme=loop"); resolves to the JSON
// answer, rejects with an ApiProblem.
export async function postFile(path, bytes, query, { signal } = {}) {
  const response = await fetch(path + query, {
    method: "POST", headers: { "Content-Type": "application/octet-stream" }, body: bytes, signal,
  });
  if (!response.ok) {
    throw new ApiProblem(response.status, await response.json().catch(() => null),
                         Number(response.headers.get("Retry-After")) || 1);
  }
  return response.json();
}

// The mesh file formats the server reads through Assimp, by file extension.
export const meshFileFormats = ["glb", "gltf", "ply", "stl", "fbx", "dae", "3ds", "off"];

// A mesh the page renders: its wire form ({format, data, scheme} or the JSON form), or a mesh
// file sent as it is (`file`: {bytes, format, scheme}; the scheme null lets the server choose),
// and, once uploaded, the server's id for it.
export class UploadedMesh {
  constructor(wire, file = null) {
    this.wire = wire;
    this.file = file;
    this.id = null;
    this.info = null;  // {id, vertices, faces, scheme, warnings}
  }

  async upload(signal) {
    if (this.file) {
      const query = `?format=${this.file.format}` +
          (this.file.scheme ? `&scheme=${encodeURIComponent(this.file.scheme)}` : "");
      this.info = await postFile("/v1/meshes", this.file.bytes, query, { signal });
    } else {
      this.info = await post("/v1/meshes", { mesh: this.wire }, { signal });
    }
    this.id = this.info.id;
    return this.info;
  }

  // Runs request(meshField) with {"id": ...}, uploading first when needed and once more when
  // the server answers that it no longer holds the mesh (evicted, or the server restarted).
  async withId(request, signal) {
    if (!this.id) await this.upload(signal);
    try {
      return await request({ id: this.id });
    } catch (problem) {
      if (!(problem instanceof ApiProblem) || problem.code !== "unknown_mesh") throw problem;
      await this.upload(signal);
      return request({ id: this.id });
    }
  }
}
