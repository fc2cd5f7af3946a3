// handleMeshUpload: POST /v1/meshes. The mesh is read exactly as /v1/render reads one (either
// form, the same limits and messages), validated so that a broken mesh is refused at upload
// rather than at its first render, and kept in the server's MeshCache under its content hash.
#include "api/json_util.h"
#include "api/render_api.h"
#include "api/request_parts.h"

namespace limn::api {

Answer handleMeshUpload(std::string_view body, const render::pipeline::JobLimits& limits,
                        render::mesh::MeshCache& meshes) {
  return answerOrError("mesh upload", [&] {
    rapidjson::Document root;
    request::parseJson(body, root);
    if (!root.IsObject()) {
      json::fail("", "the request body must be a JSON object, got " + json::describe(root));
    }
    std::vector<std::string> warnings;
    request::warnUnknownFields(root, "", {"mesh"}, warnings);
    const json::Value* meshValue = json::find(root, "mesh");
    if (!meshValue) json::fail("mesh", "mesh is required");
    json::requireObject(*meshValue, "mesh");
    if (json::find(*meshValue, "id")) {
      json::fail("mesh.id", "POST /v1/meshes takes a mesh (OBJ or JSON form), not an id");
    }
    render::mesh::ControlMesh mesh;
    try {
      mesh = request::parseMesh(*meshValue, limits, warnings);
      render::mesh::validateMesh(mesh, limits.mesh);
    } catch (const render::InputError& error) {
      throw fromInputError(error);
    }
    const int vertices = mesh.vertexCount(), faces = mesh.faceCount();
    const render::mesh::Scheme scheme = mesh.scheme;
    const size_t bytes = render::mesh::MeshCache::bytesOf(mesh);
    render::mesh::MeshCache::Stored stored = meshes.put(std::move(mesh));
    if (!stored.kept) {
      throw tooLarge("meshCacheBytes", "mesh",
                     "the mesh needs about " + std::to_string(bytes) +
                         " bytes, more than this server keeps for uploaded meshes (limit "
                         "meshCacheBytes, " +
                         std::to_string(meshes.counters().capacityBytes) +
                         "); send it inline with each request instead");
    }

    rapidjson::StringBuffer buffer;
    json::Writer w(buffer);
    w.StartObject();
    w.Key("id");
    json::writeString(w, stored.id);
    w.Key("vertices");
    w.Int(vertices);
    w.Key("faces");
    w.Int(faces);
    w.Key("scheme");
    w.String(render::mesh::schemeName(scheme));
    w.Key("bytes");
    w.Uint64(bytes);
    w.Key("warnings");
    w.StartArray();
    for (const std::string& warning : warnings) json::writeString(w, warning);
    w.EndArray();
    w.EndObject();
    Answer answer;
    answer.body = {buffer.GetString(), buffer.GetSize()};
    return answer;
  });
}

std::optional<std::string> referencedMeshId(std::string_view body) {
  // Inline meshes are the common case, and large: most bodies need no parse here.
  if (body.find("\"id\"") == std::string_view::npos) return std::nullopt;
  rapidjson::Document root;
  root.Parse<rapidjson::kParseIterativeFlag>(body.data(), body.size());
  if (root.HasParseError() || !root.IsObject()) return std::nullopt;
  const json::Value* mesh = json::find(root, "mesh");
  if (!mesh || !mesh->IsObject()) return std::nullopt;
  const json::Value* id = json::find(*mesh, "id");
  if (!id || !id->IsString()) return std::nullopt;
  return std::string(id->GetString(), id->GetStringLength());
}

}  // namespace limn::api
