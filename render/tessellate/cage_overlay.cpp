#include "render/tessellate/cage_overlay.h"

#include <algorithm>
#include <set>
#include <utility>

namespace limn::render::tessellate {

LineOverlay cageOverlay(const mesh::ControlMesh& cage, const std::string& pass) {
  LineOverlay overlay;
  overlay.pass = pass;
  overlay.occluded = true;
  // Every edge once, faces of holes included: their points shape the surface around them.
  std::set<std::pair<int, int>> seen;
  size_t offset = 0;
  for (int n : cage.faceVertexCounts) {
    for (int k = 0; k < n; ++k) {
      int a = cage.faceVertexIndices[offset + k], b = cage.faceVertexIndices[offset + (k + 1) % n];
      if (a == b || !seen.insert({std::min(a, b), std::max(a, b)}).second) continue;
      overlay.points.emplace_back(cage.points[a]);
      overlay.points.emplace_back(cage.points[b]);
      overlay.colors.push_back(kCageColor);
    }
    offset += n;
  }
  return overlay;
}

}  // namespace limn::render::tessellate
