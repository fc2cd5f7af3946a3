// ObjScan: the checking pass over OBJ text that runs before tinyobjloader. It validates the
// syntax of every line (numbers that are numbers and finite, faces of 3+ valid indices, tag
// lines whose value counts match their size triple, no unknown statements), enforces the mesh
// size limits before anything large is allocated, and collects the `t` tag lines with their
// line numbers. See obj_reader.h for why this pass exists.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::formats {

struct ObjTag {
  int line = 0;
  std::string name;
  std::vector<int> ints;
  std::vector<double> floats;
  std::vector<std::string> strings;
};

struct ObjScan {
  std::vector<int> vertexLines;  // 1-based line of each `v`, in order
  std::vector<int> faceLines;    // 1-based line of each `f`, in order
  std::vector<ObjTag> tags;
  std::vector<std::string> warnings;
};

// Throws render::InputError (InvalidMesh with subject "line N"; LimitExceeded naming
// maxVertices, maxFaces or maxFaceSize).
ObjScan scanObj(std::string_view text, const render::mesh::MeshLimits& limits);

}  // namespace limn::formats
