// Catmull-Clark by masks: the new points of one uniform step, each a weighted sum over its
// parent neighbourhood.
//   face point    the centroid of the face;
//   edge point    smooth: 1/4 of each end and of each adjacent face point (with "smooth
//                 triangles", a triangle's face point weighs 0.47 instead of 0.25, the ends
//                 what is left); sharp: the midpoint; semi-sharp with sharpness s < 1 (its
//                 children smooth): s * sharp + (1 - s) * smooth;
//   vertex point  smooth or dart, valence n: (n-2)/n of the vertex plus 1/n^2 of each edge
//                 neighbour and of each adjacent face point (Catmull & Clark 1978); crease:
//                 3/4 of the vertex plus 1/8 of its two crease neighbours (the cubic B-spline
//                 along the crease); corner: the vertex itself. Where a semi-sharp feature
//                 turns smooth in this step the parent and child rules are blended by the
//                 transition weight (sharpness.h).
#include "render/core/parallel.h"
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"

namespace limn::render::rules {

namespace {

// Crease mask of a vertex: 3/4 of itself and 1/8 of each end of its sharp edges, where
// `sharp(e)` says which of its edges count as sharp for this rule.
template <typename IsSharp>
Vec3 creasePoint(const Topology& t, const std::vector<Vec3>& P, int v, IsSharp sharp) {
  Vec3 sum = 0.75 * P[v];
  for (int e : t.vertexEdgesOf(v)) {
    if (sharp(e)) sum += 0.125 * P[t.otherVertex(e, v)];
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
      return creasePoint(t, P, v, [&](int e) {
        return isSharp(child ? childEdgeSharpness(t, e, v) : t.edgeSharpness[e]);
      });
    case Rule::Corner:
      break;
  }
  return P[v];
}

// The edge point of edge e, from the parent points and the face points.
Vec3 edgePointOf(const Topology& t, const std::vector<Vec3>& P, const Vec3* facePoint, int e) {
  const auto [a, b] = t.edgeVertices[e];
  // The edge point's own rule one level down: its two halves decide.
  if (edgePointIsMidpoint(t, e)) return 0.5 * (P[a] + P[b]);
  std::span<const int> faces = t.edgeFacesOf(e);
  // Smooth weights: ends vw each, face points fw each.
  double fw = 0.25, vw = 0.25;
  const bool smoothTriangles = t.options.triangleSubdivision == mesh::TriangleSubdivision::Smooth;
  if (smoothTriangles && (t.faceSize(faces[0]) == 3 || t.faceSize(faces[1]) == 3)) {
    const double kTriangle = 0.470;  // OpenSubdiv's (and Hbr's) weight for a triangle
    double f0 = t.faceSize(faces[0]) == 3 ? kTriangle : 0.25;
    double f1 = t.faceSize(faces[1]) == 3 ? kTriangle : 0.25;
    fw = 0.5 * (f0 + f1);
    vw = 0.5 * (1.0 - 2.0 * fw);
  }
  blendTowardsMidpoint(t.edgeSharpness[e], vw, fw);
  return vw * (P[a] + P[b]) + fw * (facePoint[faces[0]] + facePoint[faces[1]]);
}

// The child of vertex v, by its parent and child rules.
Vec3 vertexPointOf(const Topology& t, const std::vector<Vec3>& P, const Vec3* facePoint,
                   const VertexRules& rules, int v) {
  std::span<const int> faces = t.vertexFacesOf(v);
  if (faces.empty()) return P[v];  // an isolated vertex stays where it is
  Vec3 smooth{0, 0, 0};
  const Rule pr = rules.parent[v], cr = rules.child[v];
  if (pr == Rule::Smooth || pr == Rule::Dart || cr == Rule::Smooth || cr == Rule::Dart) {
    const double n = static_cast<double>(faces.size());
    Vec3 ring{0, 0, 0};
    for (int e : t.vertexEdgesOf(v)) ring += P[t.otherVertex(e, v)];
    for (int f : faces) ring += facePoint[f];
    smooth = (n - 2.0) / n * P[v] + ring / (n * n);
  }
  const Vec3 parent = maskPoint(pr, t, P, v, smooth, false);
  if (pr == Rule::Smooth || pr == Rule::Dart || pr == cr) return parent;
  const double w = rules.transition[v];
  return w * parent + (1.0 - w) * maskPoint(cr, t, P, v, smooth, true);
}

}  // namespace

// Each loop writes one point per element and reads only points made before it: its chunks run
// in parallel, and the result does not depend on the number of threads.
std::vector<Vec3> catmullClarkPoints(const Topology& t, const std::vector<Vec3>& P) {
  const int V = t.vertexCount, F = t.faceCount(), E = t.edgeCount();
  std::vector<Vec3> out(static_cast<size_t>(V) + F + E);
  Vec3* facePoint = out.data() + V;
  Vec3* edgePoint = out.data() + V + F;
  parallelFor(F, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      Vec3 sum{0, 0, 0};
      for (int v : t.faceVerts(f)) sum += P[v];
      facePoint[f] = sum / t.faceSize(f);
    }
  });
  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) edgePoint[e] = edgePointOf(t, P, facePoint, e);
  });
  const VertexRules rules = vertexRules(t);
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) out[v] = vertexPointOf(t, P, facePoint, rules, v);
  });
  return out;
}

}  // namespace limn::render::rules
