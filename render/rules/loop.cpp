// Loop by masks: the new points of one uniform step of Loop's triangle scheme.
//   edge point    smooth: 3/8 of each end and 1/8 of the vertex opposite the edge in each of
//                 its two triangles; sharp: the midpoint; semi-sharp turning smooth: blended
//                 by its sharpness as in catmull_clark.cpp;
//   vertex point  smooth or dart, valence n: (1 - n beta) of the vertex plus beta of each
//                 neighbour, with Loop's original beta(n) = (5/8 - (3/8 + 1/4 cos(2 pi/n))^2)/n
//                 (beta(3) = 3/16, beta(6) = 1/16; OpenSubdiv uses this one, not Warren's
//                 simplification); crease: 3/4 and 1/8, 1/8; corner: fixed.
#include "render/core/parallel.h"
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"
#include "render/rules/weights.h"

namespace limn::render::rules {

namespace {

Vec3 creasePoint(const Topology& t, const std::vector<Vec3>& P, int v, bool child) {
  Vec3 sum = 0.75 * P[v];
  for (int e : t.vertexEdgesOf(v)) {
    if (isSharp(child ? childEdgeSharpness(t, e, v) : t.edgeSharpness[e])) {
      sum += 0.125 * P[t.otherVertex(e, v)];
    }
  }
  return sum;
}

Vec3 maskPoint(Rule rule, const Topology& t, const std::vector<Vec3>& P, int v, const Vec3& smooth,
               bool child) {
  switch (rule) {
    case Rule::Smooth:
    case Rule::Dart:
      return smooth;
    case Rule::Crease:
      return creasePoint(t, P, v, child);
    case Rule::Corner:
      break;
  }
  return P[v];
}

// The corner of triangle f that is not on edge e.
int opposite(const Topology& t, int f, int e) {
  std::span<const int> fe = t.faceEdgesOf(f);
  int k = fe[0] == e ? 0 : (fe[1] == e ? 1 : 2);
  return t.faceVerts(f)[(k + 2) % 3];
}

// The edge point of edge e.
Vec3 edgePointOf(const Topology& t, const std::vector<Vec3>& P, int e) {
  const auto [a, b] = t.edgeVertices[e];
  if (edgePointIsMidpoint(t, e)) return 0.5 * (P[a] + P[b]);
  std::span<const int> faces = t.edgeFacesOf(e);
  double vw = 0.375, fw = 0.125;
  blendTowardsMidpoint(t.edgeSharpness[e], vw, fw);
  return vw * (P[a] + P[b]) + fw * (P[opposite(t, faces[0], e)] + P[opposite(t, faces[1], e)]);
}

// The child of vertex v, by its parent and child rules.
Vec3 vertexPointOf(const Topology& t, const std::vector<Vec3>& P, const VertexRules& rules, int v) {
  std::span<const int> faces = t.vertexFacesOf(v);
  if (faces.empty()) return P[v];
  const Rule pr = rules.parent[v], cr = rules.child[v];
  Vec3 smooth{0, 0, 0};
  if (pr == Rule::Smooth || pr == Rule::Dart || cr == Rule::Smooth || cr == Rule::Dart) {
    const int n = static_cast<int>(faces.size());
    const double beta = loopBeta(n);
    Vec3 ring{0, 0, 0};
    for (int e : t.vertexEdgesOf(v)) ring += P[t.otherVertex(e, v)];
    smooth = (1.0 - n * beta) * P[v] + beta * ring;
  }
  const Vec3 parent = maskPoint(pr, t, P, v, smooth, false);
  if (pr == Rule::Smooth || pr == Rule::Dart || pr == cr) return parent;
  const double w = rules.transition[v];
  return w * parent + (1.0 - w) * maskPoint(cr, t, P, v, smooth, true);
}

}  // namespace

std::vector<Vec3> loopPoints(const Topology& t, const std::vector<Vec3>& P) {
  const int V = t.vertexCount, E = t.edgeCount();
  std::vector<Vec3> out(static_cast<size_t>(V) + E);
  Vec3* edgePoint = out.data() + V;

  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) edgePoint[e] = edgePointOf(t, P, e);
  });
  const VertexRules rules = vertexRules(t);
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) out[v] = vertexPointOf(t, P, rules, v);
  });
  return out;
}

}  // namespace limn::render::rules
