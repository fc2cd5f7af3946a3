#include "render/rules/halfedge_level.h"

#include <algorithm>

#include "render/core/parallel.h"
#include "render/rules/ring_limit.h"
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"
#include "render/rules/weights.h"

namespace limn::render::rules {

namespace {

// The valence of a regular vertex: 4 quads, 6 triangles.
template <int N>
constexpr int kRegularValence = N == 4 ? 4 : 6;

// What a vertex rule reads from the ring of v: the far ends of its edges (all of them, and the
// sharp ones), their count and the sharp ones' count. `perFace(h)` sees each outgoing halfedge.
struct Star {
  Vec3 ends{0, 0, 0}, sharpEnds{0, 0, 0};
  int valence = 0, sharp = 0;
};

template <int N, typename PerFace>
Star starOf(const HalfedgeLevel<N>& q, int v, PerFace perFace) {
  Star s;
  const int closing = forEachAround(q, v, [&](int h) {
    const Vec3& end = q.points[q.vert[nextHalfedge<N>(h)]];
    s.ends += end;
    ++s.valence;
    perFace(h);
    if (q.edgeSharp[q.edge[h]]) {
      s.sharpEnds += end;
      ++s.sharp;
    }
  });
  // A boundary ring's last edge (sharp: boundary edges are) only counts for the crease rule.
  if (closing >= 0 && q.edgeSharp[q.edge[closing]]) {
    s.sharpEnds += q.points[q.vert[closing]];
    ++s.sharp;
  }
  return s;
}

// The rule of vertex v with `sharpEdges` sharp edges (no sharpness is fractional here, so the
// rule is the same on both levels).
template <int N>
Rule ruleAt(const HalfedgeLevel<N>& q, int v, int sharpEdges) {
  return ruleOf(q.vertexCorner[v] ? kInfinitelySharp : 0.0f, sharpEdges);
}

// The child vertex of vertex v by the masks of catmull_clark.cpp, from one walk around it (a
// regular vertex's reads only its neighbours' points).
Vec3 vertexPoint(const QuadLevel& q, const Vec3* facePoint, int v) {
  const Vec3& p = q.points[v];
  if (q.vertexRegular[v]) {
    Vec3 ring{0, 0, 0};
    forEachAround(q, v, [&](int h) {
      ring += q.points[q.vert[nextHalfedge<4>(h)]] + facePoint[faceOfHalfedge<4>(h)];
    });
    return 0.5 * p + ring / 16.0;
  }
  if (q.vertexStart[v] < 0) return p;
  Vec3 faces{0, 0, 0};
  const Star s = starOf(q, v, [&](int h) { faces += facePoint[faceOfHalfedge<4>(h)]; });
  switch (ruleAt(q, v, s.sharp)) {
    case Rule::Smooth:
    case Rule::Dart: {
      const double n = s.valence;
      return (n - 2.0) / n * p + (s.ends + faces) / (n * n);
    }
    case Rule::Crease:
      return 0.75 * p + 0.125 * s.sharpEnds;
    case Rule::Corner:
      break;
  }
  return p;
}

// The same by the masks of loop.cpp.
Vec3 vertexPoint(const TriangleLevel& q, int v) {
  const Vec3& p = q.points[v];
  if (q.vertexRegular[v]) {
    Vec3 ring{0, 0, 0};
    forEachAround(q, v, [&](int h) { ring += q.points[q.vert[nextHalfedge<3>(h)]]; });
    return 0.625 * p + ring / 16.0;  // beta(6) = 1/16
  }
  if (q.vertexStart[v] < 0) return p;
  const Star s = starOf(q, v, [](int) {});
  switch (ruleAt(q, v, s.sharp)) {
    case Rule::Smooth:
    case Rule::Dart: {
      const double beta = loopBeta(s.valence);
      return (1.0 - s.valence * beta) * p + beta * s.ends;
    }
    case Rule::Crease:
      return 0.75 * p + 0.125 * s.sharpEnds;
    case Rule::Corner:
      break;
  }
  return p;
}

// The limit of a regular vertex, without RingLimit's buffers, and twice the summed vector area
// of its faces (drawnVertices() turns the normal to their side).
struct RegularVertex {
  Vec3 position, normal, facesNormal;
};

// Quads: the bicubic B-spline's masks (RingLimit's at valence 4). E: the far ends of the
// vertex's edges; F: the corners diagonal to it; face i is (v, E[i], F[i], E[i + 1]).
RegularVertex regularVertex(const QuadLevel& q, int v) {
  static const SmoothWeights w = smoothWeightsOf(4);
  const std::vector<double>& c = w.cosines;
  Vec3 E[4], F[4];
  int i = 0;
  forEachAround(q, v, [&](int h) {
    E[i] = q.points[q.vert[nextHalfedge<4>(h)]];
    F[i] = q.points[q.vert[nextHalfedge<4>(nextHalfedge<4>(h))]];
    ++i;
  });
  const Vec3& p = q.points[v];
  RegularVertex out;
  out.position = catmullClarkLimitVertexWeight(4) * p +
                 catmullClarkLimitEdgeWeight(4) * (E[0] + E[1] + E[2] + E[3]) +
                 catmullClarkLimitFaceWeight(4) * (F[0] + F[1] + F[2] + F[3]);
  Tangents t;
  out.facesNormal = Vec3{0, 0, 0};
  for (i = 0; i < 4; ++i) {
    const int prev = (i + 3) & 3, next = (i + 1) & 3;
    t.t1 += 4.0 * c[i] * E[i] + w.faceScale * (c[i] + c[next]) * F[i];
    t.t2 += 4.0 * c[prev] * E[i] + w.faceScale * (c[prev] + c[i]) * F[i];
    out.facesNormal += cross(F[i] - p, E[next] - E[i]);
  }
  out.normal = unitCross(t);
  return out;
}

// Triangles: the quartic box spline's masks (RingLimit's at valence 6).
RegularVertex regularVertex(const TriangleLevel& q, int v) {
  static const SmoothWeights w = smoothWeightsOf(6);
  Vec3 E[6];
  int i = 0;
  forEachAround(q, v, [&](int h) { E[i++] = q.points[q.vert[nextHalfedge<3>(h)]]; });
  const Vec3& p = q.points[v];
  RegularVertex out;
  Vec3 sum{0, 0, 0};
  Tangents t;
  out.facesNormal = Vec3{0, 0, 0};
  for (i = 0; i < 6; ++i) {
    sum += E[i];
    t.t1 += w.cosines[i] * E[i];
    t.t2 += w.sines[i] * E[i];
    out.facesNormal += cross(E[i] - p, E[i == 5 ? 0 : i + 1] - p);
  }
  out.position = 0.5 * p + sum / 12.0;  // 1 - 6 chi and chi = 1/12
  out.normal = unitCross(t);
  return out;
}

// The half of parent edge e that ends at vertex w, numbered after the inner edges.
template <int N>
int halfAt(const HalfedgeLevel<N>& q, int innerEdges, int e, int w) {
  return innerEdges + 2 * e + (q.edgeVertices[e][0] == w ? 0 : 1);
}

// Parent halfedge h's corner child, the child face at vert[h]: one per halfedge for quads;
// 4 f + k for triangles (4 f + 3 is the middle one).
int cornerChild(const QuadLevel&, int h) { return h; }
int cornerChild(const TriangleLevel&, int h) {
  return 4 * faceOfHalfedge<3>(h) + cornerOfHalfedge<3>(h);
}

// The arrays of the child level that are the same for both schemes: the edge halves' ends,
// first faces and sharpness; the tags and ring starts of the parent's vertices' children and of
// the edge points (inner edges and face points are the caller's). A corner child keeps
// its parent's corner numbering (refineQuads, refineTriangles): its corner k is at vert[h] of
// parent halfedge h = N f + k, and its corner k - 1 (mod N) starts the half of edge[prev(h)].
template <int N>
void inheritFromParent(const HalfedgeLevel<N>& p, int innerEdges, int edgePoint0,
                       HalfedgeLevel<N>& c) {
  const int V = p.vertexCount, E = p.edgeCount();
  // Child halfedge at corner k of the child at parent halfedge h: N cornerChild(h) + k.
  const auto childHalfedge = [&](int h, int k) { return N * cornerChild(p, h) + k; };
  c.edgeVertices.resize(innerEdges + 2 * static_cast<size_t>(E));
  c.edgeFirst.resize(c.edgeVertices.size());
  c.edgeSharp.resize(c.edgeVertices.size());
  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (int e = static_cast<int>(begin); e < static_cast<int>(end); ++e) {
      const int first = p.edgeFirst[e];  // runs from vert[first] to vert[next(first)]
      for (int side = 0; side < 2; ++side) {
        const int w = p.edgeVertices[e][side], half = innerEdges + 2 * e + side;
        c.edgeVertices[half] = {edgePoint0 + e, w};
        c.edgeSharp[half] = p.edgeSharp[e];
        // In the child of the first face at w: its corner at w, or the one before it.
        const int k = cornerOfHalfedge<N>(first);
        c.edgeFirst[half] =
            p.vert[first] == w ? childHalfedge(first, k) : childHalfedge(nextHalfedge<N>(first), k);
      }
    }
  });

  c.vertexCorner.resize(c.vertexCount);
  c.vertexRegular.resize(c.vertexCount);
  c.vertexStart.resize(c.vertexCount);
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      c.vertexCorner[v] = p.vertexCorner[v];
      c.vertexRegular[v] = p.vertexRegular[v];
      const int s = p.vertexStart[v];
      c.vertexStart[v] = s < 0 ? -1 : childHalfedge(s, cornerOfHalfedge<N>(s));
    }
  });
  // An edge point: in the first face's child at the end the face's winding runs the edge to;
  // regular where the edge is smooth and between two faces that are not holes.
  std::fill(c.vertexCorner.begin() + V, c.vertexCorner.end(), 0);
  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      const int first = p.edgeFirst[e], other = p.twin[first];
      c.vertexStart[edgePoint0 + e] =
          childHalfedge(nextHalfedge<N>(first), cornerOfHalfedge<N>(first));
      c.vertexRegular[edgePoint0 + e] = other >= 0 && !p.edgeSharp[e] &&
                                        !p.faceHole[faceOfHalfedge<N>(first)] &&
                                        !p.faceHole[faceOfHalfedge<N>(other)];
    }
  });
}

// The point of every parent edge: its midpoint where it is sharp or on a boundary, else
// `smooth(ends, first, other)`, with ends the sum of its two ends and first and other its
// halfedges in its two faces.
template <int N, typename Smooth>
void edgePoints(const HalfedgeLevel<N>& p, Vec3* edgePoint, Smooth smooth) {
  parallelFor(p.edgeCount(), kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      const Vec3 ends = p.points[p.edgeVertices[e][0]] + p.points[p.edgeVertices[e][1]];
      const int first = p.edgeFirst[e], other = p.twin[first];
      edgePoint[e] = p.edgeSharp[e] || other < 0 ? 0.5 * ends : smooth(ends, first, other);
    }
  });
}

}  // namespace

int halfedgeCorners(const Topology& t) {
  int corners = 0;
  if (t.options.scheme == mesh::Scheme::CatmullClark) corners = 4;
  if (t.options.scheme == mesh::Scheme::Loop) corners = 3;
  for (int f = 0; f < t.faceCount() && corners; ++f) {
    if (t.faceSize(f) != corners) corners = 0;
  }
  const auto semiSharp = [](const std::vector<float>& s) {
    return std::any_of(s.begin(), s.end(), isSemiSharp);
  };
  if (semiSharp(t.edgeSharpness) || semiSharp(t.vertexSharpness)) return 0;
  return corners;
}

template <int N>
HalfedgeLevel<N> toHalfedgeLevel(const Level& level) {
  const Topology& t = level.topology;
  HalfedgeLevel<N> q;
  q.vertexCount = t.vertexCount;
  q.vert.assign(t.faceVertices.begin(), t.faceVertices.end());
  q.edge.assign(t.faceEdges.begin(), t.faceEdges.end());
  q.faceHole.assign(t.faceHole.begin(), t.faceHole.end());
  q.edgeVertices.assign(t.edgeVertices.begin(), t.edgeVertices.end());
  q.points.assign(level.points.begin(), level.points.end());
  const auto halfedgeOf = [&](int f, int e) {
    for (int k = 0; k < N; ++k) {
      if (t.faceEdges[N * f + k] == e) return N * f + k;
    }
    return -1;
  };
  q.twin.resize(q.vert.size());
  for (size_t h = 0; h < q.vert.size(); ++h) {
    const int e = q.edge[h];
    q.twin[h] = -1;
    for (int g : t.edgeFacesOf(e)) {
      if (g != faceOfHalfedge<N>(static_cast<int>(h))) q.twin[h] = halfedgeOf(g, e);
    }
  }
  q.edgeFirst.resize(t.edgeCount());
  q.edgeSharp.resize(t.edgeCount());
  for (int e = 0; e < t.edgeCount(); ++e) {
    q.edgeFirst[e] = halfedgeOf(t.edgeFacesOf(e)[0], e);
    q.edgeSharp[e] = isInfinite(t.edgeSharpness[e]);
  }
  q.vertexCorner.resize(t.vertexCount);
  q.vertexRegular.assign(t.vertexCount, 0);
  q.vertexStart.assign(t.vertexCount, -1);
  for (int v = 0; v < t.vertexCount; ++v) {
    q.vertexCorner[v] = isInfinite(t.vertexSharpness[v]);
    std::span<const int> faces = t.vertexFacesOf(v);
    if (faces.empty()) continue;
    const int first = t.ringStart.empty() || t.ringStart[v] < 0 ? faces[0] : t.ringStart[v];
    q.vertexStart[v] = N * first + t.cornerOf(first, v);
    for (int f : faces) {  // a boundary vertex starts at its boundary edge
      const int h = N * f + t.cornerOf(f, v);
      if (q.twin[h] < 0) {
        q.vertexStart[v] = h;
        break;
      }
    }
    const size_t valence = kRegularValence<N>;
    bool regular =
        faces.size() == valence && t.vertexEdgesOf(v).size() == valence && !q.vertexCorner[v];
    for (int e : t.vertexEdgesOf(v)) regular = regular && !q.edgeSharp[e];
    for (int f : faces) regular = regular && !q.faceHole[f];
    q.vertexRegular[v] = regular;
  }
  return q;
}

template QuadLevel toHalfedgeLevel<4>(const Level&);
template TriangleLevel toHalfedgeLevel<3>(const Level&);

// Child face 4 f + i is the parent's corner i (parent halfedge h = 4 f + i) and keeps the
// parent's orientation: its corner i + j (mod 4) holds, for j = 0..3, the child of vertex
// vert[h], the point of edge[h], the face point, the point of edge[prev(h)]. Inner edge h joins
// the face point and the point of edge[h].
QuadLevel refineQuads(const QuadLevel& p) {
  const int V = p.vertexCount, F = p.faceCount(), E = p.edgeCount();
  const int H = 4 * F;  // parent halfedges = child faces = inner child edges
  const int facePoint0 = V, edgePoint0 = V + F;
  QuadLevel c;
  c.vertexCount = V + F + E;
  c.vert.resize(4 * static_cast<size_t>(H));
  c.edge.resize(4 * static_cast<size_t>(H));
  c.twin.resize(4 * static_cast<size_t>(H));
  c.faceHole.resize(H);
  parallelFor(H, kParallelGrain, [&](size_t begin, size_t end) {
    for (int h = static_cast<int>(begin); h < static_cast<int>(end); ++h) {
      const int f = faceOfHalfedge<4>(h), i = h & 3, ph = prevHalfedge<4>(h);
      const int v = p.vert[h];
      const int at[4] = {4 * h + i, 4 * h + ((i + 1) & 3), 4 * h + ((i + 2) & 3),
                         4 * h + ((i + 3) & 3)};
      c.vert[at[0]] = v;
      c.vert[at[1]] = edgePoint0 + p.edge[h];
      c.vert[at[2]] = facePoint0 + f;
      c.vert[at[3]] = edgePoint0 + p.edge[ph];
      c.edge[at[0]] = halfAt(p, H, p.edge[h], v);
      c.edge[at[1]] = h;
      c.edge[at[2]] = ph;
      c.edge[at[3]] = halfAt(p, H, p.edge[ph], v);
      // Along the half of edge[h] at v: the twin is in the child of the twin's face at v.
      const int t = p.twin[h];
      c.twin[at[0]] = t < 0 ? -1 : 4 * nextHalfedge<4>(t) + (t & 3);
      // Inner edges: between this child and the next (previous) one of the same face.
      c.twin[at[1]] = 4 * nextHalfedge<4>(h) + ((i + 3) & 3);
      c.twin[at[2]] = 4 * ph + i;
      // Along the half of edge[prev(h)] at v.
      const int tp = p.twin[ph];
      c.twin[at[3]] = tp < 0 ? -1 : 4 * tp + (tp & 3);
      c.faceHole[h] = p.faceHole[f];
    }
  });

  inheritFromParent(p, H, edgePoint0, c);
  parallelFor(H, kParallelGrain, [&](size_t begin, size_t end) {
    for (int h = static_cast<int>(begin); h < static_cast<int>(end); ++h) {
      c.edgeVertices[h] = {facePoint0 + faceOfHalfedge<4>(h), edgePoint0 + p.edge[h]};
      c.edgeFirst[h] = 4 * h + ((h + 1) & 3);  // in child face h, from the edge point inwards
      c.edgeSharp[h] = 0;
    }
  });
  // A face point is regular where its face is not a hole.
  parallelFor(F, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      c.vertexStart[facePoint0 + f] = 4 * (4 * f) + 2;
      c.vertexRegular[facePoint0 + f] = !p.faceHole[f];
    }
  });

  // Points: face points, then edge points (from face points), then vertex points.
  c.points.resize(c.vertexCount);
  Vec3* facePoint = c.points.data() + facePoint0;
  Vec3* edgePoint = c.points.data() + edgePoint0;
  parallelFor(F, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      const int* fv = p.vert.data() + 4 * f;
      facePoint[f] = 0.25 * (p.points[fv[0]] + p.points[fv[1]] + p.points[fv[2]] + p.points[fv[3]]);
    }
  });
  edgePoints(p, edgePoint, [&](const Vec3& ends, int first, int other) {
    return 0.25 * ends +
           0.25 * (facePoint[faceOfHalfedge<4>(first)] + facePoint[faceOfHalfedge<4>(other)]);
  });
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) c.points[v] = vertexPoint(p, facePoint, v);
  });
  return c;
}

// Child face 4 f + i (i < 3) is the parent's corner i (parent halfedge h = 3 f + i): its corner
// i + j (mod 3) holds, for j = 0..2, the child of vertex vert[h], the point of edge[h], the point
// of edge[prev(h)]. Child face 4 f + 3, the middle one, holds at its corner i + 1 (mod 3) the
// point of edge[prev(h)], its edge there being inner edge h, which joins the points of edge[h]
// and edge[prev(h)].
TriangleLevel refineTriangles(const TriangleLevel& p) {
  const int V = p.vertexCount, F = p.faceCount(), E = p.edgeCount();
  const int H = 3 * F;  // parent halfedges = inner child edges
  const int edgePoint0 = V;
  TriangleLevel c;
  c.vertexCount = V + E;
  c.vert.resize(12 * static_cast<size_t>(F));
  c.edge.resize(12 * static_cast<size_t>(F));
  c.twin.resize(12 * static_cast<size_t>(F));
  c.faceHole.resize(4 * static_cast<size_t>(F));
  const auto childHalfedge = [&](int h, int k) { return 3 * cornerChild(p, h) + k; };
  parallelFor(F, kParallelGrain, [&](size_t begin, size_t end) {
    for (int f = static_cast<int>(begin); f < static_cast<int>(end); ++f) {
      const int middle = 3 * (4 * f + 3);
      for (int i = 0; i < 3; ++i) {
        const int h = 3 * f + i, ph = prevHalfedge<3>(h), v = p.vert[h];
        const int at[3] = {childHalfedge(h, i), childHalfedge(h, (i + 1) % 3),
                           childHalfedge(h, (i + 2) % 3)};
        const int inner = middle + (i + 1) % 3;  // inner edge h in the middle child
        c.vert[at[0]] = v;
        c.vert[at[1]] = edgePoint0 + p.edge[h];
        c.vert[at[2]] = edgePoint0 + p.edge[ph];
        c.vert[inner] = edgePoint0 + p.edge[ph];
        c.edge[at[0]] = halfAt(p, H, p.edge[h], v);
        c.edge[at[1]] = h;
        c.edge[at[2]] = halfAt(p, H, p.edge[ph], v);
        c.edge[inner] = h;
        // Along the half of edge[h] at v: in the child of the twin's face at v (the twin ends
        // there), at that child's last corner.
        const int t = p.twin[h];
        c.twin[at[0]] = t < 0 ? -1 : childHalfedge(nextHalfedge<3>(t), cornerOfHalfedge<3>(t));
        c.twin[at[1]] = inner;
        c.twin[inner] = at[1];
        // Along the half of edge[prev(h)] at v: the twin starts at v, at its child's first corner.
        const int tp = p.twin[ph];
        c.twin[at[2]] = tp < 0 ? -1 : childHalfedge(tp, cornerOfHalfedge<3>(tp));
        c.faceHole[4 * f + i] = p.faceHole[f];
      }
      c.faceHole[4 * f + 3] = p.faceHole[f];
    }
  });

  inheritFromParent(p, H, edgePoint0, c);
  parallelFor(H, kParallelGrain, [&](size_t begin, size_t end) {
    for (int h = static_cast<int>(begin); h < static_cast<int>(end); ++h) {
      c.edgeVertices[h] = {edgePoint0 + p.edge[h], edgePoint0 + p.edge[prevHalfedge<3>(h)]};
      c.edgeFirst[h] = childHalfedge(h, (cornerOfHalfedge<3>(h) + 1) % 3);  // the corner child
      c.edgeSharp[h] = 0;
    }
  });

  // Points: edge points, then vertex points (Loop's read only the parent's points).
  c.points.resize(c.vertexCount);
  Vec3* edgePoint = c.points.data() + edgePoint0;
  edgePoints(p, edgePoint, [&](const Vec3& ends, int first, int other) {
    // 3/8 of each end, 1/8 of the corner opposite the edge in each triangle.
    return 0.375 * ends + 0.125 * (p.points[p.vert[prevHalfedge<3>(first)]] +
                                   p.points[p.vert[prevHalfedge<3>(other)]]);
  });
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) c.points[v] = vertexPoint(p, v);
  });
  return c;
}

namespace {

// The limit of any vertex through RingLimit, with its ring read from the halfedges.
template <int N>
class HalfedgeRingLimit {
 public:
  void evaluate(const HalfedgeLevel<N>& q, int v, Vec3& position, Vec3& normal) {
    ring_.v = q.points[v];
    ring_.E.clear();
    ring_.F.clear();
    ring_.sharp.clear();
    ring_.boundary = false;
    if (q.vertexStart[v] >= 0) {
      const int closing = forEachAround(q, v, [&](int h) {
        const int next = nextHalfedge<N>(h);
        ring_.E.push_back(q.points[q.vert[next]]);
        // Catmull-Clark's masks read the corner diagonal to v; Loop's none (RingLimit counts
        // the faces by F all the same).
        ring_.F.push_back(q.points[q.vert[N == 4 ? nextHalfedge<N>(next) : next]]);
        ring_.sharp.push_back(q.edgeSharp[q.edge[h]]);
      });
      ring_.boundary = closing >= 0;
      if (ring_.boundary) {
        ring_.E.push_back(q.points[q.vert[closing]]);
        ring_.sharp.push_back(q.edgeSharp[q.edge[closing]]);
      }
    }
    const int sharp = static_cast<int>(std::count(ring_.sharp.begin(), ring_.sharp.end(), 1));
    ring_.evaluate(ruleAt(q, v, sharp));
    position = ring_.position;
    normal = unitCross(ring_.tangents);
  }

 private:
  RingLimit ring_{N == 4 ? mesh::Scheme::CatmullClark : mesh::Scheme::Loop};
};

// The summed normals of the faces around v that are not holes (each face fanned from its first
// corner, as the mesh draws it).
template <int N>
Vec3 facesNormalAt(const HalfedgeLevel<N>& q, int v) {
  Vec3 sum{0, 0, 0};
  if (q.vertexStart[v] < 0) return sum;
  forEachAround(q, v, [&](int h) {
    const int f = faceOfHalfedge<N>(h);
    if (q.faceHole[f]) return;
    const int* c = q.vert.data() + N * f;
    const Vec3& a = q.points[c[0]];
    for (int k = 1; k + 1 < N; ++k) sum += cross(q.points[c[k]] - a, q.points[c[k + 1]] - a);
  });
  return sum;
}

}  // namespace

template <int N>
HalfedgeLimit limitOfHalfedges(const HalfedgeLevel<N>& q) {
  HalfedgeLimit out;
  out.positions.resize(q.vertexCount);
  out.normals.resize(q.vertexCount);
  parallelFor(q.vertexCount, kParallelGrain, [&](size_t begin, size_t end) {
    HalfedgeRingLimit<N> ring;
    for (size_t v = begin; v < end; ++v) {
      if (q.vertexRegular[v]) {
        const RegularVertex r = regularVertex(q, static_cast<int>(v));
        out.positions[v] = r.position;
        out.normals[v] = r.normal;
      } else {
        ring.evaluate(q, static_cast<int>(v), out.positions[v], out.normals[v]);
      }
    }
  });
  return out;
}

template HalfedgeLimit limitOfHalfedges(const QuadLevel&);
template HalfedgeLimit limitOfHalfedges(const TriangleLevel&);

template <int N>
void drawnVertices(const HalfedgeLevel<N>& q, bool pushToLimit, Vec3f* positions,
                   Vec3f* limitPositions, Vec3f* normals) {
  const auto write = [&](int v, const Vec3& limit, const Vec3& normal) {
    positions[v] = Vec3f(pushToLimit ? limit : q.points[v]);
    limitPositions[v] = Vec3f(limit);
    normals[v] = Vec3f(normal);
  };
  // Vertices in the order of the halfedges their rings start at, not of their indices: the
  // faces around consecutive vertices then lie next to each other in memory (the vertex order
  // scatters a ring's points over the whole array; this pass is bound by those reads).
  parallelFor(q.vert.size(), kParallelGrain, [&](size_t begin, size_t end) {
    HalfedgeRingLimit<N> ring;
    for (size_t h = begin; h < end; ++h) {
      const int v = q.vert[h];
      if (q.vertexStart[v] != static_cast<int>(h)) continue;
      Vec3 limit, normal, around;
      if (q.vertexRegular[v]) {
        const RegularVertex r = regularVertex(q, v);
        limit = r.position;
        normal = r.normal;
        around = r.facesNormal;
      } else {
        ring.evaluate(q, v, limit, normal);
        around = facesNormalAt(q, v);
      }
      if (length(normal) == 0) normal = normalize(around);
      if (dot(normal, around) < 0) normal = -normal;
      write(v, limit, normal);
    }
  });
  // Vertices in no face: where they are, without a normal.
  parallelFor(q.vertexCount, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      if (q.vertexStart[v] < 0) write(static_cast<int>(v), q.points[v], Vec3{0, 0, 0});
    }
  });
}

template void drawnVertices(const QuadLevel&, bool, Vec3f*, Vec3f*, Vec3f*);
template void drawnVertices(const TriangleLevel&, bool, Vec3f*, Vec3f*, Vec3f*);

namespace {

// The remaining steps of a refinement on halfedges, from the level the Topology path reached.
template <int N, typename Step>
HalfedgeLevel<N> continueOnHalfedges(const Level& level, int steps, Step step) {
  HalfedgeLevel<N> q = toHalfedgeLevel<N>(level);
  for (int s = 0; s < steps; ++s) q = step(q);
  return q;
}

}  // namespace

FastRefinement refineUniformFast(const mesh::ControlMesh& mesh, int levels) {
  FastRefinement out;
  out.level = baseLevel(mesh);
  while (out.topologySteps < levels && halfedgeCorners(out.level.topology) == 0) {
    out.level = refine(out.level, Method::Masks);
    ++out.topologySteps;
  }
  const int steps = levels - out.topologySteps;
  if (steps == 0) return out;
  if (halfedgeCorners(out.level.topology) == 4) {
    out.quads = continueOnHalfedges<4>(out.level, steps, refineQuads);
  } else {
    out.triangles = continueOnHalfedges<3>(out.level, steps, refineTriangles);
  }
  out.level = {};
  return out;
}

}  // namespace limn::render::rules
