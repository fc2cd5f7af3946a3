// The shapes the silhouette harnesses sweep: the project's own meshes (tests/unit/test_meshes.h:
// smooth, sharp-feature and dense 500-2,000-face models) and every Catmull-Clark and Loop shape
// of the shared corpus, when it is there; and the class each belongs to.
#pragma once

#include <string>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::testing {

struct NamedMesh {
  std::string name;
  render::mesh::ControlMesh mesh;
};

// The project's own meshes, names prefixed "own_".
std::vector<NamedMesh> ownShapes();
// The corpus's Catmull-Clark and Loop shapes (bilinear ones left out), sorted by name; those
// the OBJ reader refuses are left out too.
std::vector<NamedMesh> corpusShapes();
// Keeps the shapes named in `only` (all when it is empty).
std::vector<NamedMesh> selectShapes(std::vector<NamedMesh> shapes,
                                    const std::vector<std::string>& only);

// The mesh as OBJ text with OpenSubdiv's tag lines (creases, corners, holes, boundary and
// crease rules), as a request's {"format": "obj"} mesh takes it: for reproducing a view.
std::string controlMeshObj(const render::mesh::ControlMesh& mesh);
// The mesh as a request's "mesh" object: {"format": "obj", "scheme": ..., "data": "..."}.
std::string requestMeshJson(const render::mesh::ControlMesh& mesh);

// "closed smooth", "closed semi-sharp", "closed sharp" or "open": a closed mesh has no boundary
// or non-manifold edge and no hole; sharp means an infinitely sharp crease or corner.
std::string shapeClass(const render::mesh::ControlMesh& mesh);
inline bool isClosedClass(const std::string& shapeClass) {
  return shapeClass.rfind("closed", 0) == 0;
}

}  // namespace limn::testing
