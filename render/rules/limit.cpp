#include "render/rules/limit.h"

#include <cmath>
#include <numbers>

#include "render/rules/sharpness.h"
#include "render/rules/steps.h"
#include "render/rules/weights.h"

namespace limn::render::rules {

namespace {

constexpr double kPi = std::numbers::pi;

struct Tangents {
  Vec3 t1{0, 0, 0}, t2{0, 0, 0};
};

// One side of a vertex: the ends of its edges E[0..m] and, for Catmull-Clark, the corners
// diagonal to the vertex in its faces F[0..m-1] (face i between edges i and i+1), in
// counter-clockwise order. A whole interior ring has as many edges as faces (E[m] == E[0] is
// not repeated).
struct Side {
  Vec3 v;
  std::vector<Vec3> E, F;
};

Vec3 weighted(const std::vector<Vec3>& points, const std::vector<double>& w) {
  Vec3 sum{0, 0, 0};
  for (size_t i = 0; i < w.size(); ++i) sum += w[i] * points[i];
  return sum;
}

// Interior (smooth or dart) vertex: eigenvector tangents.
Tangents smoothTangents(mesh::Scheme scheme, const Side& s) {
  const int n = static_cast<int>(s.E.size());
  const double theta = 2.0 * kPi / n;
  std::vector<double> c(n), sn(n);
  for (int i = 0; i < n; ++i) {
    c[i] = std::cos(i * theta);
    sn[i] = std::sin(i * theta);
  }
  Tangents t;
  if (scheme == mesh::Scheme::Loop) {
    t.t1 = weighted(s.E, c);
    t.t2 = weighted(s.E, sn);
    return t;
  }
  // Catmull-Clark: edge weights 4 cos(i theta), face weights (cos(i theta) + cos((i+1) theta))
  // / (4 lambda - 1), lambda the subdominant eigenvalue; the second tangent is the first
  // rotated by one edge.
  const double lambda =
      5.0 / 16.0 +
      (std::cos(theta) + std::cos(theta / 2) * std::sqrt(2.0 * (9.0 + std::cos(theta)))) / 16.0;
  const double faceScale = 1.0 / (4.0 * lambda - 1.0);
  for (int i = 0; i < n; ++i) {
    const int prev = (i + n - 1) % n;
    t.t1 += 4.0 * c[i] * s.E[i] + faceScale * (c[i] + c[(i + 1) % n]) * s.F[i];
    t.t2 += 4.0 * c[prev] * s.E[i] + faceScale * (c[prev] + c[i]) * s.F[i];
  }
  return t;
}

// One side of a crease (or the whole of a boundary vertex): E[0] and E[m] are the crease.
Tangents creaseTangents(mesh::Scheme scheme, const Side& s) {
  const int m = static_cast<int>(s.E.size()) - 1;
  const int k = m - 1;  // edges strictly inside the side
  Tangents t;
  if (scheme == mesh::Scheme::Loop) {
    t.t1 = 1.5 * (s.E[0] - s.E[m]);
    if (k == 0) {
      t.t2 = -6.0 * s.v + 3.0 * (s.E[0] + s.E[m]);
    } else if (k == 1) {
      t.t2 = -3.0 * s.v + 3.0 * s.E[1];
    } else if (k == 2) {
      const double r3 = std::sqrt(3.0);
      t.t2 = -r3 * s.v - 0.5 * r3 * (s.E[0] + s.E[m]) + r3 * (s.E[1] + s.E[2]);
    } else {
      const double theta = kPi / (k + 1);
      t.t2 = -3.0 * std::sin(theta) * (s.E[0] + s.E[m]);
      for (int i = 1; i <= k; ++i) {
        t.t2 += -6.0 * (std::cos(theta) - 1.0) * std::sin(i * theta) * s.E[i];
      }
    }
    return t;
  }
  t.t1 = 0.5 * (s.E[0] - s.E[m]);
  if (k == 0) {
    t.t2 = -6.0 * s.v + 3.0 * (s.E[0] + s.E[m]);
  } else if (k == 1) {
    // The regular boundary: the cross derivative of the uniform B-spline.
    t.t2 = (-4.0 * s.v - s.E[0] + 4.0 * s.E[1] - s.E[2] + s.F[0] + s.F[1]) / 6.0;
  } else {
    // Biermann et al.: the boundary eigenvector for k + 1 faces.
    const double kk = k + 1, theta = kPi / kk;
    const double cs = std::cos(theta), sn = std::sin(theta);
    const double d = 1.0 / (kk * (3.0 + cs)), R = (cs + 1.0) / sn;
    t.t2 = 4.0 * R * (cs - 1.0) * d * s.v - R * (1.0 + 2.0 * cs) * d * (s.E[0] + s.E[m]) +
           sn * d * s.F[0];
    for (int i = 1; i < kk; ++i) {
      t.t2 += 4.0 * std::sin(i * theta) * d * s.E[i] +
              (std::sin(i * theta) + std::sin((i + 1) * theta)) * d * s.F[i];
    }
  }
  return t;
}

Vec3 unitCross(const Tangents& t) { return normalize(cross(t.t1, t.t2)); }

struct VertexLimit {
  Vec3 position;
  Tangents tangents;       // the vertex's own: see limit.h
  VertexRing ring;
  std::vector<Vec3> face;  // normal per face of the ring
};

VertexLimit limitAt(const Topology& t, const std::vector<Vec3>& P, int v) {
  const mesh::Scheme scheme = t.options.scheme;
  const Rule rule = currentRule(t, v);
  VertexLimit out;
  out.ring = orderedRing(t, v);
  const VertexRing& ring = out.ring;
  const int faces = static_cast<int>(ring.faces.size());
  const int edges = static_cast<int>(ring.edges.size());
  out.position = P[v];
  out.face.assign(faces, Vec3{0, 0, 0});
  if (faces == 0) return out;

  std::vector<Vec3> E(edges), F(faces);
  for (int i = 0; i < edges; ++i) E[i] = P[t.otherVertex(ring.edges[i], v)];
  if (scheme == mesh::Scheme::CatmullClark) {
    for (int i = 0; i < faces; ++i) {
      std::span<const int> fv = t.faceVerts(ring.faces[i]);
      F[i] = P[fv[(ring.corners[i] + 2) % fv.size()]];
    }
  }
  auto edgeEnd = [&](int i) { return E[i % edges]; };  // E[faces] wraps on interior rings

  // Each face's own corner plane: the corner rule's tangents (and valence-2 Catmull-Clark).
  auto cornerSides = [&] {
    for (int i = 0; i < faces; ++i) {
      out.face[i] = unitCross({edgeEnd(i) - P[v], edgeEnd(i + 1) - P[v]});
    }
    out.tangents = {edgeEnd(0) - P[v], edgeEnd(1) - P[v]};
    if (scheme == mesh::Scheme::Loop) out.tangents = {3.0 * out.tangents.t1, 3.0 * out.tangents.t2};
  };

  if (rule == Rule::Corner) {
    cornerSides();
    return out;
  }
  if (rule == Rule::Crease) {
    std::vector<int> sharp;
    for (int i = 0; i < edges; ++i) {
      if (isSharp(t.edgeSharpness[ring.edges[i]])) sharp.push_back(i);
    }
    const Vec3 a = E[sharp[0]], b = E[sharp[1]];
    out.position = (4.0 * P[v] + a + b) / 6.0;
    // The sides: from each sharp edge counter-clockwise to the next (a boundary vertex has one).
    const int sides = ring.boundary ? 1 : 2;
    for (int side = 0; side < sides; ++side) {
      const int first = sharp[side], last = side == 0 ? sharp[1] : sharp[0] + faces;
      Side s{P[v], {}, {}};
      for (int i = first; i <= last; ++i) s.E.push_back(edgeEnd(i));
      for (int i = first; i < last; ++i) s.F.push_back(F[i % faces]);
      const Tangents tangents = creaseTangents(scheme, s);
      const Vec3 normal = unitCross(tangents);
      for (int i = first; i < last; ++i) out.face[i % faces] = normal;
      // OpenSubdiv's convention: the side counter-clockwise from the first sharp edge.
      if (side == 0) out.tangents = tangents;
    }
    return out;
  }

  // Smooth and dart: the interior eigenvectors.
  const int n = faces;
  if (scheme == mesh::Scheme::Loop) {
    const double w = n == 6 ? 1.0 / 12.0 : loopLimitWeight(n);
    Vec3 ring1{0, 0, 0};
    for (const Vec3& e : E) ring1 += e;
    out.position = (1.0 - n * w) * P[v] + w * ring1;
  } else if (n == 2) {
    cornerSides();  // OpenSubdiv's choice at an interior vertex of valence 2: the vertex itself
    return out;
  } else {
    Vec3 edgeSum{0, 0, 0}, faceSum{0, 0, 0};
    for (const Vec3& e : E) edgeSum += e;
    for (const Vec3& f : F) faceSum += f;
    out.position = catmullClarkLimitVertexWeight(n) * P[v] +
                   catmullClarkLimitEdgeWeight(n) * edgeSum +
                   catmullClarkLimitFaceWeight(n) * faceSum;
  }
  out.tangents = smoothTangents(scheme, {P[v], E, F});
  out.face.assign(faces, unitCross(out.tangents));
  return out;
}

bool hasNonQuad(const Topology& t) {
  for (int f = 0; f < t.faceCount(); ++f) {
    if (t.faceSize(f) != 4) return true;
  }
  return false;
}

}  // namespace

Limit limitOf(const Level& level) {
  const Topology& t = level.topology;
  if (t.options.scheme == mesh::Scheme::CatmullClark && hasNonQuad(t)) {
    // The masks of a Catmull-Clark vertex read the diagonal corners of quads: go one level
    // down, where the vertex's child (same index) has the same limit.
    Level child = refine(level, Method::Masks);
    Limit fine = limitOf(child);
    Limit out;
    out.positions.assign(fine.positions.begin(), fine.positions.begin() + t.vertexCount);
    out.tangent1.assign(fine.tangent1.begin(), fine.tangent1.begin() + t.vertexCount);
    out.tangent2.assign(fine.tangent2.begin(), fine.tangent2.begin() + t.vertexCount);
    out.normals.assign(fine.normals.begin(), fine.normals.begin() + t.vertexCount);
    out.cornerNormals.resize(t.faceVertices.size());
    for (int f = 0; f < t.faceCount(); ++f) {
      for (int k = 0; k < t.faceSize(f); ++k) {
        const int q = t.faceOffsets[f] + k;  // the child quad at corner k
        const int v = t.faceVerts(f)[k];
        out.cornerNormals[q] = fine.cornerNormals[child.topology.faceOffsets[q] +
                                                  child.topology.cornerOf(q, v)];
      }
    }
    return out;
  }

  Limit out;
  out.positions.resize(t.vertexCount);
  out.tangent1.resize(t.vertexCount);
  out.tangent2.resize(t.vertexCount);
  out.normals.resize(t.vertexCount);
  out.cornerNormals.resize(t.faceVertices.size());
  for (int v = 0; v < t.vertexCount; ++v) {
    VertexLimit limit = limitAt(t, level.points, v);
    out.positions[v] = limit.position;
    out.tangent1[v] = limit.tangents.t1;
    out.tangent2[v] = limit.tangents.t2;
    out.normals[v] = unitCross(limit.tangents);
    for (size_t i = 0; i < limit.ring.faces.size(); ++i) {
      out.cornerNormals[t.faceOffsets[limit.ring.faces[i]] + limit.ring.corners[i]] = limit.face[i];
    }
  }
  return out;
}

}  // namespace limn::render::rules
