// The wire format of POST /v1/compare: one mesh, one or several cameras and a list of methods
// -> render::pipeline::CompareJob; the CompareResult -> one JSON table (a row per method and
// camera; the reference's time once per camera). `limn batch` and POST /v1/jobs send their
// work through the same handler, so every batch row is a /v1/compare row.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "api/answer.h"
#include "render/core/cancel.h"
#include "render/image/encode.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/compare.h"

namespace limn::api {

struct CompareRequest {
  render::pipeline::CompareJob job;
  render::image::Encoding encoding;  // "imageFormat", "imageQuality"
  // Per method, as the answer echoes it: its label and its params as given (a JSON object).
  std::vector<std::string> labels, paramsJson;
  std::vector<std::string> warnings;  // found while parsing, for the answer's "warnings"
};

// Throws ApiError: 400 invalid_json / invalid_request naming the field ("methods[1].params.level",
// "cameras[0].width"), 413 too_large (maxCompareRows and the limits of /v1/render), 422
// invalid_mesh, 404 unknown_mesh.
CompareRequest parseCompareRequest(std::string_view body, const render::pipeline::JobLimits& limits,
                                   render::mesh::MeshCache* meshes = nullptr);

// The 200 answer: {"rows", "cameras", "reference", "stats", "timings", "warnings"}
// (docs/api.md); `parseMs` is the parse's time, reported in timings.
std::string writeCompareResponse(const render::pipeline::CompareResult& result,
                                 const CompareRequest& request, double parseMs);

// parse -> compare -> write, every failure turned into its JSON error answer. Never throws.
Answer handleCompare(std::string_view body, const render::pipeline::JobLimits& limits,
                     render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                     render::mesh::MeshCache* meshes = nullptr);

// The label a method gets when the request gives none: its name, the level of "uniform" or the
// dicing rate of "adaptive" after a colon, then any other param given as " key=value" in key
// order, and a shading other than smooth: "uniform:3", "adaptive:0.5", "silhouette
// contour=pn", "coarse shading=flat". `paramsJson` is the params object as given ("{}" none).
std::string methodLabel(render::pipeline::Method method,
                        const render::pipeline::MethodParams& params, std::string_view paramsJson,
                        render::Shading shading);

}  // namespace limn::api
