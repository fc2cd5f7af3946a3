#include "render/rules/limit.h"

#include <cmath>
#include <numbers>

#include "render/core/parallel.h"
#include "render/rules/ring_limit.h"
#include "render/rules/sharpness.h"
#include "render/rules/steps.h"
#include "render/rules/weights.h"

namespace limn::render::rules {

namespace {

constexpr double kPi = std::numbers::pi;

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

}  // namespace

RingLimit::RingLimit(mesh::Scheme scheme) : scheme_(scheme) {}

void RingLimit::evaluate(Rule rule) {
  const int faces = faceCount();
  position = v;
  tangents = {};
  faceNormals.assign(faces, Vec3{0, 0, 0});
  if (faces == 0) return;
  switch (rule) {
    case Rule::Corner:
      cornerSides();
      break;
    case Rule::Crease:
      creaseSides();
      break;
    case Rule::Smooth:
    case Rule::Dart:
      smooth();
      break;
  }
}

// Each face's own corner plane: the corner rule's tangents (and valence-2 Catmull-Clark).
void RingLimit::cornerSides() {
  const int faces = faceCount();
  for (int i = 0; i < faces; ++i) {
    faceNormals[i] = unitCross({edgeEnd(i) - v, edgeEnd(i + 1) - v});
  }
  const double scale = scheme_ == mesh::Scheme::Loop ? 3.0 : 1.0;  // OpenSubdiv's scales
  tangents = {scale * (edgeEnd(0) - v), scale * (edgeEnd(1) - v)};
}

void RingLimit::creaseSides() {
  const int faces = faceCount();
  int sharpAt[2] = {-1, -1};
  for (int i = 0, found = 0; i < static_cast<int>(E.size()) && found < 2; ++i) {
    if (sharp[i]) sharpAt[found++] = i;
  }
  position = (4.0 * v + E[sharpAt[0]] + E[sharpAt[1]]) / 6.0;
  // The sides: from each sharp edge counter-clockwise to the next (a boundary vertex has one).
  const int sides = boundary ? 1 : 2;
  for (int s = 0; s < sides; ++s) {
    const int first = sharpAt[s], last = s == 0 ? sharpAt[1] : sharpAt[0] + faces;
    side_.v = v;
    side_.E.clear();
    side_.F.clear();
    for (int i = first; i <= last; ++i) side_.E.push_back(edgeEnd(i));
    for (int i = first; i < last; ++i) side_.F.push_back(F[i % faces]);
    const Tangents sideTangents = creaseTangents(scheme_, side_);
    const Vec3 normal = unitCross(sideTangents);
    for (int i = first; i < last; ++i) faceNormals[i % faces] = normal;
    // OpenSubdiv's convention: the side counter-clockwise from the first sharp edge.
    if (s == 0) tangents = sideTangents;
  }
}

// Smooth and dart: the interior eigenvectors.
void RingLimit::smooth() {
  const int n = faceCount();
  Vec3 edgeSum{0, 0, 0}, faceSum{0, 0, 0};
  for (int i = 0; i < n; ++i) edgeSum += E[i];
  Tangents t;
  const SmoothWeights& w = weights(n);
  if (scheme_ == mesh::Scheme::Loop) {
    const double chi = n == 6 ? 1.0 / 12.0 : loopLimitWeight(n);
    position = (1.0 - n * chi) * v + chi * edgeSum;
    for (int i = 0; i < n; ++i) {
      t.t1 += w.cosines[i] * E[i];
      t.t2 += w.sines[i] * E[i];
    }
  } else {
    if (n == 2) return cornerSides();  // OpenSubdiv's choice at an interior valence 2
    for (int i = 0; i < n; ++i) faceSum += F[i];
    position = catmullClarkLimitVertexWeight(n) * v + catmullClarkLimitEdgeWeight(n) * edgeSum +
               catmullClarkLimitFaceWeight(n) * faceSum;
    // Edge weights 4 cos(i theta), face weights (cos(i theta) + cos((i+1) theta)) /
    // (4 lambda - 1), lambda the subdominant eigenvalue; the second tangent is the first
    // rotated by one edge.
    const std::vector<double>& c = w.cosines;
    for (int i = 0; i < n; ++i) {
      const int prev = (i + n - 1) % n, next = (i + 1) % n;
      t.t1 += 4.0 * c[i] * E[i] + w.faceScale * (c[i] + c[next]) * F[i];
      t.t2 += 4.0 * c[prev] * E[i] + w.faceScale * (c[prev] + c[i]) * F[i];
    }
  }
  tangents = t;
  faceNormals.assign(n, unitCross(t));
}

SmoothWeights smoothWeightsOf(int n) {
  SmoothWeights w;
  const double theta = 2.0 * kPi / n;
  for (int i = 0; i < n; ++i) {
    w.cosines.push_back(std::cos(i * theta));
    w.sines.push_back(std::sin(i * theta));
  }
  const double lambda =
      5.0 / 16.0 +
      (std::cos(theta) + std::cos(theta / 2) * std::sqrt(2.0 * (9.0 + std::cos(theta)))) / 16.0;
  w.faceScale = 1.0 / (4.0 * lambda - 1.0);
  return w;
}

const SmoothWeights& RingLimit::weights(int n) {
  if (static_cast<int>(weights_.size()) <= n) weights_.resize(n + 1);
  if (weights_[n].cosines.empty()) weights_[n] = smoothWeightsOf(n);
  return weights_[n];
}

namespace {

// The limit of every vertex of one level, one vertex at a time: its ordered ring read from the
// topology into a RingLimit (scratch buffers and per-valence weights kept between vertices).
class LimitMasks {
 public:
  LimitMasks(const Topology& t, const std::vector<Vec3>& points)
      : t_(t), P_(points), ring_(t.options.scheme) {}

  void evaluate(int v, Limit& out, bool cornerNormals) {
    orderedRing(t_, v, topologyRing_);
    const int faces = static_cast<int>(topologyRing_.faces.size());
    const int edges = static_cast<int>(topologyRing_.edges.size());
    ring_.v = P_[v];
    ring_.boundary = topologyRing_.boundary;
    ring_.E.resize(edges);
    ring_.sharp.resize(edges);
    for (int i = 0; i < edges; ++i) {
      const int e = topologyRing_.edges[i];
      ring_.E[i] = P_[t_.otherVertex(e, v)];
      ring_.sharp[i] = isSharp(t_.edgeSharpness[e]);
    }
    ring_.F.resize(faces);
    if (t_.options.scheme == mesh::Scheme::CatmullClark) {
      for (int i = 0; i < faces; ++i) {
        std::span<const int> fv = t_.faceVerts(topologyRing_.faces[i]);
        ring_.F[i] = P_[fv[(topologyRing_.corners[i] + 2) % fv.size()]];
      }
    }
    ring_.evaluate(currentRule(t_, v));
    out.positions[v] = ring_.position;
    out.tangent1[v] = ring_.tangents.t1;
    out.tangent2[v] = ring_.tangents.t2;
    out.normals[v] = unitCross(ring_.tangents);
    if (!cornerNormals) return;
    for (int i = 0; i < faces; ++i) {
      out.cornerNormals[t_.faceOffsets[topologyRing_.faces[i]] + topologyRing_.corners[i]] =
          ring_.faceNormals[i];
    }
  }

 private:
  const Topology& t_;
  const std::vector<Vec3>& P_;
  VertexRing topologyRing_;
  RingLimit ring_;
};

bool hasNonQuad(const Topology& t) {
  for (int f = 0; f < t.faceCount(); ++f) {
    if (t.faceSize(f) != 4) return true;
  }
  return false;
}

}  // namespace

Limit limitOf(const Level& level, bool cornerNormals) {
  const Topology& t = level.topology;
  if (t.options.scheme == mesh::Scheme::CatmullClark && hasNonQuad(t)) {
    // The masks of a Catmull-Clark vertex read the diagonal corners of quads: go one level
    // down, where the vertex's child (same index) has the same limit.
    Level child = refine(level, Method::Masks);
    Limit fine = limitOf(child, cornerNormals);
    Limit out;
    out.positions.assign(fine.positions.begin(), fine.positions.begin() + t.vertexCount);
    out.tangent1.assign(fine.tangent1.begin(), fine.tangent1.begin() + t.vertexCount);
    out.tangent2.assign(fine.tangent2.begin(), fine.tangent2.begin() + t.vertexCount);
    out.normals.assign(fine.normals.begin(), fine.normals.begin() + t.vertexCount);
    if (!cornerNormals) return out;
    out.cornerNormals.resize(t.faceVertices.size());
    for (int f = 0; f < t.faceCount(); ++f) {
      for (int k = 0; k < t.faceSize(f); ++k) {
        const int q = t.faceOffsets[f] + k;  // the child quad at corner k
        const int v = t.faceVerts(f)[k];
        out.cornerNormals[q] =
            fine.cornerNormals[child.topology.faceOffsets[q] + child.topology.cornerOf(q, v)];
      }
    }
    return out;
  }

  Limit out;
  out.positions.resize(t.vertexCount);
  out.tangent1.resize(t.vertexCount);
  out.tangent2.resize(t.vertexCount);
  out.normals.resize(t.vertexCount);
  if (cornerNormals) out.cornerNormals.assign(t.faceVertices.size(), Vec3{0, 0, 0});
  // Each vertex writes its own entries (and its own corners): the chunks run in parallel.
  parallelFor(t.vertexCount, 8192, [&](size_t begin, size_t end) {
    LimitMasks masks(t, level.points);
    for (size_t v = begin; v < end; ++v) masks.evaluate(static_cast<int>(v), out, cornerNormals);
  });
  return out;
}

}  // namespace limn::render::rules
