// Control meshes from the files users already have, read through Assimp: glTF 2.0 (text and
// binary), PLY, STL, FBX, COLLADA, 3DS and OFF. OBJ stays with limn's own reader
// (formats/obj_reader.h), which keeps OpenSubdiv's tag lines.
//
// What a subdivision surface needs from such a file, and what this import does for it:
// - polygons stay polygons (no triangulation): a quad cage refines as Catmull–Clark expects;
// - vertices a format split only for normals, UVs or per-face data (glTF seams, STL's three
//   corners per triangle) are welded back by exact position within each mesh, so the cage is
//   one connected surface rather than one that tears at every seam;
// - node transforms are applied; several meshes are merged (each welded on its own), or one is
//   picked by name;
// - the scheme is the caller's, else Loop when every face is a triangle, else Catmull–Clark.
//
// Hostile files: the file is read from memory only (a glTF naming another file, by path or URI,
// gets nothing), counts a header declares are checked against the file's size and the mesh
// limits before Assimp allocates for them (PLY, OFF, binary STL, glTF accessors and buffers),
// and the scene is checked against the limits before it is copied. Assimp itself is not
// bounded in time: the server runs the import inside a worker process (server/worker_pool.h).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "render/mesh/control_mesh.h"

namespace limn::formats {

enum class ImportFormat { Gltf, Glb, Ply, Stl, Fbx, Dae, ThreeDs, Off };

// "gltf", "glb", "ply", "stl", "fbx", "dae" (or "collada"), "3ds", "off".
std::optional<ImportFormat> importFormatNamed(std::string_view name);
const char* importFormatName(ImportFormat format);
// Every name importFormatNamed() takes, for messages and documentation.
const std::vector<std::string>& importFormatNames();
// model/gltf-binary, model/gltf+json, model/stl (and application/sla), model/ply (and
// application/x-ply), model/vnd.collada+xml, application/x-3ds, application/x-fbx, model/x-off.
// application/octet-stream names no format: the caller gives it then (?format=).
std::optional<ImportFormat> importFormatOfMediaType(std::string_view mediaType);

struct ImportOptions {
  std::optional<render::mesh::Scheme> scheme;  // else Loop for all triangles, else Catmull–Clark
  std::string meshName;                        // empty: every mesh of the file, merged
};

struct ImportedMesh {
  render::mesh::ControlMesh mesh;
  bool schemeChosen = false;  // the scheme came from the faces, not from the caller
  int meshesMerged = 0;       // mesh instances (node, mesh) in the result
  int verticesWelded = 0;     // file vertices that became one with another
  std::vector<std::string> warnings;
};

// Throws render::InputError: InvalidMesh (subject "mesh.data"; the message names the format and
// Assimp's own words) for a file that cannot be read or holds no faces, LimitExceeded
// (maxVertices, maxFaces, maxFaceSize) for one over the limits — before allocating where the
// file declares its counts. The mesh is not yet validated (validateMesh()).
ImportedMesh importMesh(std::string_view bytes, ImportFormat format, const ImportOptions& options,
                        const render::mesh::MeshLimits& limits);

}  // namespace limn::formats
