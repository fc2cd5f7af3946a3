#include "render/rules/topology.h"

#include <string>
#include <unordered_map>

#include "render/core/error.h"
#include "render/rules/sharpness.h"

namespace limn::render::rules {

namespace {

uint64_t edgeKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

[[noreturn]] void notManifold(const std::string& subject, const std::string& what) {
  throw InputError(InputError::Kind::InvalidMesh, subject,
                   "limn's own subdivision rules take manifold, consistently oriented meshes "
                   "only: " +
                       what);
}

std::string edgeName(const Topology& t, int e) {
  return "edge " + std::to_string(t.edgeVertices[e][0]) + "-" +
         std::to_string(t.edgeVertices[e][1]);
}

// Offsets + indices of a one-to-many relation given as (key, value) pairs, values in the order
// the pairs come.
void invert(int keyCount, const std::vector<std::pair<int, int>>& pairs, std::vector<int>& offsets,
            std::vector<int>& values) {
  offsets.assign(keyCount + 1, 0);
  for (const auto& [key, value] : pairs) ++offsets[key + 1];
  for (int k = 0; k < keyCount; ++k) offsets[k + 1] += offsets[k];
  values.resize(pairs.size());
  std::vector<int> next(offsets.begin(), offsets.end() - 1);
  for (const auto& [key, value] : pairs) values[next[key]++] = value;
}

void checkManifold(const Topology& t) {
  for (int f = 0; f < t.faceCount(); ++f) {
    std::span<const int> fv = t.faceVerts(f);
    for (size_t i = 0; i < fv.size(); ++i) {
      for (size_t j = i + 1; j < fv.size(); ++j) {
        if (fv[i] == fv[j]) {
          notManifold("face " + std::to_string(f),
                      "face " + std::to_string(f) + " repeats vertex " + std::to_string(fv[i]));
        }
      }
    }
  }
  for (int e = 0; e < t.edgeCount(); ++e) {
    std::span<const int> ef = t.edgeFacesOf(e);
    if (ef.size() > 2) {
      notManifold(edgeName(t, e), edgeName(t, e) + " has " + std::to_string(ef.size()) + " faces");
    }
    if (ef.size() == 2) {
      // Consistent orientation: the two faces run along the edge in opposite directions.
      auto runsForward = [&](int f) {
        int k = t.cornerOf(f, t.edgeVertices[e][0]);
        std::span<const int> fv = t.faceVerts(f);
        return fv[(k + 1) % fv.size()] == t.edgeVertices[e][1];
      };
      if (runsForward(ef[0]) == runsForward(ef[1])) {
        notManifold(edgeName(t, e), "the faces " + std::to_string(ef[0]) + " and " +
                                        std::to_string(ef[1]) + " on " + edgeName(t, e) +
                                        " are oriented inconsistently");
      }
    }
  }
  for (int v = 0; v < t.vertexCount; ++v) {
    if (t.vertexFacesOf(v).empty()) continue;
    VertexRing ring = orderedRing(t, v);
    if (ring.faces.size() != t.vertexFacesOf(v).size()) {
      notManifold("vertex " + std::to_string(v),
                  "the faces around vertex " + std::to_string(v) + " do not form one fan");
    }
  }
}

void assignTags(const mesh::ControlMesh& m, const std::unordered_map<uint64_t, int>& edgeIndex,
                Topology& t) {
  t.edgeSharpness.assign(t.edgeCount(), 0.0f);
  for (const mesh::Crease& c : m.creases) {
    auto it = edgeIndex.find(edgeKey(c.v0, c.v1));
    if (it != edgeIndex.end()) t.edgeSharpness[it->second] = c.sharpness;  // the last one wins
  }
  t.faceHole.assign(t.faceCount(), 0);
  for (int f : m.holes) t.faceHole[f] = 1;
  if (m.boundary == mesh::BoundaryInterpolation::None) {
    // As OpenSubdiv: with no boundary interpolation, the faces around a boundary vertex have
    // no limit surface unless the client made all its boundary edges infinitely sharp. They
    // stay in the mesh as holes: their points still shape their neighbours.
    for (int e = 0; e < t.edgeCount(); ++e) {
      if (!t.isBoundaryEdge(e) || isInfinite(t.edgeSharpness[e])) continue;
      for (int v : t.edgeVertices[e]) {
        for (int f : t.vertexFacesOf(v)) t.faceHole[f] = 1;
      }
    }
  }
  for (int e = 0; e < t.edgeCount(); ++e) {
    if (t.isBoundaryEdge(e)) t.edgeSharpness[e] = kInfinitelySharp;
  }
  t.vertexSharpness.assign(t.vertexCount, 0.0f);
  for (const mesh::Corner& c : m.corners) t.vertexSharpness[c.vertex] = c.sharpness;
  if (m.boundary == mesh::BoundaryInterpolation::EdgeAndCorner) {
    for (int v = 0; v < t.vertexCount; ++v) {
      if (t.vertexFacesOf(v).size() == 1 && t.vertexEdgesOf(v).size() == 2) {
        t.vertexSharpness[v] = kInfinitelySharp;
      }
    }
  }
}

}  // namespace

int Topology::cornerOf(int f, int v) const {
  std::span<const int> fv = faceVerts(f);
  for (size_t k = 0; k < fv.size(); ++k) {
    if (fv[k] == v) return static_cast<int>(k);
  }
  return -1;
}

void Topology::completeAdjacency() {
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(faceEdges.size());
  for (int f = 0; f < faceCount(); ++f) {
    for (int e : faceEdgesOf(f)) pairs.emplace_back(e, f);
  }
  invert(edgeCount(), pairs, edgeFaceOffsets, edgeFaces);

  pairs.clear();
  for (int e = 0; e < edgeCount(); ++e) {
    pairs.emplace_back(edgeVertices[e][0], e);
    pairs.emplace_back(edgeVertices[e][1], e);
  }
  invert(vertexCount, pairs, vertexEdgeOffsets, vertexEdges);

  pairs.clear();
  for (int f = 0; f < faceCount(); ++f) {
    for (int v : faceVerts(f)) pairs.emplace_back(v, f);
  }
  invert(vertexCount, pairs, vertexFaceOffsets, vertexFaces);
}

Topology Topology::fromMesh(const mesh::ControlMesh& m) {
  Topology t;
  t.options = {m.scheme, m.boundary, m.creaseMethod, m.triangleSubdivision};
  t.vertexCount = m.vertexCount();
  t.faceVertices = m.faceVertexIndices;
  t.faceOffsets.resize(m.faceCount() + 1);
  for (int f = 0; f < m.faceCount(); ++f) {
    t.faceOffsets[f + 1] = t.faceOffsets[f] + m.faceVertexCounts[f];
  }

  std::unordered_map<uint64_t, int> edgeIndex;
  edgeIndex.reserve(t.faceVertices.size());
  t.faceEdges.resize(t.faceVertices.size());
  for (int f = 0; f < t.faceCount(); ++f) {
    int n = t.faceSize(f), base = t.faceOffsets[f];
    for (int k = 0; k < n; ++k) {
      int a = t.faceVertices[base + k], b = t.faceVertices[base + (k + 1) % n];
      auto [it, added] = edgeIndex.try_emplace(edgeKey(a, b), t.edgeCount());
      if (added) t.edgeVertices.push_back({a, b});
      t.faceEdges[base + k] = it->second;
    }
  }
  t.completeAdjacency();
  checkManifold(t);
  assignTags(m, edgeIndex, t);
  return t;
}

VertexRing orderedRing(const Topology& t, int v) {
  VertexRing ring;
  orderedRing(t, v, ring);
  return ring;
}

void orderedRing(const Topology& t, int v, VertexRing& ring) {
  ring.faces.clear();
  ring.edges.clear();
  ring.corners.clear();
  ring.boundary = false;
  std::span<const int> faces = t.vertexFacesOf(v);
  if (faces.empty()) return;
  auto leading = [&](int f, int k) { return t.faceEdgesOf(f)[k]; };
  auto trailing = [&](int f, int k) {
    int n = t.faceSize(f);
    return t.faceEdgesOf(f)[(k + n - 1) % n];
  };

  int start = t.ringStart.empty() || t.ringStart[v] < 0 ? faces[0] : t.ringStart[v];
  int startCorner = t.cornerOf(start, v);
  for (int f : faces) {
    int k = t.cornerOf(f, v);
    if (t.isBoundaryEdge(leading(f, k))) {
      start = f;
      startCorner = k;
      ring.boundary = true;
      break;
    }
  }
  ring.edges.push_back(leading(start, startCorner));
  int f = start, k = startCorner;
  for (size_t guard = 0; guard <= faces.size(); ++guard) {
    ring.faces.push_back(f);
    ring.corners.push_back(k);
    int e = trailing(f, k);
    ring.edges.push_back(e);
    std::span<const int> ef = t.edgeFacesOf(e);
    if (ef.size() != 2) break;  // reached the boundary
    int next = ef[0] == f ? ef[1] : ef[0];
    if (next == start) {
      ring.edges.pop_back();  // the interior ring closes on its first edge
      break;
    }
    f = next;
    k = t.cornerOf(f, v);
  }
}

}  // namespace limn::render::rules
