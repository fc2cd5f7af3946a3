#include "formats/assimp_import.h"

#include <assimp/BaseImporter.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <unordered_map>
#include <utility>

#include "formats/import_preflight.h"
#include "render/core/error.h"

namespace limn::formats {

namespace {

using render::InputError;
using render::Vec3;
using render::mesh::ControlMesh;
using render::mesh::MeshLimits;

struct NamedFormat {
  const char* name;
  ImportFormat format;
};

constexpr NamedFormat kFormatNames[] = {
    {"gltf", ImportFormat::Gltf},   {"glb", ImportFormat::Glb}, {"ply", ImportFormat::Ply},
    {"stl", ImportFormat::Stl},     {"fbx", ImportFormat::Fbx}, {"dae", ImportFormat::Dae},
    {"3ds", ImportFormat::ThreeDs}, {"off", ImportFormat::Off},
};

// Assimp's IOSystem for everything but the file itself (which ReadFileFromMemory serves): no
// file exists. A glTF that names "/etc/passwd" or "../secret.bin" as its buffer gets nothing.
class NoFiles : public Assimp::IOSystem {
 public:
  bool Exists(const char*) const override { return false; }
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char*, const char*) override { return nullptr; }
  void Close(Assimp::IOStream*) override {}
};

[[noreturn]] void unreadable(ImportFormat format, const std::string& why) {
  throw InputError(InputError::Kind::InvalidMesh, "mesh.data",
                   std::string("the ") + importFormatName(format) + " file cannot be read: " + why);
}

// Whether Assimp's importer `desc` reads files named *.extension.
bool readsExtension(const aiImporterDesc* desc, std::string_view extension) {
  if (!desc || !desc->mFileExtensions) return false;
  std::string_view list = desc->mFileExtensions;
  while (!list.empty()) {
    const size_t space = list.find(' ');
    if (list.substr(0, space) == extension) return true;
    if (space == std::string_view::npos) break;
    list.remove_prefix(space + 1);
  }
  return false;
}

// Assimp's importers of other formats, taken out of `importer` (and deleted with the returned
// list, after it): when the named format's importer declines a file, Assimp otherwise guesses
// the format from the content among all of its some 40 importers, so a file sent as "gltf"
// could reach the Quake 3 or the Blender reader (fuzz/mesh_import found exactly that).
std::vector<std::unique_ptr<Assimp::BaseImporter>> keepOnlyImportersOf(Assimp::Importer& importer,
                                                                       ImportFormat format) {
  std::vector<std::unique_ptr<Assimp::BaseImporter>> others;
  for (size_t i = importer.GetImporterCount(); i-- > 0;) {
    if (readsExtension(importer.GetImporterInfo(i), importFormatName(format))) continue;
    Assimp::BaseImporter* other = importer.GetImporter(i);
    if (importer.UnregisterLoader(other) == aiReturn_SUCCESS) others.emplace_back(other);
  }
  return others;
}

const aiScene* readScene(Assimp::Importer& importer, std::string_view bytes, ImportFormat format) {
  importer.SetIOHandler(new NoFiles);  // the importer owns it
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_ANIMATIONS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_TEXTURES, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  // No triangulation and no vertex joining by Assimp: polygons stay polygons, and welding by
  // position (below) is what a cage needs, not Assimp's join of identical attribute sets.
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_ValidateDataStructure,
                                        importFormatName(format));
  } catch (const std::exception& e) {
    unreadable(format, e.what());
  }
  if (!scene) {
    const std::string error = importer.GetErrorString();
    unreadable(format, error.empty() ? "Assimp gave no reason" : error);
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) unreadable(format, "the scene is incomplete");
  return scene;
}

// One mesh of the scene as a node places it.
struct Instance {
  const aiNode* node;
  aiMatrix4x4 transform;  // node to world
  std::vector<unsigned> meshes;
};

bool named(const aiString& name, const std::string& wanted) {
  return std::string_view(name.data, name.length) == wanted;
}

// Every node with meshes, with its world transform; an explicit stack, since a hostile file may
// nest nodes deeply. With a name, only the node of that name or the meshes of that name.
std::vector<Instance> instancesOf(const aiScene& scene, const std::string& meshName) {
  std::vector<Instance> instances;
  if (!scene.mRootNode) return instances;
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack{{scene.mRootNode, aiMatrix4x4()}};
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    const aiMatrix4x4 world = parent * node->mTransformation;
    Instance instance{node, world, {}};
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const unsigned m = node->mMeshes[i];
      if (m >= scene.mNumMeshes) continue;
      if (meshName.empty() || named(node->mName, meshName) ||
          named(scene.mMeshes[m]->mName, meshName)) {
        instance.meshes.push_back(m);
      }
    }
    if (!instance.meshes.empty()) instances.push_back(std::move(instance));
    for (unsigned c = 0; c < node->mNumChildren; ++c) stack.push_back({node->mChildren[c], world});
  }
  return instances;
}

std::string meshNamesOf(const aiScene& scene) {
  std::string names;
  for (unsigned m = 0; m < scene.mNumMeshes && m < 12; ++m) {
    if (!names.empty()) names += ", ";
    names +=
        "\"" + std::string(scene.mMeshes[m]->mName.data, scene.mMeshes[m]->mName.length) + "\"";
  }
  return names.empty() ? "none" : names;
}

// Before anything is copied: the scene's faces and vertices within the limits. Vertices are
// counted before welding, where a file may hold several per corner (STL: three per triangle),
// so they may reach maxVertices times the most a weld commonly folds (8).
void checkSceneSize(const aiScene& scene, const std::vector<Instance>& instances,
                    const MeshLimits& limits) {
  uint64_t vertices = 0, faces = 0;
  for (const Instance& instance : instances) {
    for (unsigned m : instance.meshes) {
      vertices += scene.mMeshes[m]->mNumVertices;
      faces += scene.mMeshes[m]->mNumFaces;
    }
  }
  if (faces > static_cast<uint64_t>(limits.maxFaces)) {
    throw InputError(InputError::Kind::LimitExceeded, "maxFaces",
                     "the file's meshes have " + std::to_string(faces) + " faces, more than " +
                         std::to_string(limits.maxFaces));
  }
  if (vertices > 8 * static_cast<uint64_t>(limits.maxVertices)) {
    throw InputError(InputError::Kind::LimitExceeded, "maxVertices",
                     "the file's meshes have " + std::to_string(vertices) +
                         " vertices before welding, more than 8 x " +
                         std::to_string(limits.maxVertices));
  }
}

// Position bits, with -0 made +0 so that a seam's two copies weld.
using PositionKey = std::array<uint64_t, 3>;
struct PositionHash {
  size_t operator()(const PositionKey& k) const {
    return std::hash<uint64_t>()(k[0] * 0x9E3779B97F4A7C15ull ^ k[1] * 0xC2B2AE3D27D4EB4Full ^
                                 k[2]);
  }
};

PositionKey keyOf(const Vec3& p) {
  PositionKey key;
  const double c[3] = {p.x + 0.0, p.y + 0.0, p.z + 0.0};
  for (int i = 0; i < 3; ++i) std::memcpy(&key[i], &c[i], sizeof(double));
  return key;
}

struct Counts {
  int pointsAndLines = 0;  // primitives of fewer than 3 corners, left out
  int collapsedFaces = 0;  // faces under 3 distinct corners once welded, left out
};

// Appends one node's meshes to `out`, welded by position among themselves.
void appendInstance(const aiScene& scene, const Instance& instance, ImportFormat format,
                    const MeshLimits& limits, ImportedMesh& out, Counts& counts) {
  ControlMesh& mesh = out.mesh;
  std::unordered_map<PositionKey, int, PositionHash> welded;
  std::vector<int> corners;
  for (unsigned m : instance.meshes) {
    const aiMesh& source = *scene.mMeshes[m];
    std::vector<int> index(source.mNumVertices);
    for (unsigned v = 0; v < source.mNumVertices; ++v) {
      const aiVector3D p = instance.transform * source.mVertices[v];
      const Vec3 point{p.x, p.y, p.z};
      if (!std::isfinite(point.x) || !std::isfinite(point.y) || !std::isfinite(point.z)) {
        unreadable(format, "vertex " + std::to_string(v) + " of mesh \"" +
                               std::string(source.mName.data, source.mName.length) +
                               "\" is not finite");
      }
      auto [at, added] = welded.try_emplace(keyOf(point), mesh.vertexCount());
      if (added) {
        if (mesh.vertexCount() >= limits.maxVertices) {
          throw InputError(InputError::Kind::LimitExceeded, "maxVertices",
                           "the file's meshes have more than " +
                               std::to_string(limits.maxVertices) + " vertices once welded");
        }
        mesh.points.push_back(point);
      } else {
        ++out.verticesWelded;
      }
      index[v] = at->second;
    }
    for (unsigned f = 0; f < source.mNumFaces; ++f) {
      const aiFace& face = source.mFaces[f];
      if (face.mNumIndices < 3) {
        ++counts.pointsAndLines;
        continue;
      }
      if (face.mNumIndices > static_cast<unsigned>(limits.maxFaceSize)) {
        throw InputError(InputError::Kind::LimitExceeded, "maxFaceSize",
                         "a face of the file has " + std::to_string(face.mNumIndices) +
                             " vertices, more than " + std::to_string(limits.maxFaceSize));
      }
      corners.clear();
      for (unsigned c = 0; c < face.mNumIndices; ++c) {
        if (face.mIndices[c] >= source.mNumVertices)
          unreadable(format, "a face index is out of range");
        const int v = index[face.mIndices[c]];
        if (corners.empty() || corners.back() != v) corners.push_back(v);
      }
      while (corners.size() > 1 && corners.front() == corners.back()) corners.pop_back();
      if (corners.size() < 3) {
        ++counts.collapsedFaces;
        continue;
      }
      mesh.faceVertexCounts.push_back(static_cast<int>(corners.size()));
      mesh.faceVertexIndices.insert(mesh.faceVertexIndices.end(), corners.begin(), corners.end());
    }
  }
  ++out.meshesMerged;
}

void chooseScheme(const ImportOptions& options, ImportedMesh& out) {
  if (options.scheme) {
    out.mesh.scheme = *options.scheme;
    return;
  }
  const bool triangles = std::all_of(out.mesh.faceVertexCounts.begin(),
                                     out.mesh.faceVertexCounts.end(), [](int n) { return n == 3; });
  out.mesh.scheme = triangles ? render::mesh::Scheme::Loop : render::mesh::Scheme::CatmullClark;
  out.schemeChosen = true;
}

}  // namespace

std::optional<ImportFormat> importFormatNamed(std::string_view name) {
  if (name == "collada") return ImportFormat::Dae;
  for (const NamedFormat& f : kFormatNames) {
    if (name == f.name) return f.format;
  }
  return std::nullopt;
}

const char* importFormatName(ImportFormat format) {
  for (const NamedFormat& f : kFormatNames) {
    if (f.format == format) return f.name;
  }
  return "?";
}

const std::vector<std::string>& importFormatNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const NamedFormat& f : kFormatNames) all.emplace_back(f.name);
    return all;
  }();
  return names;
}

std::optional<ImportFormat> importFormatOfMediaType(std::string_view mediaType) {
  static const std::pair<const char*, ImportFormat> kTypes[] = {
      {"model/gltf-binary", ImportFormat::Glb},
      {"model/gltf+json", ImportFormat::Gltf},
      {"model/stl", ImportFormat::Stl},
      {"application/sla", ImportFormat::Stl},
      {"model/ply", ImportFormat::Ply},
      {"application/x-ply", ImportFormat::Ply},
      {"model/vnd.collada+xml", ImportFormat::Dae},
      {"application/x-3ds", ImportFormat::ThreeDs},
      {"image/x-3ds", ImportFormat::ThreeDs},
      {"application/x-fbx", ImportFormat::Fbx},
      {"model/x-off", ImportFormat::Off},
  };
  for (const auto& [type, format] : kTypes) {
    if (mediaType == type) return format;
  }
  return std::nullopt;
}

ImportedMesh importMesh(std::string_view bytes, ImportFormat format, const ImportOptions& options,
                        const MeshLimits& limits) {
  if (bytes.empty()) unreadable(format, "the file is empty");
  checkDeclaredSizes(bytes, format, limits);

  Assimp::Importer importer;
  const auto others = keepOnlyImportersOf(importer, format);
  const aiScene* scene = readScene(importer, bytes, format);
  const std::vector<Instance> instances = instancesOf(*scene, options.meshName);
  if (instances.empty()) {
    if (!options.meshName.empty()) {
      throw InputError(InputError::Kind::InvalidMesh, "mesh.name",
                       "the " + std::string(importFormatName(format)) +
                           " file has no mesh named \"" + options.meshName +
                           "\"; its meshes: " + meshNamesOf(*scene));
    }
    unreadable(format, "it holds no mesh");
  }
  checkSceneSize(*scene, instances, limits);

  ImportedMesh out;
  Counts counts;
  for (const Instance& instance : instances) {
    appendInstance(*scene, instance, format, limits, out, counts);
  }
  if (out.mesh.faceCount() == 0)
    unreadable(format, "its meshes have no faces of 3 or more corners");
  chooseScheme(options, out);
  if (counts.pointsAndLines > 0) {
    out.warnings.push_back(std::to_string(counts.pointsAndLines) +
                           " points and lines of the file were left out (a cage has faces only)");
  }
  if (counts.collapsedFaces > 0) {
    out.warnings.push_back(std::to_string(counts.collapsedFaces) +
                           " faces with fewer than 3 distinct corners were left out");
  }
  return out;
}

}  // namespace limn::formats
