#include "render/implicit/polygonize.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void checkTriangles(size_t triangles, size_t limit) {
  if (triangles > limit) {
    throw InputError(InputError::Kind::LimitExceeded, "maxTriangles",
                     "the polygonisation has more than " + std::to_string(limit) +
                         " triangles (limits.maxTriangles); lower polygonizer.resolution");
  }
}

// Every cell of the grid, slab by slab: a slab's layers are sampled on all threads, then marched
// on all threads (slabs in order: a slab's first layer is the previous one's last).
void marchGrid(const Field& field, const Grid& grid, size_t maxTriangles, RawMesh& raw,
               PolygonizerStats& stats, const CancelToken& cancel) {
  constexpr int kSlab = 16;
  const size_t perLayer = grid.cornersPerLayer();
  std::vector<float> values((kSlab + 1) * perLayer);
  SlabMarcher marcher(grid, raw);
  for (int k0 = 0; k0 < grid.n[2]; k0 += kSlab) {
    const int k1 = std::min(grid.n[2], k0 + kSlab);
    auto start = Clock::now();
    if (k0 == 0) {
      sampleLayers(field, grid, k0, k1, values.data(), cancel);
    } else {
      std::copy_n(values.begin() + kSlab * perLayer, perLayer, values.begin());
      sampleLayers(field, grid, k0 + 1, k1, values.data() + perLayer, cancel);
    }
    stats.sampleMs += msSince(start);
    start = Clock::now();
    marcher.march(k0, k1, values.data());
    stats.polygonizeMs += msSince(start);
    checkTriangles(raw.indices.size() / 3, maxTriangles);
    cancel.check();
  }
  stats.cellsVisited = static_cast<size_t>(grid.n[0]) * grid.n[1] * grid.n[2];
  stats.fieldSamples = perLayer * (grid.n[2] + 1);
}

uint64_t edgeKey(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 32) | b;
}

// Velho-style refinement: split the edges whose end normals differ by more than `flatness`,
// project the midpoints onto the surface, and re-triangulate every triangle by how many of its
// edges were split (red-green), so neighbours always agree on their shared edge.
void refineAdaptively(const Field& field, const PolygonizerOptions& options, double tolerance,
                      tessellate::TriangleMesh& mesh, PolygonizerStats& stats,
                      const CancelToken& cancel) {
  for (int round = 0; round < options.maxDepth; ++round) {
    cancel.check();
    std::unordered_map<uint64_t, uint32_t> split;
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
        const Vec3 na = mesh.normals[a].toDouble(), nb = mesh.normals[b].toDouble();
        if (dot(na, nb) >= options.flatness) continue;
        if (split.emplace(edgeKey(a, b), 0).second) edges.emplace_back(a, b);
      }
    }
    if (edges.empty()) break;
    checkTriangles(mesh.triangleCount() + 3 * edges.size(), options.maxTriangles);
    const uint32_t first = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.resize(first + edges.size());
    mesh.normals.resize(first + edges.size());
    parallelFor(edges.size(), 1024, [&](size_t begin, size_t end) {
      if (cancel.expired()) return;
      FieldEvaluator evaluator(field);
      for (size_t e = begin; e < end; ++e) {
        const Vec3 a = mesh.positions[edges[e].first].toDouble(),
                   b = mesh.positions[edges[e].second].toDouble();
        Vec3 p = (a + b) * 0.5;
        projectToSurface(evaluator, p, tolerance, length(b - a));
        mesh.positions[first + e] = Vec3f(p);
        mesh.normals[first + e] = Vec3f(evaluator.normal(p));
      }
    });
    cancel.check();
    for (size_t e = 0; e < edges.size(); ++e) {
      split[edgeKey(edges[e].first, edges[e].second)] = first + static_cast<uint32_t>(e);
    }
    stats.edgesSplit += edges.size();

    std::vector<uint32_t> indices;
    indices.reserve(mesh.indices.size() * 2);
    auto add = [&](uint32_t a, uint32_t b, uint32_t c) {
      indices.insert(indices.end(), {a, b, c});
    };
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      uint32_t v[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
      int64_t m[3];  // m[k]: midpoint of edge v[k] - v[k + 1], or -1
      int count = 0;
      for (int k = 0; k < 3; ++k) {
        auto it = split.find(edgeKey(v[k], v[(k + 1) % 3]));
        m[k] = it == split.end() ? int64_t{-1} : static_cast<int64_t>(it->second);
        count += m[k] >= 0;
      }
      if (count == 0) {
        add(v[0], v[1], v[2]);
      } else if (count == 3) {
        const uint32_t a = m[0], b = m[1], c = m[2];
        add(v[0], a, c);
        add(a, v[1], b);
        add(c, b, v[2]);
        add(a, b, c);
      } else if (count == 1) {
        const int k = m[0] >= 0 ? 0 : m[1] >= 0 ? 1 : 2;  // split edge v[k] - v[k+1]
        const uint32_t mid = m[k], a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
        add(a, mid, c);
        add(mid, b, c);
      } else {
        const int k = m[0] < 0 ? 1 : m[1] < 0 ? 2 : 0;  // edges k and k+1 split, k+2 not
        const uint32_t a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
        const uint32_t mab = m[k], mbc = m[(k + 1) % 3];
        add(mab, b, mbc);
        add(a, mab, mbc);
        add(a, mbc, c);
      }
    }
    mesh.indices = std::move(indices);
  }
}

void checkOptions(const PolygonizerOptions& options) {
  if (options.resolution < 2) {
    throw InputError(InputError::Kind::InvalidParameter, "polygonizer.resolution",
                     "must be at least 2");
  }
  if (!(options.flatness >= -1 && options.flatness <= 1)) {
    throw InputError(InputError::Kind::InvalidParameter, "polygonizer.flatness",
                     "must be a cosine in [-1, 1]");
  }
  if (!(options.epsilon > 0 && options.epsilon <= 0.1)) {
    throw InputError(InputError::Kind::InvalidParameter, "polygonizer.epsilon",
                     "must be in (0, 0.1] (relative to the domain's diagonal)");
  }
  if (options.maxDepth < 0 || options.maxDepth > 8) {
    throw InputError(InputError::Kind::InvalidParameter, "polygonizer.maxDepth", "must be in 0..8");
  }
}

}  // namespace

const char* polygonizerName(PolygonizerMethod method) {
  switch (method) {
    case PolygonizerMethod::MarchingCubes:
      return "marching-cubes";
    case PolygonizerMethod::Tracker:
      return "tracker";
    case PolygonizerMethod::Octree:
      return "octree";
    case PolygonizerMethod::Adaptive:
      return "adaptive";
  }
  return "?";
}

Polygonization polygonize(const Field& field, const PolygonizerOptions& options,
                          const CancelToken& cancel) {
  checkOptions(options);
  const double tolerance = options.epsilon * field.bounds().diagonal();
  const bool adaptive = options.method == PolygonizerMethod::Adaptive;
  const Grid grid = makeGrid(field.bounds(), options.resolution);
  Polygonization result;
  PolygonizerStats& stats = result.stats;
  for (int a = 0; a < 3; ++a) stats.gridCells[a] = grid.n[a];
  stats.cellSize = grid.cell;

  RawMesh raw;
  auto start = Clock::now();
  switch (options.method) {
    case PolygonizerMethod::MarchingCubes:
    case PolygonizerMethod::Adaptive:
      marchGrid(field, grid, options.maxTriangles, raw, stats, cancel);
      break;
    case PolygonizerMethod::Tracker:
      trackSurface(field, grid, raw, stats, cancel);
      stats.polygonizeMs = msSince(start);
      break;
    case PolygonizerMethod::Octree:
      octreeSurface(field, grid, options.flatness, raw, stats, cancel);
      stats.polygonizeMs = msSince(start);
      break;
  }
  checkTriangles(raw.indices.size() / 3, options.maxTriangles);
  start = Clock::now();
  result.mesh = finishVertices(field, raw, tolerance, cancel);
  if (adaptive) refineAdaptively(field, options, tolerance, result.mesh, stats, cancel);
  stats.vertexMs = msSince(start);
  if (stats.sampleMs > 0) {
    stats.sampleMvoxelsPerS = static_cast<double>(stats.fieldSamples) / (stats.sampleMs * 1e3);
  }
  return result;
}

}  // namespace limn::render::implicit
