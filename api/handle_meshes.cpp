// POST /v1/meshes. The mesh is read exactly as /v1/render reads one (any form, the same limits
// and messages), validated so that a broken mesh is refused at upload rather than at its first
// render, and kept in the server's MeshCache under its content hash. Reading (Assimp's formats
// above all) happens in a worker process: handleMeshImport answers the mesh in limn's JSON form,
// and storeImportedMesh, in the server, reads that back with limn's own reader and keeps it.
#include <cctype>

#include "api/accept.h"
#include "api/base64.h"
#include "api/json_mesh_reader.h"
#include "api/json_util.h"
#include "api/render_api.h"
#include "api/request_parts.h"
#include "formats/assimp_import.h"

namespace limn::api {

namespace {

// {"mesh": {...}} of an upload, with the JSON errors an upload gets.
const json::Value& uploadedMeshOf(const rapidjson::Document& root,
                                  std::vector<std::string>& warnings) {
  if (!root.IsObject()) {
    json::fail("", "the request body must be a JSON object, got " + json::describe(root));
  }
  request::warnUnknownFields(root, "", {"mesh"}, warnings);
  const json::Value* meshValue = json::find(root, "mesh");
  if (!meshValue) json::fail("mesh", "mesh is required");
  json::requireObject(*meshValue, "mesh");
  if (json::find(*meshValue, "id")) {
    json::fail("mesh.id", "POST /v1/meshes takes a mesh (a file or the JSON form), not an id");
  }
  return *meshValue;
}

// Percent-decoding of a query value ("my%20mesh" -> "my mesh"); '+' is a space.
std::string decodeQueryValue(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '+') {
      out += ' ';
    } else if (text[i] == '%' && i + 2 < text.size() &&
               std::isxdigit(static_cast<unsigned char>(text[i + 1])) &&
               std::isxdigit(static_cast<unsigned char>(text[i + 2]))) {
      out += static_cast<char>(std::stoi(std::string(text.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      out += text[i];
    }
  }
  return out;
}

// The format a file upload's media type names: Assimp's types, model/obj and text/plain (OBJ),
// or application/octet-stream with ?format=.
std::string uploadFormatOf(std::string_view mediaType, const std::string& formatParameter) {
  if (!formatParameter.empty()) return formatParameter;
  if (std::optional<formats::ImportFormat> format = formats::importFormatOfMediaType(mediaType)) {
    return formats::importFormatName(*format);
  }
  if (sameMediaType(mediaType, "model/obj") || sameMediaType(mediaType, "text/plain")) return "obj";
  throw ApiError{415, "unsupported_media_type",
                 "POST /v1/meshes takes application/json ({\"mesh\": ...}) or a mesh file: "
                 "model/gltf-binary, model/gltf+json, model/obj, model/stl, model/ply, "
                 "model/vnd.collada+xml, application/x-fbx, application/x-3ds, model/x-off, or "
                 "any type with ?format=" +
                     request::meshFormatList() + "; got " + json::quote(mediaType),
                 json::detailObject({{"field", "Content-Type"}})};
}

}  // namespace

std::string meshUploadBody(std::string_view contentType, const MeshUploadQuery& query,
                           std::string body) {
  const std::string_view mediaType = contentType.substr(0, contentType.find(';'));
  const std::string_view trimmed = mediaType.substr(0, mediaType.find_last_not_of(" \t") + 1);
  if ((trimmed.empty() || sameMediaType(trimmed, "application/json")) && query.format.empty()) {
    return body;
  }
  if (query.format == "json") return body;  // the JSON form, whatever the media type says
  const std::string format = uploadFormatOf(trimmed, decodeQueryValue(query.format));
  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  w.StartObject();
  w.Key("mesh");
  w.StartObject();
  w.Key("format");
  json::writeString(w, format);
  if (!query.scheme.empty()) {
    w.Key("scheme");
    json::writeString(w, decodeQueryValue(query.scheme));
  }
  if (!query.name.empty()) {
    w.Key("name");
    json::writeString(w, decodeQueryValue(query.name));
  }
  w.Key("dataBase64");
  json::writeString(w, encodeBase64(body));
  w.EndObject();
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

Answer handleMeshImport(std::string_view body, const render::pipeline::JobLimits& limits) {
  return answerOrError("mesh upload", [&] {
    rapidjson::Document root;
    request::parseJson(body, root);
    std::vector<std::string> warnings;
    const json::Value& meshValue = uploadedMeshOf(root, warnings);
    render::mesh::ControlMesh mesh;
    try {
      mesh = request::parseMesh(meshValue, limits, warnings);
      render::mesh::validateMesh(mesh, limits.mesh);
    } catch (const render::InputError& error) {
      throw fromInputError(error);
    }
    const std::string meshJson = writeJsonMesh(mesh);
    rapidjson::StringBuffer buffer;
    json::Writer w(buffer);
    w.StartObject();
    w.Key("mesh");
    w.RawValue(meshJson.data(), meshJson.size(), rapidjson::kObjectType);
    w.Key("warnings");
    json::writeStrings(w, warnings);
    w.EndObject();
    Answer answer;
    answer.body = {buffer.GetString(), buffer.GetSize()};
    return answer;
  });
}

Answer storeImportedMesh(const Answer& imported, const render::pipeline::JobLimits& limits,
                         render::mesh::MeshCache& meshes) {
  if (imported.status != 200) return imported;
  return answerOrError("mesh upload", [&] {
    rapidjson::Document root;
    request::parseJson(imported.body, root);
    render::mesh::ControlMesh mesh = readJsonMesh(root["mesh"], "mesh", limits.mesh);
    std::vector<std::string> warnings;
    for (const json::Value& w : root["warnings"].GetArray()) warnings.emplace_back(w.GetString());
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
    json::writeStrings(w, warnings);
    w.EndObject();
    Answer answer;
    answer.body = {buffer.GetString(), buffer.GetSize()};
    return answer;
  });
}

Answer handleMeshUpload(std::string_view body, const render::pipeline::JobLimits& limits,
                        render::mesh::MeshCache& meshes) {
  return storeImportedMesh(handleMeshImport(body, limits), limits, meshes);
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
