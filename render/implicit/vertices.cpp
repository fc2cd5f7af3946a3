// The polygonisers' common last steps: vertices onto the surface, and the mesh's measures.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <unordered_map>

#include "render/core/parallel.h"
#include "render/implicit/grid.h"

namespace limn::render::implicit {

namespace {

// The vertex on a-b: the field's root between the two samples of opposite signs.
Vec3 rootOnEdge(FieldEvaluator& field, const EdgeVertex& e, double tolerance) {
  const Vec3 d = e.b - e.a;
  const double len = std::max(length(d), 1e-300);
  return e.a + d * rootOnSegment(field, e.a, d, 0.0, e.fa, 1.0, e.fb, tolerance / len);
}

uint64_t edgeKey(uint32_t a, uint32_t b) { return (static_cast<uint64_t>(a) << 32) | b; }

}  // namespace

tessellate::TriangleMesh finishVertices(const Field& field, const RawMesh& raw, double tolerance,
                                        const CancelToken& cancel) {
  tessellate::TriangleMesh mesh;
  mesh.positions.resize(raw.vertices.size());
  mesh.normals.resize(raw.vertices.size());
  parallelFor(raw.vertices.size(), 2048, [&](size_t begin, size_t end) {
    if (cancel.expired()) return;
    FieldEvaluator evaluator(field);
    for (size_t v = begin; v < end; ++v) {
      const Vec3 p = rootOnEdge(evaluator, raw.vertices[v], tolerance);
      mesh.positions[v] = Vec3f(p);
      mesh.normals[v] = Vec3f(evaluator.normal(p));
    }
  });
  cancel.check();
  mesh.indices = raw.indices;
  return mesh;
}

MeshClosure checkClosure(const tessellate::TriangleMesh& mesh) {
  // Directed edge -> uses; a closed, consistently oriented mesh uses each directed edge once
  // and its reverse once.
  std::unordered_map<uint64_t, uint32_t> directed;
  directed.reserve(mesh.indices.size());
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      ++directed[edgeKey(mesh.indices[t + k], mesh.indices[t + (k + 1) % 3])];
    }
  }
  MeshClosure closure;
  for (const auto& [key, uses] : directed) {
    const uint32_t a = static_cast<uint32_t>(key >> 32), b = static_cast<uint32_t>(key);
    auto reverse = directed.find(edgeKey(b, a));
    const uint32_t back = reverse == directed.end() ? 0 : reverse->second;
    if (a > b && back > 0) continue;  // counted from the other direction
    const uint32_t total = uses + back;
    if (total == 1) ++closure.boundaryEdges;
    if (total > 2) ++closure.nonManifoldEdges;
    if (uses > 1 || back > 1) ++closure.misorientedEdges;
  }
  return closure;
}

ImplicitGeometryError measureImplicitGeometry(const tessellate::TriangleMesh& mesh,
                                              const Field& field, const CancelToken& cancel) {
  const size_t triangles = mesh.triangleCount();
  std::vector<double> maxima(triangles, 0.0), sums(triangles, 0.0);
  parallelFor(triangles, 1024, [&](size_t begin, size_t end) {
    if (cancel.expired()) return;
    FieldEvaluator evaluator(field);
    auto distance = [&](const Vec3& p) {
      Vec3 g;
      const double f = evaluator.valueAndGradient(p, g);
      const double n = length(g);
      return n > 0 ? std::fabs(f) / n : std::fabs(f) > 0 ? 1e300 : 0.0;
    };
    for (size_t t = begin; t < end; ++t) {
      const Vec3 a = mesh.positions[mesh.indices[3 * t]].toDouble(),
                 b = mesh.positions[mesh.indices[3 * t + 1]].toDouble(),
                 c = mesh.positions[mesh.indices[3 * t + 2]].toDouble();
      const Vec3 samples[7] = {
          a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5, (a + b + c) / 3.0};
      double largest = 0, sum = 0;
      for (const Vec3& p : samples) {
        const double d = distance(p);
        largest = std::max(largest, d);
        sum += d;
      }
      maxima[t] = largest;
      sums[t] = sum;
    }
  });
  cancel.check();
  ImplicitGeometryError error;
  double total = 0;
  for (size_t t = 0; t < triangles; ++t) {
    error.maxDist = std::max(error.maxDist, maxima[t]);
    total += sums[t];
  }
  error.meanDist = triangles ? total / (7.0 * triangles) : 0.0;
  const double diagonal = std::max(field.bounds().diagonal(), 1e-300);
  error.relMaxDist = error.maxDist / diagonal;
  error.relMeanDist = error.meanDist / diagonal;
  return error;
}

}  // namespace limn::render::implicit
