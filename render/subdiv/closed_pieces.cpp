#include "render/subdiv/closed_pieces.h"

#include <cmath>

namespace limn::render::subdiv {

namespace Far = OpenSubdiv::Far;

namespace {

// Connected pieces through shared edges: piece[f] numbers them from 0.
std::vector<int> piecesOf(const Far::TopologyLevel& base, int* count) {
  std::vector<int> piece(base.GetNumFaces(), -1), stack;
  *count = 0;
  for (int start = 0; start < base.GetNumFaces(); ++start) {
    if (piece[start] >= 0) continue;
    piece[start] = *count;
    stack.push_back(start);
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (int e : base.GetFaceEdges(f)) {
        for (int g : base.GetEdgeFaces(e)) {
          if (piece[g] < 0) {
            piece[g] = *count;
            stack.push_back(g);
          }
        }
      }
    }
    ++*count;
  }
  return piece;
}

}  // namespace

std::vector<int8_t> hiddenSideOfFaces(const Far::TopologyLevel& base,
                                      const std::vector<Vec3>& points) {
  int count = 0;
  const std::vector<int> piece = piecesOf(base, &count);
  std::vector<char> open(count, 0);
  std::vector<double> volume(count, 0.0), scale(count, 0.0);
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    if (base.IsEdgeBoundary(e) || base.IsEdgeNonManifold(e)) {
      for (int f : base.GetEdgeFaces(e)) open[piece[f]] = 1;
    }
  }
  for (int f = 0; f < base.GetNumFaces(); ++f) {
    if (base.IsFaceHole(f)) open[piece[f]] = 1;
    // The enclosed volume of the control polygons, fanned from the face's first corner (the
    // limit surface is wound as its cage is).
    Far::ConstIndexArray v = base.GetFaceVertices(f);
    const Vec3& a = points[v[0]];
    for (int k = 1; k + 1 < v.size(); ++k) {
      const double signedVolume = dot(a, cross(points[v[k]], points[v[k + 1]])) / 6;
      volume[piece[f]] += signedVolume;
      scale[piece[f]] += std::abs(signedVolume);
    }
  }
  std::vector<int8_t> side(base.GetNumFaces(), 0);
  for (int f = 0; f < base.GetNumFaces(); ++f) {
    const int p = piece[f];
    // A closed piece that encloses (almost) nothing, a flat double-sided sheet, has no inside.
    if (open[p] || std::abs(volume[p]) <= 1e-9 * scale[p]) continue;
    side[f] = volume[p] > 0 ? 1 : -1;
  }
  return side;
}

}  // namespace limn::render::subdiv
