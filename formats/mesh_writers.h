// The approximation's mesh as a file for clients that draw it themselves (POST /v1/tessellate):
// binary glTF 2.0 (GLB), binary PLY or OBJ, each with per-vertex positions and normals and
// counter-clockwise triangles. Which one an Accept header asks for is api/accept.h's
// business; the writers know nothing of HTTP.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "render/tessellate/triangle_mesh.h"

namespace limn::formats {

// GLB with one mesh of one triangle primitive (POSITION, NORMAL when the mesh has normals,
// 32-bit indices); `extrasJson` (a JSON object, or "") goes into asset.extras.
std::string writeGlb(const render::tessellate::TriangleMesh& mesh, const std::string& extrasJson);
// binary_little_endian PLY: float x y z nx ny nz per vertex, uchar-counted uint faces;
// `comments` become comment lines of the header.
std::string writePly(const render::tessellate::TriangleMesh& mesh,
                     const std::vector<std::string>& comments);
// v / vn lines and "f a//a b//b c//c" (1-based); `comments` become # lines.
std::string writeObjMesh(const render::tessellate::TriangleMesh& mesh,
                         const std::vector<std::string>& comments);

}  // namespace limn::formats
