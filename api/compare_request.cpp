// parseCompareRequest: the JSON body of POST /v1/compare -> CompareRequest. The mesh, camera,
// method, params, shading and outputs are read by /v1/render's own readers (request_parts.h);
// what they report about "camera" or "params" is re-labelled with the list entry it came from
// ("cameras[2].width", "methods[1].params.level"), so the client learns which entry is wrong.
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <utility>

#include "api/compare_api.h"
#include "api/json_util.h"
#include "api/request_parts.h"

namespace limn::api {

namespace {

using json::Value;
using render::pipeline::CompareMethod;
using render::pipeline::JobLimits;
using render::pipeline::Method;

// Runs `read`; an ApiError from it (and the warnings it adds) get `from` renamed to `to`.
template <class Read>
auto relabelled(const std::string& from, const std::string& to, std::vector<std::string>& warnings,
                Read read) {
  std::vector<std::string> found;
  auto moveWarnings = [&] {
    for (std::string& w : found) warnings.push_back(json::renameField(std::move(w), from, to));
  };
  try {
    auto value = read(found);
    moveWarnings();
    return value;
  } catch (ApiError& e) {
    json::renameField(e, from, to);
    throw;
  }
}

std::string jsonText(const Value& value) {
  rapidjson::StringBuffer buffer;
  rapidjson::Writer<rapidjson::StringBuffer> writer(buffer);
  value.Accept(writer);
  return {buffer.GetString(), buffer.GetSize()};
}

void parseMethodEntry(const Value& entry, size_t index, const JobLimits& limits,
                      CompareRequest& request) {
  request::ParsedMethod parsed = request::parseCompareMethod(
      entry, "methods[" + std::to_string(index) + "]", limits, request.warnings);
  request.job.methods.push_back(parsed.method);
  request.labels.push_back(std::move(parsed.label));
  request.paramsJson.push_back(std::move(parsed.paramsJson));
}

}  // namespace

namespace request {

ParsedMethod parseCompareMethod(const Value& entry, const std::string& field,
                                const JobLimits& limits, std::vector<std::string>& warnings) {
  CompareMethod method;
  std::string paramsJson = "{}";
  std::string label;
  auto readMethod = [&](const Value& name) {
    return relabelled("method", field + ".method", warnings,
                      [&](std::vector<std::string>&) { return request::parseMethod(name); });
  };
  if (entry.IsString()) {
    method.method = readMethod(entry);
  } else {
    json::requireObject(entry, field);
    request::warnUnknownFields(entry, field, {"method", "params", "shading", "label"}, warnings);
    const Value* name = json::find(entry, "method");
    if (!name) json::fail(field + ".method", field + ".method is required");
    method.method = readMethod(*name);
    if (const Value* params = json::find(entry, "params")) {
      if (params->IsObject() && json::find(*params, "metricSupersample")) {
        json::fail(field + ".params.metricSupersample",
                   "one metricSupersample serves every row of a comparison (the reference is "
                   "shared): give it at the top level, not in " +
                       field + ".params");
      }
      method.params =
          relabelled("params", field + ".params", warnings, [&](std::vector<std::string>& found) {
            return request::parseParams(*params, limits, found);
          });
      if (method.params.referenceCrossCheck) {
        warnings.push_back(field +
                           ".params.referenceCrossCheck is not run in a comparison; ignored "
                           "(ask /v1/render for it)");
        method.params.referenceCrossCheck = false;
      }
      paramsJson = jsonText(*params);
    }
    if (const Value* shading = json::find(entry, "shading")) {
      method.shading =
          relabelled("shading", field + ".shading", warnings,
                     [&](std::vector<std::string>&) { return request::parseShading(*shading); });
    }
    if (const Value* v = json::find(entry, "label")) {
      label = std::string(json::string(*v, field + ".label"));
      if (label.empty()) json::fail(field + ".label", field + ".label must not be empty");
    }
  }
  if (method.method == Method::Limit) {
    json::fail(field + ".method",
               field +
                   ".method \"limit\" is the reference every row is measured against; list the "
                   "methods to compare with it");
  }
  if (method.method != Method::Uniform &&
      (method.params.engine != render::pipeline::Engine::Auto || method.params.pushToLimit)) {
    warnings.push_back(field +
                       ".params.engine and pushToLimit are read by method \"uniform\" only; "
                       "ignored");
  }
  if (label.empty()) label = methodLabel(method.method, method.params, paramsJson, method.shading);
  return {method, std::move(label), std::move(paramsJson)};
}

}  // namespace request

namespace {

void parseCameras(const Value& root, const JobLimits& limits, CompareRequest& request) {
  const Value* one = json::find(root, "camera");
  const Value* many = json::find(root, "cameras");
  if (one && many) {
    json::fail("cameras", "camera and cameras are two ways to give the views; give one");
  }
  if (!many) {
    request.job.cameras.push_back(one ? request::parseCamera(*one, limits, request.warnings)
                                      : render::CameraSpec{});
    return;
  }
  json::requireArray(*many, "cameras");
  if (many->Empty()) json::fail("cameras", "cameras must list at least one camera");
  for (rapidjson::SizeType i = 0; i < many->Size(); ++i) {
    request.job.cameras.push_back(
        relabelled("camera", "cameras[" + std::to_string(i) + "]", request.warnings,
                   [&](std::vector<std::string>& found) {
                     return request::parseCamera((*many)[i], limits, found);
                   }));
  }
}

// Methods x cameras against maxCompareRows before any mesh is read (the engine checks again).
void checkRows(const CompareRequest& request, const JobLimits& limits) {
  const size_t rows = request.job.methods.size() * request.job.cameras.size();
  if (rows > limits.maxCompareRows) {
    throw tooLarge(
        "maxCompareRows", "methods",
        std::to_string(request.job.methods.size()) + " methods x " +
            std::to_string(request.job.cameras.size()) + " cameras = " + std::to_string(rows) +
            " rows: exceeds limit maxCompareRows (" + std::to_string(limits.maxCompareRows) + ")");
  }
}

CompareRequest parseDocument(const Value& root, const JobLimits& limits,
                             render::mesh::MeshCache* meshes) {
  if (!root.IsObject()) {
    json::fail("", "the request body must be a JSON object, got " + json::describe(root));
  }
  CompareRequest request;
  render::pipeline::CompareJob& job = request.job;
  request::warnUnknownFields(
      root, "",
      {"mesh", "camera", "cameras", "methods", "metricSupersample", "outputs", "antialias",
       "background", "imageFormat", "imageQuality", "displacement"},
      request.warnings);
  parseCameras(root, limits, request);
  const Value* methods = json::find(root, "methods");
  if (!methods) json::fail("methods", "methods is required: the methods to compare");
  json::requireArray(*methods, "methods");
  if (methods->Empty()) json::fail("methods", "methods must list at least one method");
  for (rapidjson::SizeType i = 0; i < methods->Size(); ++i) {
    parseMethodEntry((*methods)[i], i, limits, request);
  }
  checkRows(request, limits);
  if (const Value* v = json::find(root, "metricSupersample")) {
    job.metricSupersample = json::integer(*v, "metricSupersample");
    if (job.metricSupersample < 1) {
      json::fail("metricSupersample", "metricSupersample must be >= 1");
    }
    if (job.metricSupersample > limits.maxSupersample) {
      throw tooLarge("maxSupersample", "metricSupersample",
                     "metricSupersample " + std::to_string(job.metricSupersample) +
                         " exceeds limit maxSupersample (" + std::to_string(limits.maxSupersample) +
                         ")");
    }
  }
  if (const Value* v = json::find(root, "outputs")) job.outputs = request::parseOutputs(*v);
  if (const Value* v = json::find(root, "antialias")) {
    job.outputs.antialias = request::parseAntialias(*v);
  }
  if (job.outputs.contours &&
      std::none_of(job.methods.begin(), job.methods.end(),
                   [](const CompareMethod& m) { return m.method == Method::Silhouette; })) {
    json::fail("outputs", "output \"contours\" is drawn by method \"silhouette\" only");
  }
  request.encoding = request::parseImageEncoding(root);
  if (const Value* v = json::find(root, "background")) {
    job.outputs.background = request::parseBackground(*v);
  }

  const Value* mesh = json::find(root, "mesh");
  if (!mesh) json::fail("mesh", "mesh is required");
  job.mesh = request::parseMesh(*mesh, limits, request.warnings, meshes);
  if (const Value* v = json::find(root, "displacement")) {
    job.displacement = request::parseDisplacement(*v, request.warnings);
  }
  for (size_t c = 0; c < job.cameras.size(); ++c) {
    const std::string name =
        json::find(root, "cameras") ? "cameras[" + std::to_string(c) + "]" : "camera";
    relabelled("camera", name, request.warnings, [&](std::vector<std::string>&) {
      request::checkCameraAgainstMesh(job.cameras[c], job.mesh);
      return 0;
    });
  }
  return request;
}

// A param's value in a label: strings bare, numbers as people write them.
std::string labelValue(const Value& value) {
  if (value.IsString()) return value.GetString();
  if (value.IsNumber()) return json::formatNumber(value.GetDouble());
  return jsonText(value);
}

}  // namespace

std::string methodLabel(Method method, const render::pipeline::MethodParams& params,
                        std::string_view paramsJson, render::Shading shading) {
  std::string label = render::pipeline::methodName(method);
  const char* main = nullptr;  // the param the label shows after the colon
  if (method == Method::Uniform) {
    label += ":" + std::to_string(params.level);
    main = "level";
  } else if (method == Method::Adaptive || method == Method::Patches) {
    label += ":" + json::formatNumber(params.dicingRate);
    main = "dicingRate";
  }
  rapidjson::Document document;
  document.Parse(paramsJson.data(), paramsJson.size());
  std::map<std::string, std::string> others;  // sorted by key
  if (!document.HasParseError() && document.IsObject()) {
    for (const auto& member : std::as_const(document).GetObject()) {
      std::string key(member.name.GetString(), member.name.GetStringLength());
      if (!main || key != main) others[key] = labelValue(member.value);
    }
  }
  for (const auto& [key, value] : others) label += " " + key + "=" + value;
  if (shading == render::Shading::Flat) label += " shading=flat";
  if (shading == render::Shading::NormalMap) label += " shading=normal-map";
  return label;
}

CompareRequest parseCompareRequest(std::string_view body, const JobLimits& limits,
                                   render::mesh::MeshCache* meshes) {
  rapidjson::Document document;
  request::parseJson(body, document);
  try {
    return parseDocument(document, limits, meshes);
  } catch (const render::InputError& error) {
    throw fromInputError(error);
  }
}

}  // namespace limn::api
