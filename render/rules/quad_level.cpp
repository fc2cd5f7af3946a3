#include "render/rules/quad_level.h"

#include <algorithm>

#include "render/core/parallel.h"
#include "render/rules/ring_limit.h"
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"
#include "render/rules/weights.h"

namespace limn::render::rules {

namespace {

// The child vertex of vertex v: the masks of catmull_clark.cpp with the rule the same on both
// levels (no sharpness is fractional here), from one walk around the vertex.
Vec3 vertexPoint(const QuadLevel& q, const Vec3* facePoint, int v) {
  const Vec3& p = q.points[v];
  if (q.vertexRegular[v]) {
    Vec3 ring{0, 0, 0};
    forEachAround(q, v, [&](int h) {
      ring += q.points[q.vert[nextHalfedge(h)]] + facePoint[faceOfHalfedge(h)];
    });
    return 0.5 * p + ring / 16.0;
  }
  if (q.vertexStart[v] < 0) return p;
  Vec3 ring{0, 0, 0}, crease{0, 0, 0};
  int valence = 0, sharp = 0;
  const int closing = forEachAround(q, v, [&](int h) {
    const Vec3& end = q.points[q.vert[nextHalfedge(h)]];
    ring += end + facePoint[faceOfHalfedge(h)];
    ++valence;
    if (q.edgeSharp[q.edge[h]]) {
      crease += end;
      ++sharp;
    }
  });
  if (closing >= 0 && q.edgeSharp[q.edge[closing]]) {
    crease += q.points[q.vert[closing]];
    ++sharp;
  }
  switch (ruleOf(q.vertexCorner[v] ? kInfinitelySharp : 0.0f, sharp)) {
    case Rule::Smooth:
    case Rule::Dart: {
      const double n = valence;
      return (n - 2.0) / n * p + ring / (n * n);
    }
    case Rule::Crease:
      return 0.75 * p + 0.125 * crease;
    case Rule::Corner:
      break;
  }
  return p;
}

// The ring of a regular vertex: the far ends of its edges E and the corners diagonal to it F;
// face i is (v, E[i], F[i], E[i + 1]) counter-clockwise.
struct RegularRing {
  Vec3 E[4], F[4];
};

RegularRing regularRing(const QuadLevel& q, int v) {
  RegularRing r;
  int i = 0;
  forEachAround(q, v, [&](int h) {
    r.E[i] = q.points[q.vert[nextHalfedge(h)]];
    r.F[i] = q.points[q.vert[nextHalfedge(nextHalfedge(h))]];
    ++i;
  });
  return r;
}

// The limit of a regular vertex by the bicubic B-spline's masks, as RingLimit computes them for
// valence 4 but without its buffers.
void regularLimit(const Vec3& p, const RegularRing& r, Vec3& position, Vec3& normal) {
  static const SmoothWeights w = smoothWeightsOf(4);
  const std::vector<double>& c = w.cosines;
  position = catmullClarkLimitVertexWeight(4) * p +
             catmullClarkLimitEdgeWeight(4) * (r.E[0] + r.E[1] + r.E[2] + r.E[3]) +
             catmullClarkLimitFaceWeight(4) * (r.F[0] + r.F[1] + r.F[2] + r.F[3]);
  Tangents t;
  for (int i = 0; i < 4; ++i) {
    const int prev = (i + 3) & 3, next = (i + 1) & 3;
    t.t1 += 4.0 * c[i] * r.E[i] + w.faceScale * (c[i] + c[next]) * r.F[i];
    t.t2 += 4.0 * c[prev] * r.E[i] + w.faceScale * (c[prev] + c[i]) * r.F[i];
  }
  normal = unitCross(t);
}

// Twice the summed vector area of a regular vertex's four faces.
Vec3 regularFacesNormal(const Vec3& p, const RegularRing& r) {
  Vec3 sum{0, 0, 0};
  for (int i = 0; i < 4; ++i) sum += cross(r.F[i] - p, r.E[(i + 1) & 3] - r.E[i]);
  return sum;
}

// The half of parent edge e that ends at vertex w, numbered after the inner edges.
int halfAt(const QuadLevel& q, int innerEdges, int e, int w) {
  return innerEdges + 2 * e + (q.edgeVertices[e][0] == w ? 0 : 1);
}

}  // namespace

bool quadReady(const Topology& t) {
  if (t.options.scheme != mesh::Scheme::CatmullClark) return false;
  for (int f = 0; f < t.faceCount(); ++f) {
    if (t.faceSize(f) != 4) return false;
  }
  for (float s : t.edgeSharpness) {
    if (isSemiSharp(s)) return false;
  }
  for (float s : t.vertexSharpness) {
    if (isSemiSharp(s)) return false;
  }
  return true;
}

QuadLevel toQuadLevel(const Level& level) {
  const Topology& t = level.topology;
  QuadLevel q;
  q.vertexCount = t.vertexCount;
  q.vert.assign(t.faceVertices.begin(), t.faceVertices.end());
  q.edge.assign(t.faceEdges.begin(), t.faceEdges.end());
  q.faceHole.assign(t.faceHole.begin(), t.faceHole.end());
  q.edgeVertices.assign(t.edgeVertices.begin(), t.edgeVertices.end());
  q.points.assign(level.points.begin(), level.points.end());
  const auto halfedgeOf = [&](int f, int e) {
    for (int k = 0; k < 4; ++k) {
      if (t.faceEdges[4 * f + k] == e) return 4 * f + k;
    }
    return -1;
  };
  q.twin.resize(q.vert.size());
  for (size_t h = 0; h < q.vert.size(); ++h) {
    const int e = q.edge[h];
    std::span<const int> faces = t.edgeFacesOf(e);
    q.twin[h] = -1;
    for (int g : faces) {
      if (g != faceOfHalfedge(static_cast<int>(h))) q.twin[h] = halfedgeOf(g, e);
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
    q.vertexStart[v] = 4 * first + t.cornerOf(first, v);
    for (int f : faces) {  // a boundary vertex starts at its boundary edge
      const int h = 4 * f + t.cornerOf(f, v);
      if (q.twin[h] < 0) {
        q.vertexStart[v] = h;
        break;
      }
    }
    bool regular = faces.size() == 4 && !q.vertexCorner[v];
    for (int e : t.vertexEdgesOf(v)) regular = regular && !q.edgeSharp[e];
    for (int f : faces) regular = regular && !q.faceHole[f];
    q.vertexRegular[v] = regular && t.vertexEdgesOf(v).size() == 4;
  }
  return q;
}

// Child face 4 f + i is the parent's corner i (parent halfedge h = 4 f + i) and keeps the
// parent's orientation: its corner i + j (mod 4) holds, for j = 0..3, the child of vertex
// vert[h], the point of edge[h], the face point, the point of edge[prevHalfedge(h)].
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
      const int f = faceOfHalfedge(h), i = h & 3, ph = prevHalfedge(h);
      const int v = p.vert[h];
      const int corner[4] = {(i + 0) & 3, (i + 1) & 3, (i + 2) & 3, (i + 3) & 3};
      const int base = 4 * h;  // the child face's first halfedge
      c.vert[base + corner[0]] = v;
      c.vert[base + corner[1]] = edgePoint0 + p.edge[h];
      c.vert[base + corner[2]] = facePoint0 + f;
      c.vert[base + corner[3]] = edgePoint0 + p.edge[ph];
      c.edge[base + corner[0]] = halfAt(p, H, p.edge[h], v);
      c.edge[base + corner[1]] = h;
      c.edge[base + corner[2]] = ph;
      c.edge[base + corner[3]] = halfAt(p, H, p.edge[ph], v);
      // Along the half of edge[h] at v: the twin is in the child of the twin's face at v.
      const int t = p.twin[h];
      c.twin[base + corner[0]] = t < 0 ? -1 : 4 * nextHalfedge(t) + (t & 3);
      // Inner edges: between this child and the next (previous) one of the same face.
      c.twin[base + corner[1]] = 4 * nextHalfedge(h) + ((i + 3) & 3);
      c.twin[base + corner[2]] = 4 * ph + i;
      // Along the half of edge[prevHalfedge(h)] at v.
      const int tp = p.twin[ph];
      c.twin[base + corner[3]] = tp < 0 ? -1 : 4 * tp + (tp & 3);
      c.faceHole[h] = p.faceHole[f];
    }
  });

  c.edgeVertices.resize(H + 2 * static_cast<size_t>(E));
  c.edgeFirst.resize(c.edgeVertices.size());
  c.edgeSharp.assign(c.edgeVertices.size(), 0);
  parallelFor(H, kParallelGrain, [&](size_t begin, size_t end) {
    for (int h = static_cast<int>(begin); h < static_cast<int>(end); ++h) {
      c.edgeVertices[h] = {facePoint0 + faceOfHalfedge(h), edgePoint0 + p.edge[h]};
      c.edgeFirst[h] = 4 * h + ((h + 1) & 3);  // in child face h, from the edge point inwards
    }
  });
  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (int e = static_cast<int>(begin); e < static_cast<int>(end); ++e) {
      const int first = p.edgeFirst[e];  // runs from vert[first] to vert[nextHalfedge(first)]
      for (int side = 0; side < 2; ++side) {
        const int w = p.edgeVertices[e][side], half = H + 2 * e + side;
        c.edgeVertices[half] = {edgePoint0 + e, w};
        c.edgeSharp[half] = p.edgeSharp[e];
        // In the child of the first face at w: its first corner's halfedge, or its last's.
        c.edgeFirst[half] =
            p.vert[first] == w ? 4 * first + (first & 3) : 4 * nextHalfedge(first) + (first & 3);
      }
    }
  });

  // A vertex's child is regular where it is; a face point where its face is not a hole; an edge
  // point where the edge is smooth and between two faces that are not holes.
  c.vertexCorner.assign(c.vertexCount, 0);
  c.vertexRegular.resize(c.vertexCount);
  c.vertexStart.resize(c.vertexCount);
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      c.vertexCorner[v] = p.vertexCorner[v];
      c.vertexRegular[v] = p.vertexRegular[v];
      const int s = p.vertexStart[v];
      c.vertexStart[v] = s < 0 ? -1 : 4 * s + (s & 3);
    }
  });
  parallelFor(F, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      c.vertexStart[facePoint0 + f] = 4 * (4 * f) + 2;
      c.vertexRegular[facePoint0 + f] = !p.faceHole[f];
    }
  });
  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      // In the first face's child at the end the face's winding runs the edge to.
      const int first = p.edgeFirst[e], other = p.twin[first];
      c.vertexStart[edgePoint0 + e] = 4 * nextHalfedge(first) + (first & 3);
      c.vertexRegular[edgePoint0 + e] = other >= 0 && !p.edgeSharp[e] &&
                                        !p.faceHole[faceOfHalfedge(first)] &&
                                        !p.faceHole[faceOfHalfedge(other)];
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
  parallelFor(E, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      const Vec3 ends = p.points[p.edgeVertices[e][0]] + p.points[p.edgeVertices[e][1]];
      const int first = p.edgeFirst[e], other = p.twin[first];
      if (p.edgeSharp[e] || other < 0) {
        edgePoint[e] = 0.5 * ends;
      } else {
        edgePoint[e] = 0.25 * ends +
                       0.25 * (facePoint[faceOfHalfedge(first)] + facePoint[faceOfHalfedge(other)]);
      }
    }
  });
  parallelFor(V, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) c.points[v] = vertexPoint(p, facePoint, v);
  });
  return c;
}

namespace {

// The limit of any vertex through RingLimit, with its ring read from the halfedges.
class QuadRingLimit {
 public:
  void evaluate(const QuadLevel& q, int v, Vec3& position, Vec3& normal) {
    ring_.v = q.points[v];
    ring_.E.clear();
    ring_.F.clear();
    ring_.sharp.clear();
    ring_.boundary = false;
    if (q.vertexStart[v] >= 0) {
      const int closing = forEachAround(q, v, [&](int h) {
        ring_.E.push_back(q.points[q.vert[nextHalfedge(h)]]);
        ring_.F.push_back(q.points[q.vert[nextHalfedge(nextHalfedge(h))]]);
        ring_.sharp.push_back(q.edgeSharp[q.edge[h]]);
      });
      ring_.boundary = closing >= 0;
      if (ring_.boundary) {
        ring_.E.push_back(q.points[q.vert[closing]]);
        ring_.sharp.push_back(q.edgeSharp[q.edge[closing]]);
      }
    }
    const int sharp = static_cast<int>(std::count(ring_.sharp.begin(), ring_.sharp.end(), 1));
    ring_.evaluate(ruleOf(q.vertexCorner[v] ? kInfinitelySharp : 0.0f, sharp));
    position = ring_.position;
    normal = unitCross(ring_.tangents);
  }

 private:
  RingLimit ring_{mesh::Scheme::CatmullClark};
};

// The summed normals of the faces around v that are not holes (each quad as two triangles
// fanned from its first corner, as the mesh draws it).
Vec3 facesNormalAt(const QuadLevel& q, int v) {
  Vec3 sum{0, 0, 0};
  if (q.vertexStart[v] < 0) return sum;
  forEachAround(q, v, [&](int h) {
    const int f = faceOfHalfedge(h);
    if (q.faceHole[f]) return;
    const int* c = q.vert.data() + 4 * f;
    const Vec3 &a = q.points[c[0]], &b = q.points[c[1]], &m = q.points[c[2]], &d = q.points[c[3]];
    sum += cross(b - a, m - a) + cross(m - a, d - a);
  });
  return sum;
}

}  // namespace

QuadLimit limitOfQuads(const QuadLevel& q) {
  QuadLimit out;
  out.positions.resize(q.vertexCount);
  out.normals.resize(q.vertexCount);
  parallelFor(q.vertexCount, kParallelGrain, [&](size_t begin, size_t end) {
    QuadRingLimit ring;
    for (size_t v = begin; v < end; ++v) {
      if (q.vertexRegular[v]) {
        regularLimit(q.points[v], regularRing(q, v), out.positions[v], out.normals[v]);
      } else {
        ring.evaluate(q, static_cast<int>(v), out.positions[v], out.normals[v]);
      }
    }
  });
  return out;
}

void drawnVertices(const QuadLevel& q, bool pushToLimit, Vec3f* positions, Vec3f* limitPositions,
                   Vec3f* normals) {
  const auto write = [&](int v, const Vec3& limit, const Vec3& normal) {
    positions[v] = Vec3f(pushToLimit ? limit : q.points[v]);
    limitPositions[v] = Vec3f(limit);
    normals[v] = Vec3f(normal);
  };
  // Vertices in the order of the halfedges their rings start at, not of their indices: the
  // faces around consecutive vertices then lie next to each other in memory (the vertex order
  // scatters a ring's points over the whole array; this pass is bound by those reads).
  parallelFor(q.vert.size(), kParallelGrain, [&](size_t begin, size_t end) {
    QuadRingLimit ring;
    for (size_t h = begin; h < end; ++h) {
      const int v = q.vert[h];
      if (q.vertexStart[v] != static_cast<int>(h)) continue;
      Vec3 limit, normal, around;
      if (q.vertexRegular[v]) {
        const RegularRing r = regularRing(q, v);
        regularLimit(q.points[v], r, limit, normal);
        around = regularFacesNormal(q.points[v], r);
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

FastRefinement refineUniformFast(const mesh::ControlMesh& mesh, int levels) {
  FastRefinement out;
  out.level = baseLevel(mesh);
  while (out.topologySteps < levels && !quadReady(out.level.topology)) {
    out.level = refine(out.level, Method::Masks);
    ++out.topologySteps;
  }
  if (out.topologySteps == levels) return out;
  out.quads = toQuadLevel(out.level);
  out.level = {};
  for (int l = out.topologySteps; l < levels; ++l) out.quads = refineQuads(*out.quads);
  return out;
}

}  // namespace limn::render::rules
