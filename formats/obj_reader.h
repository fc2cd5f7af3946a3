// OBJ text -> ControlMesh. Reads the `v` and `f` statements with tinyobjloader and the `t` tag
// lines of OpenSubdiv's regression shapes (crease, corner, hole, interpolateboundary,
// creasemethod, smoothtriangles; 0-based indices), then checks the mesh with validateMesh().
//
// A scan of every line runs first, because tinyobjloader is lenient where a service must not
// be: it reads "nan" or "abc" as 0, drops faces with fewer than 3 vertices, keeps indices
// outside the file, stores face sizes in a byte, and attaches tags only to groups that have
// faces (tags after a trailing `g` are lost). The scan rejects all of these with the line
// number, and the tags come from the scan.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::formats {

struct ObjMesh {
  render::mesh::ControlMesh mesh;
  // Unsupported tags and ignored statements, each naming its line.
  std::vector<std::string> warnings;
  // 1-based line of each vertex, face, crease, corner and hole, for error messages.
  std::vector<int> vertexLines, faceLines, creaseLines, cornerLines, holeLines;
};

// parseObj() then validateObjMesh(): what the request parser uses.
// Throws render::InputError: InvalidMesh (subject "line N", or the element validateMesh names,
// with the OBJ line in the message) or LimitExceeded (maxVertices, maxFaces, maxFaceSize).
// Without an interpolateboundary tag the boundary is edge-only.
ObjMesh readObj(std::string_view text, render::mesh::Scheme scheme,
                const render::mesh::MeshLimits& limits);

// Reading alone: syntax, indices inside the file, tag forms and the size limits are checked;
// the topology checks of validateMesh() (edges of creases, scheme constraints, ...) are not.
ObjMesh parseObj(std::string_view text, render::mesh::Scheme scheme,
                 const render::mesh::MeshLimits& limits);

// validateMesh() with the OBJ line of the vertex, face, crease, corner or hole it names added
// to the message.
void validateObjMesh(const ObjMesh& obj, const render::mesh::MeshLimits& limits);

}  // namespace limn::formats
