// parseImplicitRequest: the JSON body of POST /v1/implicit -> ImplicitJob. Cheap checks first
// (primitive count, expression lengths, resolution) so an over-limit request is refused before
// anything is compiled or sampled.
#include <string>

#include "api/implicit_api.h"
#include "api/json_util.h"
#include "api/request_parts.h"

namespace limn::api {

namespace {

using json::Value;
using render::implicit::PolygonizerMethod;
using render::implicit::Primitive;
using render::implicit::PrimitiveType;

[[noreturn]] void tooLarge(const char* limit, const std::string& message) {
  throw ApiError{413, "too_large", message, json::detailObject({{"limit", limit}})};
}

render::implicit::Transform parseTransform(const Value& value, const std::string& field,
                                           std::vector<std::string>& warnings) {
  json::requireObject(value, field);
  request::warnUnknownFields(value, field, {"scale", "rotateDeg", "translate"}, warnings);
  render::implicit::Transform t;
  if (const Value* v = json::find(value, "scale")) {
    t.scale = v->IsNumber() ? render::Vec3{1, 1, 1} * json::number(*v, field + ".scale")
                            : json::vec3(*v, field + ".scale");
  }
  if (const Value* v = json::find(value, "rotateDeg"))
    t.rotateDeg = json::vec3(*v, field + ".rotateDeg");
  if (const Value* v = json::find(value, "translate"))
    t.translate = json::vec3(*v, field + ".translate");
  return t;
}

render::Bounds parseBounds(const Value& value, const std::string& field) {
  json::requireObject(value, field);
  const Value* lo = json::find(value, "min");
  const Value* hi = json::find(value, "max");
  if (!lo || !hi) json::fail(field, field + " needs \"min\" and \"max\" ([x, y, z] each)");
  render::Bounds box;
  box.lo = json::vec3(*lo, field + ".min");
  box.hi = json::vec3(*hi, field + ".max");
  if (!(box.lo.x < box.hi.x && box.lo.y < box.hi.y && box.lo.z < box.hi.z)) {
    json::fail(field, field + ".min must be below " + field + ".max on every axis");
  }
  return box;
}

Primitive parsePrimitive(const Value& value, size_t index,
                         const render::pipeline::JobLimits& limits,
                         std::vector<std::string>& warnings) {
  const std::string field = "field.primitives[" + std::to_string(index) + "]";
  json::requireObject(value, field);
  request::warnUnknownFields(value, field,
                             {"type", "center", "radius", "weight", "negative", "transform",
                              "blobbiness", "majorRadius", "exponent", "expression", "bounds"},
                             warnings);
  Primitive p;
  const Value* type = json::find(value, "type");
  if (!type) json::fail(field + ".type", field + ".type is required");
  p.type = json::choice<PrimitiveType>(*type, field + ".type",
                                       {{"blobby", PrimitiveType::Blobby},
                                        {"metaball", PrimitiveType::Metaball},
                                        {"soft", PrimitiveType::Soft},
                                        {"torus", PrimitiveType::Torus},
                                        {"cube", PrimitiveType::Cube},
                                        {"expression", PrimitiveType::Expression}});
  auto number = [&](const char* key, double& out) {
    if (const Value* v = json::find(value, key)) out = json::number(*v, field + "." + key);
  };
  if (const Value* v = json::find(value, "center")) p.center = json::vec3(*v, field + ".center");
  number("radius", p.radius);
  number("weight", p.weight);
  number("blobbiness", p.blobbiness);
  number("majorRadius", p.majorRadius);
  number("exponent", p.exponent);
  if (const Value* v = json::find(value, "negative")) {
    p.negative = json::boolean(*v, field + ".negative");
  }
  if (const Value* v = json::find(value, "transform")) {
    p.transform = parseTransform(*v, field + ".transform", warnings);
  }
  if (const Value* v = json::find(value, "expression")) {
    std::string_view text = json::string(*v, field + ".expression");
    if (text.size() > limits.maxExpressionLength) {
      tooLarge("maxExpressionLength", field + ".expression has " + std::to_string(text.size()) +
                                          " characters, over limit maxExpressionLength (" +
                                          std::to_string(limits.maxExpressionLength) + ")");
    }
    p.expression = std::string(text);
  }
  if (const Value* v = json::find(value, "bounds")) p.bounds = parseBounds(*v, field + ".bounds");
  if (p.type == PrimitiveType::Expression && p.expression.empty()) {
    json::fail(field + ".expression", field + ".expression is required for type \"expression\"");
  }
  return p;
}

render::implicit::FieldSpec parseField(const Value& value,
                                       const render::pipeline::JobLimits& limits,
                                       std::vector<std::string>& warnings) {
  json::requireObject(value, "field");
  request::warnUnknownFields(value, "field", {"iso", "primitives"}, warnings);
  render::implicit::FieldSpec spec;
  if (const Value* v = json::find(value, "iso")) spec.iso = json::number(*v, "field.iso");
  const Value* primitives = json::find(value, "primitives");
  if (!primitives) json::fail("field.primitives", "field.primitives is required");
  json::requireArray(*primitives, "field.primitives");
  if (primitives->Size() > static_cast<rapidjson::SizeType>(limits.maxPrimitives)) {
    tooLarge("maxPrimitives", "field.primitives has " + std::to_string(primitives->Size()) +
                                  " primitives, over limit maxPrimitives (" +
                                  std::to_string(limits.maxPrimitives) + ")");
  }
  for (rapidjson::SizeType i = 0; i < primitives->Size(); ++i) {
    spec.primitives.push_back(parsePrimitive((*primitives)[i], i, limits, warnings));
  }
  return spec;
}

render::implicit::PolygonizerOptions parsePolygonizer(const Value& value,
                                                      const render::pipeline::JobLimits& limits,
                                                      std::vector<std::string>& warnings) {
  json::requireObject(value, "polygonizer");
  request::warnUnknownFields(value, "polygonizer",
                             {"method", "resolution", "flatness", "epsilon", "maxDepth"}, warnings);
  render::implicit::PolygonizerOptions options;
  if (const Value* v = json::find(value, "method")) {
    options.method =
        json::choice<PolygonizerMethod>(*v, "polygonizer.method",
                                        {{"marching-cubes", PolygonizerMethod::MarchingCubes},
                                         {"tracker", PolygonizerMethod::Tracker},
                                         {"octree", PolygonizerMethod::Octree},
                                         {"adaptive", PolygonizerMethod::Adaptive}});
  }
  if (const Value* v = json::find(value, "resolution")) {
    options.resolution = json::integer(*v, "polygonizer.resolution");
    if (options.resolution > limits.maxResolution) {
      tooLarge("maxResolution", "polygonizer.resolution " + std::to_string(options.resolution) +
                                    " exceeds limit maxResolution (" +
                                    std::to_string(limits.maxResolution) + ")");
    }
  }
  if (const Value* v = json::find(value, "flatness")) {
    options.flatness = json::number(*v, "polygonizer.flatness");
  }
  if (const Value* v = json::find(value, "epsilon")) {
    options.epsilon = json::number(*v, "polygonizer.epsilon");
  }
  if (const Value* v = json::find(value, "maxDepth")) {
    options.maxDepth = json::integer(*v, "polygonizer.maxDepth");
  }
  return options;
}

}  // namespace

bool isImplicitRequest(std::string_view body) {
  rapidjson::Document document;
  try {
    request::parseJson(body, document);
  } catch (const ApiError&) {
    return false;
  }
  return document.IsObject() && document.HasMember("field");
}

ImplicitRequest parseImplicitRequest(std::string_view body,
                                     const render::pipeline::JobLimits& limits) {
  rapidjson::Document root;
  request::parseJson(body, root);
  if (!root.IsObject()) {
    json::fail("", "the request body must be a JSON object, got " + json::describe(root));
  }
  ImplicitRequest request;
  std::vector<std::string>& warnings = request.warnings;
  render::pipeline::ImplicitJob& job = request.job;
  request::warnUnknownFields(root, "",
                             {"field", "polygonizer", "camera", "shading", "outputs", "antialias",
                              "background", "reference", "imageFormat", "imageQuality", "params"},
                             warnings);
  if (const Value* v = json::find(root, "camera")) {
    job.camera = request::parseCamera(*v, limits, warnings);
  }
  if (const Value* v = json::find(root, "polygonizer")) {
    job.polygonizer = parsePolygonizer(*v, limits, warnings);
  }
  if (const Value* v = json::find(root, "shading")) job.shading = request::parseShading(*v);
  if (const Value* v = json::find(root, "outputs")) job.outputs = request::parseOutputs(*v);
  if (const Value* v = json::find(root, "antialias")) {
    job.outputs.antialias = request::parseAntialias(*v);
  }
  if (job.outputs.contours || job.outputs.cage) {
    json::fail("outputs",
               "outputs \"contours\" and \"cage\" belong to subdivision meshes; an "
               "implicit scene has color, mask, depth, normal, wireframe and diff");
  }
  if (const Value* v = json::find(root, "reference"))
    job.reference = json::boolean(*v, "reference");
  if (job.outputs.diff && !job.reference) {
    json::fail("outputs",
               "output \"diff\" compares with the reference: it needs \"reference\": true");
  }
  request.encoding = request::parseImageEncoding(root);
  if (const Value* v = json::find(root, "background")) {
    job.outputs.background = request::parseBackground(*v);
  }
  if (const Value* v = json::find(root, "params")) {
    json::requireObject(*v, "params");
    request::warnUnknownFields(*v, "params", {"metricSupersample"}, warnings);
    if (const Value* s = json::find(*v, "metricSupersample")) {
      job.metricSupersample = json::integer(*s, "params.metricSupersample");
      if (job.metricSupersample < 1 || job.metricSupersample > limits.maxSupersample) {
        json::fail("params.metricSupersample", "params.metricSupersample must be in 1.." +
                                                   std::to_string(limits.maxSupersample));
      }
    }
  }
  const Value* field = json::find(root, "field");
  if (!field) json::fail("field", "field is required");
  job.field = parseField(*field, limits, warnings);
  return request;
}

}  // namespace limn::api
