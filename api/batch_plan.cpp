// BatchPlan: meshes x views x methods as numbered rows, their keys, shards and the
// /v1/compare bodies of their groups (api/batch_plan.h).
#include "api/batch_plan.h"

#include <rapidjson/document.h>

#include <algorithm>

#include "api/base64.h"
#include "api/json_mesh_reader.h"
#include "api/json_util.h"
#include "api/request_parts.h"
#include "formats/assimp_import.h"
#include "formats/obj_reader.h"
#include "render/mesh/content_hash.h"

namespace limn::api {

namespace {

render::mesh::Scheme schemeNamed(const std::string& scheme) {
  rapidjson::Document name;
  name.SetString(scheme.c_str(), static_cast<rapidjson::SizeType>(scheme.size()));
  return readScheme(name, "scheme");
}

BatchMesh described(const render::mesh::ControlMesh& mesh, std::string name, std::string path,
                    std::string meshJson) {
  return {std::move(name),     std::move(path),    render::mesh::contentHash(mesh),
          std::move(meshJson), mesh.vertexCount(), mesh.faceCount()};
}

}  // namespace

BatchMesh meshFromObj(const std::string& name, const std::string& path, const std::string& text,
                      const std::string& scheme, const render::pipeline::JobLimits& limits) {
  formats::ObjMesh obj;
  try {
    obj = formats::readObj(text, schemeNamed(scheme), limits.mesh);
  } catch (const render::InputError& e) {
    throw fromInputError(e);
  }
  rapidjson::Document mesh(rapidjson::kObjectType);
  auto& a = mesh.GetAllocator();
  mesh.AddMember("format", "obj", a);
  mesh.AddMember("scheme", json::Value(scheme.c_str(), a), a);
  mesh.AddMember("data",
                 json::Value(text.c_str(), static_cast<rapidjson::SizeType>(text.size()), a), a);
  return described(obj.mesh, name, path, json::canonical(mesh));
}

BatchMesh meshFromFile(const std::string& name, const std::string& path, const std::string& bytes,
                       const std::string& format, const std::optional<std::string>& scheme,
                       const render::pipeline::JobLimits& limits) {
  const std::optional<formats::ImportFormat> named = formats::importFormatNamed(format);
  if (!named) json::fail("meshes", path + ": " + format + " is not a mesh file format limn reads");
  formats::ImportOptions options;
  if (scheme) options.scheme = schemeNamed(*scheme);
  render::mesh::ControlMesh mesh;
  try {
    mesh = formats::importMesh(bytes, *named, options, limits.mesh).mesh;
    render::mesh::validateMesh(mesh, limits.mesh);
  } catch (const render::InputError& e) {
    throw fromInputError(e);
  }
  rapidjson::Document wire(rapidjson::kObjectType);
  auto& a = wire.GetAllocator();
  wire.AddMember("format", json::Value(format.c_str(), a), a);
  wire.AddMember("scheme", json::Value(render::mesh::schemeName(mesh.scheme), a), a);
  const std::string encoded = encodeBase64(bytes);
  wire.AddMember("dataBase64",
                 json::Value(encoded.c_str(), static_cast<rapidjson::SizeType>(encoded.size()), a),
                 a);
  return described(mesh, name, path, json::canonical(wire));
}

BatchMesh meshFromJson(const std::string& name, const std::string& meshJson,
                       const render::pipeline::JobLimits& limits, render::mesh::MeshCache* meshes) {
  rapidjson::Document document;
  request::parseJson(meshJson, document);
  // A job's meshes are read where the job is planned, in the server process: the files only
  // Assimp reads go through a worker process as uploads instead (POST /v1/meshes).
  if (request::readsThroughAssimp(document)) {
    json::fail("mesh.format",
               "a job takes its " + std::string(document["format"].GetString()) +
                   " meshes by id: upload the file with POST /v1/meshes and give "
                   "{\"mesh\": {\"id\": ...}} in the job (OBJ and JSON meshes may be inline)");
  }
  std::vector<std::string> warnings;
  try {
    render::mesh::ControlMesh mesh = request::parseMesh(document, limits, warnings, meshes);
    render::mesh::validateMesh(mesh, limits.mesh);
    // A mesh named by id lives in this process's cache only: the plan carries it inline, so
    // that a job's spec reads the same in every replica and after a restart.
    const bool byId = document.IsObject() && document.HasMember("id");
    return described(mesh, name, "", byId ? writeJsonMesh(mesh) : meshJson);
  } catch (const render::InputError& e) {
    throw fromInputError(e);
  }
}

std::string rowKey(const BatchMesh& mesh, const MethodVariant& method, const ViewSpec& view,
                   int size, int supersample) {
  return mesh.hash + " " + method.key() + " " + view.cameraJson + " " + std::to_string(size) +
         "px S" + std::to_string(supersample);
}

BatchPlan::BatchPlan(BatchSpec spec, std::vector<BatchMesh> meshes)
    : spec_(std::move(spec)), meshes_(std::move(meshes)) {
  for (size_t m = 0; m < meshes_.size(); ++m) {
    for (size_t v = 0; v < spec_.views.size(); ++v) {
      for (size_t k = 0; k < spec_.methods.size(); ++k) {
        rows_.push_back(
            {rows_.size(), m, v, k,
             rowKey(meshes_[m], spec_.methods[k], spec_.views[v], spec_.size, spec_.supersample)});
      }
    }
  }
}

std::vector<RowGroup> BatchPlan::pendingGroups(const Shard& shard,
                                               const std::set<std::string>& done,
                                               size_t maxRowsPerGroup) const {
  std::vector<RowGroup> groups;
  const size_t count = static_cast<size_t>(std::max(shard.count, 1));
  for (const BatchRow& row : rows_) {
    if (row.index % count != static_cast<size_t>(shard.index) || done.count(row.key)) continue;
    const bool sameView = !groups.empty() && groups.back().mesh == row.mesh &&
                          groups.back().view == row.view &&
                          groups.back().rows.size() < std::max<size_t>(maxRowsPerGroup, 1);
    if (!sameView) groups.push_back({row.mesh, row.view, {}});
    groups.back().rows.push_back(row.index);
  }
  return groups;
}

std::string BatchPlan::compareBody(const RowGroup& group) const {
  std::string methods;
  for (size_t r : group.rows) {
    methods += (methods.empty() ? "" : ",") + spec_.methods[rows_[r].method].compareJson();
  }
  return "{\"mesh\":" + meshes_[group.mesh].meshJson +
         ",\"camera\":" + spec_.views[group.view].compareJson(spec_.size) + ",\"methods\":[" +
         methods + "],\"metricSupersample\":" + std::to_string(spec_.supersample) +
         ",\"outputs\":[]}";
}

}  // namespace limn::api
