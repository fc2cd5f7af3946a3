// parseSilhouetteRequest: the JSON body of POST /v1/silhouette -> SilhouetteRequest. The mesh,
// camera and params are read by /v1/render's own readers (request_parts.h), so both endpoints
// accept and refuse the same things with the same messages.
#include <algorithm>
#include <string>

#include "api/accept.h"
#include "api/json_util.h"
#include "api/request_parts.h"
#include "api/silhouette_api.h"

namespace limn::api {

namespace {

using json::Value;

}  // namespace

bool acceptsSvg(std::string_view accept) {
  double svg = -1, json = -1;  // -1: not listed
  for (const MediaRange& range : parseAccept(accept)) {
    if (sameMediaType(range.type, "image/svg+xml")) svg = std::max(svg, range.q);
    if (sameMediaType(range.type, "application/json")) json = std::max(json, range.q);
  }
  return svg > 0 && svg > json;
}

SilhouetteRequest parseSilhouetteRequest(std::string_view body, std::string_view accept,
                                         const render::pipeline::JobLimits& limits,
                                         render::mesh::MeshCache* meshes) {
  rapidjson::Document root;
  request::parseJson(body, root);
  try {
    if (!root.IsObject()) {
      json::fail("", "the request body must be a JSON object, got " + json::describe(root));
    }
    SilhouetteRequest out;
    render::pipeline::ContourJob& job = out.job;
    request::warnUnknownFields(root, "", {"mesh", "camera", "params", "format"}, out.warnings);
    if (const Value* v = json::find(root, "camera")) {
      job.camera = request::parseCamera(*v, limits, out.warnings);
    }
    if (const Value* v = json::find(root, "params")) {
      json::requireObject(*v, "params");
      request::warnUnknownFields(
          *v, "params", {"presubdivide", "searchSteps", "curveSamples", "contour"}, out.warnings);
      render::pipeline::MethodParams params;
      request::parseSilhouetteParams(*v, limits, params);
      job.params = {params.presubdivide, params.searchSteps, params.curveSamples, params.contour};
    }
    out.format = acceptsSvg(accept) ? ContourFormat::Svg : ContourFormat::Json;
    if (const Value* v = json::find(root, "format")) {
      out.format = json::choice<ContourFormat>(
          *v, "format", {{"json", ContourFormat::Json}, {"svg", ContourFormat::Svg}});
    }
    const Value* mesh = json::find(root, "mesh");
    if (!mesh) json::fail("mesh", "mesh is required");
    job.mesh = request::parseMesh(*mesh, limits, out.warnings, meshes);
    request::checkCameraAgainstMesh(job.camera, job.mesh);
    return out;
  } catch (const render::InputError& error) {
    throw fromInputError(error);
  }
}

}  // namespace limn::api
