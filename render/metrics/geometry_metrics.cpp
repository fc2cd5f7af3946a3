// measureGeometry(): how far an approximation's triangles are from the limit surface, in world
// units, at points whose place on the limit surface is known.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "render/metrics/metrics.h"

namespace limn::render::metrics {

namespace {

// Items per task. Partial results are kept per chunk and summed in chunk order, so the numbers
// are the same whatever the number of threads.
constexpr size_t kChunk = 4096;

struct Partial {
  double max = 0, sum = 0;
  size_t count = 0;
  void add(double d) {
    max = std::max(max, d);
    sum += d;
    ++count;
  }
};

// perItem(i, partial, state): `state` is cleared for every chunk (a cache the chunk's items
// share), so what it holds cannot depend on how chunks fall on threads.
template <typename State, typename PerItem>
Partial reduceInChunksWith(size_t items, PerItem&& perItem) {
  const size_t chunks = (items + kChunk - 1) / kChunk;
  std::vector<Partial> partials(chunks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<size_t>& range) {
                      auto state = std::make_unique<State>();
                      for (size_t c = range.begin(); c < range.end(); ++c) {
                        state->clear();
                        Partial& p = partials[c];
                        const size_t end = std::min(items, (c + 1) * kChunk);
                        for (size_t i = c * kChunk; i < end; ++i) perItem(i, p, *state);
                      }
                    });
  Partial total;
  for (const Partial& p : partials) {
    total.max = std::max(total.max, p.max);
    total.sum += p.sum;
    total.count += p.count;
  }
  return total;
}

struct NoState {
  void clear() {}
};

template <typename PerItem>
Partial reduceInChunks(size_t items, PerItem&& perItem) {
  return reduceInChunksWith<NoState>(items, [&](size_t i, Partial& p, NoState&) { perItem(i, p); });
}

// Distances at edge midpoints already measured in this chunk, by edge. A triangle's neighbour
// across an edge of its own face is mostly a few triangles or a row of triangles away (the
// tessellator emits a face row by row), so a small direct-mapped table finds most of them: a
// midpoint of two triangles is then evaluated once instead of twice. A hit must have the same
// face, corners and corner (u, v): then the midpoint 0.5 a + 0.5 b and its (u, v) are the same
// numbers in either triangle (a two-term sum, whichever order), and so is its distance.
class MidpointCache {
 public:
  const double* find(int face, uint32_t a, uint32_t b, Vec2f uvA, Vec2f uvB) const {
    order(a, b, uvA, uvB);
    const Entry& e = entries_[slot(a, b)];
    const bool same = e.a == a && e.b == b && e.face == face && e.uvA.x == uvA.x &&
                      e.uvA.y == uvA.y && e.uvB.x == uvB.x && e.uvB.y == uvB.y;
    return same ? &e.distance : nullptr;
  }
  void clear() { entries_.fill(Entry{}); }
  void put(int face, uint32_t a, uint32_t b, Vec2f uvA, Vec2f uvB, double distance) {
    order(a, b, uvA, uvB);
    entries_[slot(a, b)] = {a, b, face, uvA, uvB, distance};
  }

 private:
  struct Entry {
    uint32_t a = std::numeric_limits<uint32_t>::max(), b = 0;
    int face = -1;
    Vec2f uvA, uvB;
    double distance = 0;
  };
  static constexpr size_t kSlots = 4096;
  static void order(uint32_t& a, uint32_t& b, Vec2f& uvA, Vec2f& uvB) {
    if (a > b) {
      std::swap(a, b);
      std::swap(uvA, uvB);
    }
  }
  static size_t slot(uint32_t a, uint32_t b) {
    return (a * 0x9E3779B1u ^ b * 0x85EBCA77u) % kSlots;
  }
  std::array<Entry, kSlots> entries_;
};

// A triangle is sampled at its three corners and at these barycentric blends of them: the edge
// midpoints and the centroid.
constexpr double kBlendWeights[4][3] = {
    {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};
// The corners of the edge whose midpoint each of the first three blends is.
constexpr int kMidpointEdges[3][2] = {{0, 1}, {1, 2}, {0, 2}};

// Meshes whose vertices approximate the limit surface (coarse, uniform): each vertex against
// its own limit position.
Partial measureVertices(const tessellate::TriangleMesh& mesh) {
  if (mesh.limitPositions.size() != mesh.positions.size()) {
    throw std::invalid_argument("measureGeometry: " + std::to_string(mesh.limitPositions.size()) +
                                " limit positions for " + std::to_string(mesh.positions.size()) +
                                " vertices");
  }
  return reduceInChunks(mesh.positions.size(), [&](size_t v, Partial& p) {
    p.add(length(mesh.positions[v].toDouble() - mesh.limitPositions[v].toDouble()));
  });
}

// Meshes that remember (face, u, v): seven points of every triangle against the limit surface
// at the same barycentric combination of the corners' parameters.
//
// Surface evaluation is nearly all the cost, and a vertex is typically a corner of six
// triangles, so each vertex is evaluated once, at the (face, u, v) of the first corner that
// names it, and that distance is reused by every corner with the same face and (u, v).
// Corners where the vertex has other parameters (across a face boundary) are evaluated on
// their own. Each corner still counts as one sample, as the definition says. Likewise an edge's
// midpoint, shared by the two triangles of a face on either side of it, is evaluated once when
// the second triangle finds it in its chunk's MidpointCache (about a third fewer evaluations).
Partial measureTriangles(const tessellate::TriangleMesh& mesh,
                         const subdiv::LimitSurface& surface) {
  const size_t triangles = mesh.triangleCount();
  if (mesh.triangleFaces.size() != triangles || mesh.cornerUVs.size() != 3 * triangles) {
    throw std::invalid_argument(
        "measureGeometry: the mesh has neither limit positions nor (face, u, v) for each "
        "triangle");
  }
  constexpr uint32_t kUnused = std::numeric_limits<uint32_t>::max();
  const size_t vertices = mesh.positions.size();
  std::vector<uint32_t> firstCorner(vertices, kUnused);
  for (size_t c = 0; c < 3 * triangles; ++c) {
    const uint32_t v = mesh.indices[c];
    if (v >= vertices) {
      throw std::invalid_argument("measureGeometry: triangle " + std::to_string(c / 3) +
                                  " names vertex " + std::to_string(v) + " of " +
                                  std::to_string(vertices));
    }
    const int face = mesh.triangleFaces[c / 3];
    if (face < 0 || face >= surface.faceCount()) {
      throw std::invalid_argument("measureGeometry: triangle " + std::to_string(c / 3) +
                                  " names face " + std::to_string(face) + " of " +
                                  std::to_string(surface.faceCount()));
    }
    if (firstCorner[v] == kUnused) firstCorner[v] = static_cast<uint32_t>(c);
  }
  auto sameParameters = [&](size_t c, size_t d) {
    return mesh.triangleFaces[c / 3] == mesh.triangleFaces[d / 3] &&
           mesh.cornerUVs[c].x == mesh.cornerUVs[d].x && mesh.cornerUVs[c].y == mesh.cornerUVs[d].y;
  };
  auto cornerDistance = [&](size_t c) {
    const Vec2f uv = mesh.cornerUVs[c];
    return length(mesh.positions[mesh.indices[c]].toDouble() -
                  surface.position(mesh.triangleFaces[c / 3], uv.x, uv.y));
  };

  // Vertex distances, at each vertex's first corner (holes have no surface: left unused).
  std::vector<double> vertexDistance(vertices, 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices, kChunk),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t v = range.begin(); v < range.end(); ++v) {
                        const uint32_t c = firstCorner[v];
                        if (c != kUnused && surface.hasLimit(mesh.triangleFaces[c / 3])) {
                          vertexDistance[v] = cornerDistance(c);
                        }
                      }
                    });

  // Bfr parameterisations are the same for every call on a face; look them up once.
  std::vector<OpenSubdiv::Bfr::Parameterization> params(surface.faceCount());
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (surface.hasLimit(f)) params[f] = surface.parameterization(f);
  }
  return reduceInChunksWith<MidpointCache>(
      triangles, [&](size_t t, Partial& p, MidpointCache& midpoints) {
        const int face = mesh.triangleFaces[t];
        if (!surface.hasLimit(face)) return;  // holes have no surface to be measured against
        Vec3 corner[3];
        Vec2f uv[3];
        for (int k = 0; k < 3; ++k) {
          const size_t c = 3 * t + k;
          const uint32_t v = mesh.indices[c];
          corner[k] = mesh.positions[v].toDouble();
          uv[k] = mesh.cornerUVs[c];
          p.add(sameParameters(c, firstCorner[v]) ? vertexDistance[v] : cornerDistance(c));
        }
        // Faces split into quad sub-faces (Catmull-Clark n-gons, n != 4) have a parameter space
        // made of separate tiles; between corners on different tiles a linear blend of (u, v)
        // lands in no sub-face at all, so such a triangle is measured at its corners only.
        const OpenSubdiv::Bfr::Parameterization& param = params[face];
        if (param.HasSubFaces()) {
          const float c0[2] = {uv[0].x, uv[0].y}, c1[2] = {uv[1].x, uv[1].y},
                      c2[2] = {uv[2].x, uv[2].y};
          const int s0 = param.GetSubFace(c0);
          if (param.GetSubFace(c1) != s0 || param.GetSubFace(c2) != s0) return;
        }
        auto blendDistance = [&](const double* w) {
          const Vec3 onTriangle = corner[0] * w[0] + corner[1] * w[1] + corner[2] * w[2];
          const double u = w[0] * uv[0].x + w[1] * uv[1].x + w[2] * uv[2].x;
          const double v = w[0] * uv[0].y + w[1] * uv[1].y + w[2] * uv[2].y;
          return length(onTriangle - surface.position(face, u, v));
        };
        for (int k = 0; k < 3; ++k) {
          const int i = kMidpointEdges[k][0], j = kMidpointEdges[k][1];
          const uint32_t a = mesh.indices[3 * t + i], b = mesh.indices[3 * t + j];
          if (const double* known = midpoints.find(face, a, b, uv[i], uv[j])) {
            p.add(*known);
            continue;
          }
          const double d = blendDistance(kBlendWeights[k]);
          midpoints.put(face, a, b, uv[i], uv[j], d);
          p.add(d);
        }
        p.add(blendDistance(kBlendWeights[3]));
      });
}

}  // namespace

GeometryMetrics measureGeometry(const tessellate::TriangleMesh& mesh,
                                const subdiv::LimitSurface& surface) {
  const Partial total =
      mesh.limitPositions.empty() ? measureTriangles(mesh, surface) : measureVertices(mesh);
  GeometryMetrics result;
  result.maxDist = total.max;
  result.meanDist = total.count == 0 ? 0.0 : total.sum / static_cast<double>(total.count);
  const double diagonal = surface.bounds().diagonal();
  result.relMaxDist = diagonal > 0 ? result.maxDist / diagonal : 0.0;
  result.relMeanDist = diagonal > 0 ? result.meanDist / diagonal : 0.0;
  return result;
}

}  // namespace limn::render::metrics
