// parseBatchSpec, parseMethodList, seededViews, namedView: the batch spec and its expansion
// into flat lists of methods and views (api/batch_spec.h).
#include "api/batch_spec.h"

#include <rapidjson/document.h>

#include <cmath>
#include <functional>
#include <set>
#include <utility>

#include "api/batch_views.h"
#include "api/compare_api.h"
#include "api/json_mesh_reader.h"
#include "api/json_util.h"
#include "api/request_parts.h"

namespace limn::api {

namespace {

using json::Value;
using render::pipeline::JobLimits;

constexpr size_t kMaxVariants = 10000;  // the methods a sweep may expand to

std::string textOf(const Value& value) { return json::canonical(value); }

rapidjson::Document parseText(const std::string& text) {
  rapidjson::Document document;
  document.Parse(text.c_str(), text.size());
  return document;
}

// ---- methods ----

// A variant checked by /v1/render's readers; `field` names its spec entry.
MethodVariant makeVariant(const std::string& field, const std::string& method,
                          const std::string& paramsJson, const std::string& shading,
                          const std::string& label, const JobLimits& limits) {
  // Read by /v1/compare's own reader of a "methods" entry: a spec is refused for exactly what
  // a comparison would refuse, with the entry's name in the message.
  rapidjson::Document entry(rapidjson::kObjectType);
  auto& a = entry.GetAllocator();
  rapidjson::Document params = parseText(paramsJson);
  entry.AddMember("method", Value(method.c_str(), a), a);
  entry.AddMember("params", Value(params, a), a);
  entry.AddMember("shading", Value(shading.c_str(), a), a);
  std::vector<std::string> warnings;
  const request::ParsedMethod m = request::parseCompareMethod(entry, field, limits, warnings);
  if (!warnings.empty()) json::fail(field, warnings.front());
  MethodVariant v;
  v.method = method;
  v.paramsJson = paramsJson;
  v.shading = shading;
  v.label = label.empty() ? m.label : label;
  return v;
}

// Every combination of the array-valued params (and shadings) of one "methods" entry.
std::vector<std::string> expandParams(const Value& params, const std::string& field) {
  std::vector<rapidjson::Document> combos(1);
  combos[0].SetObject();
  for (auto it = params.MemberBegin(); it != params.MemberEnd(); ++it) {
    const Value& v = it->value;
    const std::string key(it->name.GetString(), it->name.GetStringLength());
    if (v.IsArray() && v.Empty()) {
      json::fail(field + ".params." + key,
                 field + ".params." + key + " sweeps no value: give at least one");
    }
    std::vector<rapidjson::Document> next;
    const rapidjson::SizeType n = v.IsArray() ? v.Size() : 1;
    for (const rapidjson::Document& combo : combos) {
      for (rapidjson::SizeType i = 0; i < n; ++i) {
        rapidjson::Document d;
        d.CopyFrom(combo, d.GetAllocator());
        d.AddMember(Value(key.c_str(), d.GetAllocator()),
                    Value(v.IsArray() ? v[i] : v, d.GetAllocator()), d.GetAllocator());
        next.push_back(std::move(d));
        if (next.size() > kMaxVariants) {
          json::fail(field + ".params", field + ".params sweeps more than " +
                                            std::to_string(kMaxVariants) + " combinations");
        }
      }
    }
    combos = std::move(next);
  }
  std::vector<std::string> out;
  for (const rapidjson::Document& combo : combos) out.push_back(textOf(combo));
  return out;
}

std::vector<MethodVariant> parseMethodEntry(const Value& entry, const std::string& field,
                                            const JobLimits& limits) {
  if (entry.IsString()) return parseMethodList(entry.GetString(), limits, field);
  json::requireObject(entry, field);
  for (auto it = entry.MemberBegin(); it != entry.MemberEnd(); ++it) {
    std::string_view name(it->name.GetString(), it->name.GetStringLength());
    if (name != "method" && name != "params" && name != "shading" && name != "label") {
      json::fail(field + "." + std::string(name),
                 field + "." + std::string(name) + " is not a field of a method entry");
    }
  }
  const Value* method = json::find(entry, "method");
  if (!method) json::fail(field + ".method", field + ".method is required");
  const std::string name(json::string(*method, field + ".method"));
  std::vector<std::string> paramSets{"{}"};
  if (const Value* params = json::find(entry, "params")) {
    json::requireObject(*params, field + ".params");
    paramSets = expandParams(*params, field);
  }
  std::vector<std::string> shadings{"smooth"};
  if (const Value* shading = json::find(entry, "shading")) {
    shadings.clear();
    if (shading->IsArray()) {
      for (const Value& s : shading->GetArray()) {
        shadings.emplace_back(json::string(s, field + ".shading"));
      }
      if (shadings.empty()) json::fail(field + ".shading", field + ".shading sweeps nothing");
    } else {
      shadings.emplace_back(json::string(*shading, field + ".shading"));
    }
  }
  std::string label;
  if (const Value* v = json::find(entry, "label")) label = json::string(*v, field + ".label");
  if (!label.empty() && paramSets.size() * shadings.size() > 1) {
    json::fail(field + ".label", field + ".label names one method, but the entry sweeps " +
                                     std::to_string(paramSets.size() * shadings.size()));
  }
  std::vector<MethodVariant> out;
  for (const std::string& params : paramSets) {
    for (const std::string& shading : shadings) {
      out.push_back(makeVariant(field, name, params, shading, label, limits));
    }
  }
  return out;
}

// ---- meshes ----

MeshEntry parseMeshEntry(const Value& entry, const std::string& field) {
  MeshEntry out;
  if (entry.IsString()) {
    out.pattern = entry.GetString();
    if (out.pattern.empty()) json::fail(field, field + " must not be empty");
    return out;
  }
  json::requireObject(entry, field);
  if (const Value* path = json::find(entry, "path")) {
    out.pattern = json::string(*path, field + ".path");
    if (const Value* scheme = json::find(entry, "scheme")) {
      out.scheme = std::string(json::string(*scheme, field + ".scheme"));
      readScheme(*scheme, field + ".scheme");  // a name the OBJ reader knows
    }
    return out;
  }
  const Value* mesh = json::find(entry, "mesh");
  if (!mesh) json::fail(field, field + " needs \"path\" (a file) or \"mesh\" (given inline)");
  json::requireObject(*mesh, field + ".mesh");
  out.meshJson = textOf(*mesh);
  if (const Value* name = json::find(entry, "name"))
    out.name = json::string(*name, field + ".name");
  return out;
}

int positiveInt(const Value& root, const char* key, int value, int max, const char* limit) {
  const Value* v = json::find(root, key);
  if (!v) return value;
  int n = json::integer(*v, key);
  if (n < 1) json::fail(key, std::string(key) + " must be at least 1");
  if (n > max) {
    throw tooLarge(limit, key,
                   std::string(key) + " " + std::to_string(n) + " exceeds limit " + limit + " (" +
                       std::to_string(max) + ")");
  }
  return n;
}

template <class T>
void dropDuplicates(std::vector<T>& items, const std::function<std::string(const T&)>& key) {
  std::set<std::string> seen;
  std::vector<T> kept;
  for (T& item : items) {
    if (seen.insert(key(item)).second) kept.push_back(std::move(item));
  }
  items = std::move(kept);
}

}  // namespace

std::string MethodVariant::compareJson() const {
  rapidjson::Document entry(rapidjson::kObjectType);
  auto& a = entry.GetAllocator();
  rapidjson::Document params = parseText(paramsJson);
  entry.AddMember("method", Value(method.c_str(), a), a);
  entry.AddMember("params", Value(params, a), a);
  entry.AddMember("shading", Value(shading.c_str(), a), a);
  entry.AddMember("label", Value(label.c_str(), a), a);
  return textOf(entry);
}

std::string MethodVariant::key() const { return method + " " + paramsJson + " " + shading; }

std::map<std::string, std::string> schemeIndex(std::string_view text) {
  rapidjson::Document index;
  index.Parse(text.data(), text.size());
  std::map<std::string, std::string> schemes;
  if (index.HasParseError() || !index.IsArray()) return schemes;
  for (const Value& entry : index.GetArray()) {
    if (entry.IsObject() && entry.HasMember("file") && entry["file"].IsString() &&
        entry.HasMember("scheme") && entry["scheme"].IsString()) {
      schemes[entry["file"].GetString()] = entry["scheme"].GetString();
    }
  }
  return schemes;
}

std::vector<MethodVariant> parseMethodList(std::string_view list, const JobLimits& limits,
                                           const std::string& field) {
  std::vector<MethodVariant> out;
  size_t start = 0;
  while (start <= list.size()) {
    size_t comma = list.find(',', start);
    std::string item(list.substr(start, comma == std::string_view::npos ? comma : comma - start));
    start = comma == std::string_view::npos ? list.size() + 1 : comma + 1;
    if (item.empty()) continue;
    const size_t colon = item.find(':');
    const std::string method = item.substr(0, colon);
    std::string params = "{}";
    if (colon != std::string::npos) {
      const std::string value = item.substr(colon + 1);
      const char* key = method == "uniform"    ? "level"
                        : method == "adaptive" ? "dicingRate"
                                               : nullptr;
      if (!key) {
        json::fail(field, field + ": " + json::quote(item) +
                              ": only uniform (level) and adaptive (dicing rate) take a value "
                              "after a colon");
      }
      rapidjson::Document number;
      number.Parse(value.c_str());
      if (number.HasParseError() || !number.IsNumber()) {
        json::fail(field, field + ": " + json::quote(item) + ": " + json::quote(value) +
                              " is not a number");
      }
      params = std::string("{\"") + key + "\":" + json::canonical(number) + "}";
    }
    out.push_back(makeVariant(field, method, params, "smooth", "", limits));
  }
  if (out.empty()) json::fail(field, field + " lists no method");
  return out;
}

BatchSpec parseBatchSpec(std::string_view text, const JobLimits& limits) {
  rapidjson::Document root;
  request::parseJson(text, root);
  if (!root.IsObject()) json::fail("", "a batch spec must be a JSON object");
  for (const auto& member : std::as_const(root).GetObject()) {
    std::string_view name(member.name.GetString(), member.name.GetStringLength());
    if (name != "meshes" && name != "methods" && name != "cameras" && name != "views" &&
        name != "seed" && name != "size" && name != "supersample") {
      json::fail(std::string(name),
                 "the batch spec has no field " + json::quote(name) +
                     " (meshes, methods, cameras, views, seed, size, supersample)");
    }
  }
  BatchSpec spec;
  auto list = [&](const char* key) -> const Value& {
    const Value* v = json::find(root, key);
    if (!v) json::fail(key, std::string(key) + " is required");
    json::requireArray(*v, key);
    if (v->Empty()) json::fail(key, std::string(key) + " must not be empty");
    return *v;
  };
  const Value& meshes = list("meshes");
  for (rapidjson::SizeType i = 0; i < meshes.Size(); ++i) {
    spec.meshes.push_back(parseMeshEntry(meshes[i], "meshes[" + std::to_string(i) + "]"));
  }
  const Value& methods = list("methods");
  for (rapidjson::SizeType i = 0; i < methods.Size(); ++i) {
    for (MethodVariant& v :
         parseMethodEntry(methods[i], "methods[" + std::to_string(i) + "]", limits)) {
      spec.methods.push_back(std::move(v));
    }
  }
  if (json::find(root, "cameras") || !json::find(root, "views")) {
    const Value& cameras = list("cameras");
    for (rapidjson::SizeType i = 0; i < cameras.Size(); ++i) {
      for (ViewSpec& v : parseViewEntry(cameras[i], "cameras[" + std::to_string(i) + "]", limits)) {
        spec.views.push_back(std::move(v));
      }
    }
  }
  // "views": N (and "seed") is the spec's --views: N seeded orbit views after the cameras.
  if (const Value* views = json::find(root, "views")) {
    const int count = json::integer(*views, "views");
    if (count < 1 || count > 1000) json::fail("views", "views must be in 1..1000");
    double seed = 1;
    if (const Value* v = json::find(root, "seed")) seed = json::number(*v, "seed");
    if (!(seed >= 0 && seed == std::floor(seed) && seed < 9007199254740992.0)) {
      json::fail("seed", "seed must be a non-negative integer");
    }
    for (ViewSpec& v : seededViews(count, static_cast<uint64_t>(seed))) {
      spec.views.push_back(std::move(v));
    }
  } else if (json::find(root, "seed")) {
    json::fail("seed", "seed is the seed of \"views\": give views too");
  }
  dropDuplicates<MethodVariant>(spec.methods, [](const MethodVariant& m) { return m.key(); });
  dropDuplicates<ViewSpec>(spec.views, [](const ViewSpec& v) { return v.cameraJson; });
  spec.size = positiveInt(root, "size", spec.size, limits.maxImageSide, "maxImageSide");
  spec.supersample =
      positiveInt(root, "supersample", spec.supersample, limits.maxSupersample, "maxSupersample");
  const double samples =
      static_cast<double>(spec.size) * spec.size * spec.supersample * spec.supersample;
  if (samples > static_cast<double>(limits.maxSupersampledPixels)) {
    throw tooLarge("maxSupersampledPixels", "supersample",
                   "size " + std::to_string(spec.size) + " at supersample " +
                       std::to_string(spec.supersample) + " exceeds limit maxSupersampledPixels (" +
                       std::to_string(limits.maxSupersampledPixels) + ")");
  }
  return spec;
}

}  // namespace limn::api
