// measureGeometry(): how far an approximation's triangles are from the limit surface, in world
// units, at points whose place on the limit surface is known.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
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

template <typename PerItem>
Partial reduceInChunks(size_t items, PerItem&& perItem) {
  const size_t chunks = (items + kChunk - 1) / kChunk;
  std::vector<Partial> partials(chunks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t c = range.begin(); c < range.end(); ++c) {
                        Partial& p = partials[c];
                        const size_t end = std::min(items, (c + 1) * kChunk);
                        for (size_t i = c * kChunk; i < end; ++i) perItem(i, p);
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

// A triangle is sampled at its three corners and at these barycentric blends of them: the edge
// midpoints and the centroid.
constexpr double kBlendWeights[4][3] = {
    {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};

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
// their own. Each corner still counts as one sample, as the definition says.
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
  return reduceInChunks(triangles, [&](size_t t, Partial& p) {
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
    for (const auto& w : kBlendWeights) {
      const Vec3 onTriangle = corner[0] * w[0] + corner[1] * w[1] + corner[2] * w[2];
      const double u = w[0] * uv[0].x + w[1] * uv[1].x + w[2] * uv[2].x;
      const double v = w[0] * uv[0].y + w[1] * uv[1].y + w[2] * uv[2].y;
      p.add(length(onTriangle - surface.position(face, u, v)));
    }
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
