// Test files of every format limn imports, written by Assimp's own exporters from a ControlMesh
// (and OFF by hand: Assimp has no OFF exporter), so that a round trip through limn's import is
// checked against files no limn code wrote.
#pragma once

#include <string>
#include <vector>

#include "render/core/vec.h"
#include "render/mesh/control_mesh.h"

namespace limn::testing {

// One mesh of a test scene: the cage and where its node puts it.
struct SceneMesh {
  std::string name;
  render::mesh::ControlMesh mesh;
  render::Vec3 translation{0, 0, 0};
  // Every face gets its own copies of its corners, as a format with per-face normals or UV
  // seams stores them: the import must weld them back.
  bool splitCorners = false;
};

// The file Assimp's exporter `formatId` writes ("glb2", "gltf2", "ply", "plyb", "stl", "stlb",
// "fbx", "fbxa", "collada", "3ds"). "gltf2" comes back as one self-contained .gltf (its buffer
// as a data: URI). Throws std::runtime_error when Assimp cannot export.
std::string exportWithAssimp(const std::vector<SceneMesh>& meshes, const std::string& formatId);

// A .gltf of `mesh`'s triangles without indices (three vertices of its own per triangle, as a
// flat-shaded or UV-seamed export has), its buffer a data: URI. Every face must be a triangle.
std::string nonIndexedGltf(const render::mesh::ControlMesh& mesh);

// OFF text of `mesh`.
std::string writeOff(const render::mesh::ControlMesh& mesh);

}  // namespace limn::testing
