// The wire format of POST /v1/silhouette: the contour of the limit surface for a mesh and a
// camera, as JSON polylines or as an SVG drawing, each piece marked seen or hidden.
//
// Request: the mesh, camera and silhouette params of POST /v1/render (params.presubdivide,
// searchSteps, curveSamples, contour), plus "format": "json" (default) | "svg". Without a
// "format" field, an Accept header that prefers image/svg+xml to application/json selects SVG.
// Errors are JSON whatever the format.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "api/answer.h"
#include "render/core/cancel.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/contours.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

enum class ContourFormat { Json, Svg };

struct SilhouetteRequest {
  render::pipeline::ContourJob job;
  ContourFormat format = ContourFormat::Json;
  std::vector<std::string> warnings;  // notes on the request, listed before the engine's
};

// Throws ApiError (400 invalid_json / invalid_request, 413 too_large, 422 invalid_mesh).
// `accept` is the request's Accept header ("" when it had none).
SilhouetteRequest parseSilhouetteRequest(std::string_view json, std::string_view accept,
                                         const render::pipeline::JobLimits& limits,
                                         render::mesh::MeshCache* meshes = nullptr);

// True when an Accept header ranks image/svg+xml above application/json (q values honoured;
// "*/*" and absent types do not count).
bool acceptsSvg(std::string_view accept);

// {"camera", "polylines": [{"closed", "points": [{"position", "pixel", "depth", "normal",
// "face", "uv", "edgePoint", "visible"}], "pieces": [{"start", "end", "visible"}]}], "stats",
// "timings", "warnings"}. timings.totalMs = parseMs + the engine's run + encodeMs.
std::string writeSilhouetteJson(const render::pipeline::ContourResult& result,
                                const SilhouetteRequest& request);

// An SVG the size of the camera's image: one <path> per piece in pixel coordinates, hidden
// pieces (class="hidden": dashed, light grey) under visible ones (class="visible": solid,
// dark). Warnings go in an XML comment.
std::string writeSilhouetteSvg(const render::pipeline::ContourResult& result,
                               const SilhouetteRequest& request);

// parse -> run -> write, every failure turned into its JSON error answer (as handleRender).
// Never throws.
Answer handleSilhouette(std::string_view body, std::string_view accept,
                        const render::pipeline::JobLimits& limits,
                        const render::CancelToken& cancel,
                        render::mesh::MeshCache* meshes = nullptr);

}  // namespace limn::api
