// The wire format of POST /v1/render: JSON request -> RenderJob, RenderResult -> JSON answer.
// The server and the CLI call these; nothing below api/ knows JSON.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/answer.h"
#include "render/core/cancel.h"
#include "render/image/encode.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

// Answer, ApiError and errorAnswer() live in api/answer.h.

// "turntable": views orbiting the target, as frames of one answer (and an animated GIF).
struct Turntable {
  int frames = 24;
  double elevationDeg = 20;  // else camera.orbit's elevation when it has one
  double fps = 12;           // of the animation
  bool animation = false;    // "turntable" in outputs: the animated GIF of the colour pass
};

struct RenderRequest {
  render::pipeline::RenderJob job;
  std::optional<Turntable> turntable;
  render::image::Encoding encoding;  // "imageFormat", "imageQuality"
  // Notes for the client found while parsing (ignored OBJ tags, unknown fields); the answer's
  // "warnings" lists them before the engine's own.
  std::vector<std::string> warnings;
};

// Throws ApiError (400 invalid_json / invalid_request, 413 too_large, 422 invalid_mesh).
// A "mesh": {"id": ...} is looked up in `meshes` (404 unknown_mesh when absent).
RenderRequest parseRenderRequest(std::string_view json, const render::pipeline::JobLimits& limits,
                                 render::mesh::MeshCache* meshes = nullptr);

// What of a RenderResult the answer shows, and how: the outputs asked for, whether a reference
// was, the image encoding, and the parser's warnings (written before the engine's).
struct AnswerShape {
  const render::pipeline::Outputs& outputs;
  bool reference;
  render::image::Encoding encoding;
  const std::vector<std::string>& warnings;
};
std::string writeRenderResponse(const render::pipeline::RenderResult& result,
                                const AnswerShape& shape);

// The 200 answer's JSON: images (base64), reference.images, metrics, stats, timings, warnings,
// camera. timings.totalMs = result.timings.parseMs + result.timings.totalMs (the engine's run)
// + the time spent here encoding, which is also written as timings.encodeMs.
std::string writeRenderResponse(const render::pipeline::RenderResult& result,
                                const RenderRequest& request);

// The turntable's views (job.camera with its orbit's azimuth stepped round, at the turntable's
// elevation) drawn as the rows of one comparison (render/pipeline/compare.h): the surface built
// once, the reference and metrics per view when job.reference; the answer's "frames", "worst"
// and the animation. Throws as handleRender's parse and run do.
std::string writeTurntable(const RenderRequest& request, const render::pipeline::JobLimits& limits,
                           render::pipeline::RenderContext& context,
                           const render::CancelToken& cancel);

// parse -> run -> write, with every failure turned into its JSON error answer (InputError ->
// 4xx, Cancelled -> 504 timeout, anything else -> 500 internal). Never throws.
// With an Accept header that ranks an image type (image/png, image/jpeg, image/webp,
// image/x-exr; image/* is PNG) above JSON, a request for one image without reference images is
// answered by the picture itself, with X-Limn-* headers for its counts (406 for more images).
Answer handleRender(std::string_view body, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                    render::mesh::MeshCache* meshes = nullptr, std::string_view accept = {});

// POST /v1/tessellate: the body of a /v1/render request; answers the approximation's mesh
// (positions, limit normals, triangles) as GLB, PLY or OBJ by `accept` (api/accept.h,
// formats/mesh_writers.h), 406 not_acceptable when the header allows none. Never throws.
Answer handleTessellate(std::string_view body, std::string_view accept,
                        const render::pipeline::JobLimits& limits,
                        const render::CancelToken& cancel,
                        render::mesh::MeshCache* meshes = nullptr);

// POST /v1/meshes: {"mesh": {...}} (any form) is read, validated and kept in `meshes`;
// answers {"id", "vertices", "faces", "scheme", "bytes", "warnings"}. A mesh larger than the
// whole cache is a 413 naming meshCacheBytes. Never throws. The same in two steps, for a server
// that reads meshes in its worker processes: handleMeshImport (the worker: read and validate,
// answering {"mesh": <the JSON form>, "warnings"}) and storeImportedMesh (the server: read that
// back with limn's own reader and keep it; an import that failed is answered as it is).
Answer handleMeshImport(std::string_view body, const render::pipeline::JobLimits& limits);
Answer storeImportedMesh(const Answer& imported, const render::pipeline::JobLimits& limits,
                         render::mesh::MeshCache& meshes);

// The body of an upload as handleMeshImport reads it: a JSON body as it is; a file (its media
// type, or any type with ?format=) wrapped as {"mesh": {"format", "dataBase64", "scheme",
// "name"}} from the query's scheme= and name=. A media type that is neither: 415.
struct MeshUploadQuery {
  std::string format, scheme, name;  // as in the URL (percent-encoded)
};
std::string meshUploadBody(std::string_view contentType, const MeshUploadQuery& query,
                           std::string body);
Answer handleMeshUpload(std::string_view body, const render::pipeline::JobLimits& limits,
                        render::mesh::MeshCache& meshes);

// The images of a 200 answer of /v1/render or /v1/implicit as files: "color.png", ...,
// and the reference's as "reference_color.png", ... (limn render writes them to a folder).
struct DecodedImage {
  std::string fileName;
  std::vector<unsigned char> bytes;
};
std::vector<DecodedImage> imagesOf(std::string_view answerJson);

// The id of the uploaded mesh a /v1/render, /v1/silhouette, /v1/tessellate or /v1/compare body
// names ({"mesh": {"id": "..."}}), or nothing (another mesh form, or not such a body at all:
// the handler's parse says what is wrong). For the server, which holds the uploaded meshes.
std::optional<std::string> referencedMeshId(std::string_view body);

}  // namespace limn::api
