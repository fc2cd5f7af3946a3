// The control cage as triangles: each polygon fanned from its first vertex, holes left out.
#include <set>
#include <utility>

#include "render/tessellate/tessellate.h"

namespace limn::render::tessellate {

namespace {

// Adds the polygon edges of face `corners` to `lines`, each undirected edge once.
void addPolygonEdges(const std::vector<int>& corners, std::set<std::pair<int, int>>& seen,
                     std::vector<uint32_t>& lines) {
  for (size_t k = 0; k < corners.size(); ++k) {
    int a = corners[k], b = corners[(k + 1) % corners.size()];
    if (seen.insert({std::min(a, b), std::max(a, b)}).second) {
      lines.push_back(static_cast<uint32_t>(a));
      lines.push_back(static_cast<uint32_t>(b));
    }
  }
}

}  // namespace

TriangleMesh tessellateCoarse(const subdiv::LimitSurface& surface) {
  const mesh::ControlMesh& cage = surface.mesh();
  TriangleMesh out;
  for (int v = 0; v < cage.vertexCount(); ++v) {
    out.positions.emplace_back(cage.points[v]);
    out.normals.emplace_back(surface.controlLimitNormals()[v]);
    out.limitPositions.emplace_back(surface.controlLimitPositions()[v]);
  }
  std::vector<bool> hole(cage.faceCount(), false);
  for (int f : cage.holes) hole[f] = true;

  std::set<std::pair<int, int>> seen;
  std::vector<int> corners;
  size_t offset = 0;
  for (int f = 0; f < cage.faceCount(); ++f) {
    int n = cage.faceVertexCounts[f];
    corners.assign(cage.faceVertexIndices.begin() + offset,
                   cage.faceVertexIndices.begin() + offset + n);
    offset += n;
    if (hole[f]) continue;
    for (int k = 1; k + 1 < n; ++k) {
      out.indices.insert(out.indices.end(),
                         {static_cast<uint32_t>(corners[0]), static_cast<uint32_t>(corners[k]),
                          static_cast<uint32_t>(corners[k + 1])});
    }
    addPolygonEdges(corners, seen, out.lines);
  }
  return out;
}

}  // namespace limn::render::tessellate
