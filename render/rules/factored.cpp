// Catmull-Clark in Warren & Schaefer's factored form ("A factored approach to subdivision
// surfaces", 2004): linear subdivision, then one round of averaging, then a correction.
//   1. Linear stage: every vertex stays, every edge gets its midpoint, every face its
//      centroid; each n-gon is split into n quads (the child topology of splitToQuads, whose
//      edges were found once each through the base level's hash map).
//   2. Averaging: every new vertex becomes the mean of the centroids of the quads around it.
//   3. Correction: at a vertex of valence n, p^ + (4/n)(p - p^), p^ its linear-stage position
//      and p its average. (Valence 4, which every face and edge point of a quad mesh has,
//      leaves the average as it is.)
// On quad meshes this is exactly the mask rule: a vertex's quads contribute
// (n v + 2 sum(edge midpoints) + sum(face points)) / 4n, which the correction turns into
// (n-2)/n v + (sum(neighbours) + sum(face points)) / n^2. Next to a triangle or n-gon an edge
// point's quads see the face's centroid and the midpoints of the face's other edges instead of
// the quad's opposite corner, so the first step differs there (steps after it act on quads).
//
// Sharp features have no averaging over quads: along a boundary or infinitely sharp crease
// the linear stage is followed by two averages along the curve, giving midpoints on sharp
// edges and 1/8, 6/8, 1/8 at crease vertices (the cubic B-spline, as the masks); corners stay.
// Semi-sharp features and the smooth-triangle option are refused (checkMethod in refine.cpp).
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"

namespace limn::render::rules {

std::vector<Vec3> factoredPoints(const Topology& t, const Topology& child,
                                 const std::vector<Vec3>& P) {
  const int V = t.vertexCount, F = t.faceCount(), E = t.edgeCount();

  // 1. Linear stage.
  std::vector<Vec3> linear(static_cast<size_t>(V) + F + E);
  for (int v = 0; v < V; ++v) linear[v] = P[v];
  for (int f = 0; f < F; ++f) {
    Vec3 sum{0, 0, 0};
    for (int v : t.faceVerts(f)) sum += P[v];
    linear[V + f] = sum / t.faceSize(f);
  }
  for (int e = 0; e < E; ++e) {
    linear[V + F + e] = 0.5 * (P[t.edgeVertices[e][0]] + P[t.edgeVertices[e][1]]);
  }

  // 2. Averaging: scatter each quad's centroid to its corners.
  std::vector<Vec3> sum(linear.size(), Vec3{0, 0, 0});
  std::vector<int> count(linear.size(), 0);
  for (int q = 0; q < child.faceCount(); ++q) {
    std::span<const int> qv = child.faceVerts(q);
    const Vec3 centroid = 0.25 * (linear[qv[0]] + linear[qv[1]] + linear[qv[2]] + linear[qv[3]]);
    for (int x : qv) {
      sum[x] += centroid;
      ++count[x];
    }
  }

  // 3. Correction, and the curve rule at sharp features.
  std::vector<Vec3> out(linear.size());
  for (size_t x = 0; x < linear.size(); ++x) {
    if (count[x] == 0) {
      out[x] = linear[x];  // an isolated vertex
      continue;
    }
    const double n = count[x];
    out[x] = linear[x] + (4.0 / n) * (sum[x] / n - linear[x]);
  }
  for (int e = 0; e < E; ++e) {
    if (isSharp(t.edgeSharpness[e])) out[V + F + e] = linear[V + F + e];
  }
  for (int v = 0; v < V; ++v) {
    switch (currentRule(t, v)) {
      case Rule::Smooth:
      case Rule::Dart:
        break;
      case Rule::Corner:
        out[v] = P[v];
        break;
      case Rule::Crease: {
        // Average the vertex with its two crease midpoints, twice: (m_a + 2 v + m_b) / 4.
        Vec3 curve = 0.5 * P[v];
        for (int e : t.vertexEdgesOf(v)) {
          if (isSharp(t.edgeSharpness[e])) curve += 0.25 * linear[V + F + e];
        }
        out[v] = curve;
        break;
      }
    }
  }
  return out;
}

}  // namespace limn::render::rules
