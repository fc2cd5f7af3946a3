// parseSilhouetteRequest: the JSON body of POST /v1/silhouette -> SilhouetteRequest. The mesh,
// camera and params are read by /v1/render's own readers (request_parts.h), so both endpoints
// accept and refuse the same things with the same messages.
#include <algorithm>
#include <cctype>
#include <string>

#include "api/json_util.h"
#include "api/request_parts.h"
#include "api/silhouette_api.h"

namespace limn::api {

namespace {

using json::Value;

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) !=
        std::tolower(static_cast<unsigned char>(b[i]))) {
      return false;
    }
  }
  return true;
}

// The q value of one media range's parameters ("; q=0.5"); 1 when absent or unreadable.
double qualityOf(std::string_view params) {
  while (!params.empty()) {
    size_t semicolon = params.find(';');
    std::string_view param = trim(params.substr(0, semicolon));
    params = semicolon == std::string_view::npos ? "" : params.substr(semicolon + 1);
    if (param.size() > 2 && (param[0] == 'q' || param[0] == 'Q') && param[1] == '=') {
      try {
        return std::stod(std::string(param.substr(2)));
      } catch (...) {
        return 1.0;
      }
    }
  }
  return 1.0;
}

}  // namespace

bool acceptsSvg(std::string_view accept) {
  double svg = -1, json = -1;  // -1: not listed
  while (!accept.empty()) {
    size_t comma = accept.find(',');
    std::string_view range = accept.substr(0, comma);
    accept = comma == std::string_view::npos ? "" : accept.substr(comma + 1);
    size_t semicolon = range.find(';');
    std::string_view type = trim(range.substr(0, semicolon));
    double q = semicolon == std::string_view::npos ? 1.0 : qualityOf(range.substr(semicolon + 1));
    if (equalsIgnoringCase(type, "image/svg+xml")) svg = std::max(svg, q);
    if (equalsIgnoringCase(type, "application/json")) json = std::max(json, q);
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
