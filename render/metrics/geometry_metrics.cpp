// measureGeometry(): how far an approximation's triangles are from the limit surface, in world
// units, at points whose place on the limit surface is known.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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

// Barycentric weights of the seven samples of a triangle: corners, edge midpoints, centroid.
constexpr double kSampleWeights[7][3] = {
    {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
    {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
    {1.0 / 3, 1.0 / 3, 1.0 / 3}};

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
Partial measureTriangles(const tessellate::TriangleMesh& mesh,
                         const subdiv::LimitSurface& surface) {
  const size_t triangles = mesh.triangleCount();
  if (mesh.triangleFaces.size() != triangles || mesh.cornerUVs.size() != 3 * triangles) {
    throw std::invalid_argument(
        "measureGeometry: the mesh has neither limit positions nor (face, u, v) for each "
        "triangle");
  }
  // Bfr parameterisations are the same for every call on a face; look them up once.
  std::vector<OpenSubdiv::Bfr::Parameterization> params(surface.faceCount());
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (surface.hasLimit(f)) params[f] = surface.parameterization(f);
  }
  return reduceInChunks(triangles, [&](size_t t, Partial& p) {
    const int face = mesh.triangleFaces[t];
    if (face < 0 || face >= surface.faceCount()) {
      throw std::invalid_argument("measureGeometry: triangle " + std::to_string(t) +
                                  " names face " + std::to_string(face) + " of " +
                                  std::to_string(surface.faceCount()));
    }
    if (!surface.hasLimit(face)) return;  // holes have no surface to be measured against
    Vec3 corner[3];
    Vec2f uv[3];
    for (int k = 0; k < 3; ++k) {
      corner[k] = mesh.positions[mesh.indices[3 * t + k]].toDouble();
      uv[k] = mesh.cornerUVs[3 * t + k];
    }
    // Faces split into quad sub-faces (Catmull-Clark n-gons, n != 4) have a parameter space
    // made of separate tiles; between corners on different tiles a linear blend of (u, v)
    // lands in no sub-face at all, so such a triangle is measured at its corners only.
    int samples = 7;
    const OpenSubdiv::Bfr::Parameterization& param = params[face];
    if (param.HasSubFaces()) {
      const float c0[2] = {uv[0].x, uv[0].y}, c1[2] = {uv[1].x, uv[1].y},
                  c2[2] = {uv[2].x, uv[2].y};
      const int s0 = param.GetSubFace(c0);
      if (param.GetSubFace(c1) != s0 || param.GetSubFace(c2) != s0) samples = 3;
    }
    for (int i = 0; i < samples; ++i) {
      const double* w = kSampleWeights[i];
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
  return result;
}

}  // namespace limn::render::metrics
