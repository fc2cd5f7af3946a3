#include "tests/support/shapes.h"

#include <algorithm>
#include <sstream>

#include "render/subdiv/limit_surface.h"
#include "tests/support/corpus.h"
#include "tests/unit/test_meshes.h"

namespace limn::testing {

using render::mesh::kInfiniteSharpness;

std::vector<NamedMesh> ownShapes() {
  return {
      {"own_cube", cube()},
      {"own_icosahedron_loop", icosahedron()},
      {"own_torus_12x8_creased", torus(12, 8, true)},
      {"own_torus_40x25", torus(40, 25, false)},
      {"own_sharp_cube", sharpCube()},
      {"own_cube_sharp_corners", cubeWithSharpCorners()},
      {"own_semisharp_cube", semiSharpCube(false)},
      {"own_chaikin_cube", semiSharpCube(true)},
      {"own_sharp_tetrahedron_loop", sharpTetrahedron()},
      {"own_pawn_588", pawn()},
      {"own_wavy_torus_1152", wavyTorus()},
      {"own_bumpy_ball_1536", bumpyBall()},
      {"own_tri_sphere_1280", icosphere(3)},
      {"own_icosphere_loop_1280", icosphere(3, Scheme::Loop)},
  };
}

std::vector<NamedMesh> corpusShapes() {
  std::vector<NamedMesh> shapes;
  for (const auto& path : corpusFiles()) {
    std::string name = path.stem().string();
    if (name.rfind("bilinear_", 0) == 0) continue;
    try {
      if (auto mesh = readCorpusMesh(path)) shapes.push_back({name, std::move(*mesh)});
    } catch (const std::exception&) {
      // Shapes the reader refuses are the hostile-input tests' business.
    }
  }
  return shapes;
}

std::vector<NamedMesh> selectShapes(std::vector<NamedMesh> shapes,
                                    const std::vector<std::string>& only) {
  if (only.empty()) return shapes;
  std::erase_if(shapes, [&](const NamedMesh& s) {
    return std::find(only.begin(), only.end(), s.name) == only.end();
  });
  return shapes;
}

std::string controlMeshObj(const render::mesh::ControlMesh& mesh) {
  using render::mesh::BoundaryInterpolation;
  std::ostringstream out;
  out.precision(17);
  for (const auto& p : mesh.points) out << "v " << p.x << " " << p.y << " " << p.z << "\n";
  size_t offset = 0;
  for (int count : mesh.faceVertexCounts) {
    out << "f";
    for (int k = 0; k < count; ++k) out << " " << mesh.faceVertexIndices[offset + k] + 1;
    out << "\n";
    offset += count;
  }
  for (const auto& c : mesh.creases) {
    out << "t crease 2/1/0 " << c.v0 << " " << c.v1 << " " << c.sharpness << "\n";
  }
  for (const auto& c : mesh.corners)
    out << "t corner 1/1/0 " << c.vertex << " " << c.sharpness << "\n";
  for (int h : mesh.holes) out << "t hole 1/0/0 " << h << "\n";
  if (mesh.boundary != BoundaryInterpolation::EdgeOnly) {
    out << "t interpolateboundary 1/0/0 " << (mesh.boundary == BoundaryInterpolation::None ? 0 : 1)
        << "\n";
  }
  if (mesh.creaseMethod == render::mesh::CreaseMethod::Chaikin) {
    out << "t creasemethod 0/0/1 chaikin\n";
  }
  if (mesh.triangleSubdivision == render::mesh::TriangleSubdivision::Smooth) {
    out << "t smoothtriangles 0/0/1 smooth\n";
  }
  return out.str();
}

std::string requestMeshJson(const render::mesh::ControlMesh& mesh) {
  std::string data;
  for (char c : controlMeshObj(mesh)) {
    if (c == '\n') {
      data += "\\n";
    } else {
      if (c == '"' || c == '\\') data += '\\';
      data += c;
    }
  }
  return std::string(R"({"format": "obj", "scheme": ")") + render::mesh::schemeName(mesh.scheme) +
         R"(", "data": ")" + data + "\"}";
}

std::string shapeClass(const render::mesh::ControlMesh& mesh) {
  render::subdiv::LimitSurface surface(mesh);
  const auto& base = surface.baseLevel();
  bool open = !mesh.holes.empty();
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    open = open || base.IsEdgeBoundary(e) || base.IsEdgeNonManifold(e);
  }
  if (open) return "open";
  float sharpest = 0;
  for (const auto& c : mesh.creases) sharpest = std::max(sharpest, c.sharpness);
  for (const auto& c : mesh.corners) sharpest = std::max(sharpest, c.sharpness);
  if (sharpest >= kInfiniteSharpness) return "closed sharp";
  return sharpest > 0 ? "closed semi-sharp" : "closed smooth";
}

}  // namespace limn::testing
