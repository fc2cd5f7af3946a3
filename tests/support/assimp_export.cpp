#include "tests/support/assimp_export.h"

#include <assimp/scene.h>
#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "api/base64.h"

namespace limn::testing {

namespace {

aiMesh* toAiMesh(const SceneMesh& source) {
  const render::mesh::ControlMesh& mesh = source.mesh;
  auto* out = new aiMesh;
  out->mName = aiString(source.name);
  out->mMaterialIndex = 0;
  const bool triangles = std::all_of(mesh.faceVertexCounts.begin(), mesh.faceVertexCounts.end(),
                                     [](int n) { return n == 3; });
  out->mPrimitiveTypes = triangles ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
  const unsigned corners = static_cast<unsigned>(mesh.faceVertexIndices.size());
  out->mNumVertices = source.splitCorners ? corners : static_cast<unsigned>(mesh.points.size());
  out->mVertices = new aiVector3D[out->mNumVertices];
  auto point = [&](int v) {
    const render::Vec3& p = mesh.points[v];
    return aiVector3D(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
  };
  if (!source.splitCorners) {
    for (unsigned v = 0; v < out->mNumVertices; ++v) out->mVertices[v] = point(static_cast<int>(v));
  }
  out->mNumFaces = static_cast<unsigned>(mesh.faceCount());
  out->mFaces = new aiFace[out->mNumFaces];
  unsigned at = 0;
  for (unsigned f = 0; f < out->mNumFaces; ++f) {
    aiFace& face = out->mFaces[f];
    face.mNumIndices = static_cast<unsigned>(mesh.faceVertexCounts[f]);
    face.mIndices = new unsigned[face.mNumIndices];
    for (unsigned c = 0; c < face.mNumIndices; ++c, ++at) {
      const int v = mesh.faceVertexIndices[at];
      if (source.splitCorners) {
        out->mVertices[at] = point(v);
        face.mIndices[c] = at;
      } else {
        face.mIndices[c] = static_cast<unsigned>(v);
      }
    }
  }
  return out;
}

std::unique_ptr<aiScene> sceneOf(const std::vector<SceneMesh>& meshes) {
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("root");
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { new aiMaterial };
  scene->mNumMeshes = static_cast<unsigned>(meshes.size());
  scene->mMeshes = new aiMesh*[meshes.size()];
  scene->mRootNode->mNumChildren = static_cast<unsigned>(meshes.size());
  scene->mRootNode->mChildren = new aiNode*[meshes.size()];
  for (size_t i = 0; i < meshes.size(); ++i) {
    scene->mMeshes[i] = toAiMesh(meshes[i]);
    auto* node = new aiNode(meshes[i].name);
    node->mParent = scene->mRootNode;
    const render::Vec3& t = meshes[i].translation;
    aiMatrix4x4::Translation(
        aiVector3D(static_cast<float>(t.x), static_cast<float>(t.y), static_cast<float>(t.z)),
        node->mTransformation);
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{static_cast<unsigned>(i)};
    scene->mRootNode->mChildren[i] = node;
  }
  return scene;
}

// The .gltf with its .bin blob inlined as a data: URI: limn reads no second file.
std::string inlineGltfBuffer(const aiExportDataBlob& blob) {
  rapidjson::Document gltf;
  gltf.Parse(static_cast<const char*>(blob.data), blob.size);
  if (gltf.HasParseError() || !blob.next) throw std::runtime_error("gltf2: no JSON and buffer");
  const std::string bin(static_cast<const char*>(blob.next->data), blob.next->size);
  const std::string uri = "data:application/octet-stream;base64," + api::encodeBase64(bin);
  gltf["buffers"][0]["uri"].SetString(uri.c_str(), static_cast<rapidjson::SizeType>(uri.size()),
                                      gltf.GetAllocator());
  rapidjson::StringBuffer out;
  rapidjson::Writer<rapidjson::StringBuffer> writer(out);
  gltf.Accept(writer);
  return {out.GetString(), out.GetSize()};
}

}  // namespace

std::string exportWithAssimp(const std::vector<SceneMesh>& meshes, const std::string& formatId) {
  std::unique_ptr<aiScene> scene = sceneOf(meshes);
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), formatId);
  if (!blob) throw std::runtime_error(formatId + ": " + exporter.GetErrorString());
  if (formatId == "gltf2") return inlineGltfBuffer(*blob);
  return {static_cast<const char*>(blob->data), blob->size};
}

std::string nonIndexedGltf(const render::mesh::ControlMesh& mesh) {
  std::string buffer;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (int v : mesh.faceVertexIndices) {
    const render::Vec3& p = mesh.points[v];
    const float xyz[3] = {static_cast<float>(p.x), static_cast<float>(p.y),
                          static_cast<float>(p.z)};
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], xyz[i]);
      hi[i] = std::max(hi[i], xyz[i]);
    }
    buffer.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  }
  std::ostringstream gltf;
  gltf.precision(9);
  gltf << R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":)" << buffer.size()
       << R"(,"uri":"data:application/octet-stream;base64,)" << api::encodeBase64(buffer)
       << R"("}],"bufferViews":[{"buffer":0,"byteLength":)" << buffer.size()
       << R"(}],"accessors":[{"bufferView":0,"componentType":5126,"count":)"
       << mesh.faceVertexIndices.size() << R"(,"type":"VEC3","min":[)" << lo[0] << "," << lo[1]
       << "," << lo[2] << "],\"max\":[" << hi[0] << "," << hi[1] << "," << hi[2]
       << R"(]}],"meshes":[{"name":"split","primitives":[{"attributes":{"POSITION":0}}]}],)"
       << R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  return gltf.str();
}

std::string writeOff(const render::mesh::ControlMesh& mesh) {
  std::ostringstream off;
  off.precision(17);
  off << "OFF\n# written by limn's tests\n"
      << mesh.vertexCount() << " " << mesh.faceCount() << " 0\n";
  for (const render::Vec3& p : mesh.points) off << p.x << " " << p.y << " " << p.z << "\n";
  size_t at = 0;
  for (int n : mesh.faceVertexCounts) {
    off << n;
    for (int c = 0; c < n; ++c) off << " " << mesh.faceVertexIndices[at++];
    off << "\n";
  }
  return off.str();
}

}  // namespace limn::testing
