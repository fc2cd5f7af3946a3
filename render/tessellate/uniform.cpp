// Uniform refinement of the cage with OpenSubdiv's Far: positions interpolated level by level,
// then every vertex of the last level gets its limit position and limit normal.
#include <cmath>
#include <set>
#include <string>

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefiner.h>

#include "render/core/error.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::tessellate {

namespace Far = OpenSubdiv::Far;

namespace {

// The primvar type Far's PrimvarRefiner interpolates.
struct Point {
  double x = 0, y = 0, z = 0;
  void Clear(void* = nullptr) { x = y = z = 0; }
  void AddWithWeight(const Point& p, float w) {
    x += w * p.x;
    y += w * p.y;
    z += w * p.z;
  }
  Vec3 vec() const { return {x, y, z}; }
};

// Triangles the refined mesh will have: Loop splits every triangle into 4 per level;
// Catmull-Clark and bilinear split an n-gon into n quads at the first level, each quad into 4
// after that, and every quad is drawn as 2 triangles.
size_t predictedTriangles(const mesh::ControlMesh& cage, int level) {
  double count = 0;
  for (int n : cage.faceVertexCounts) {
    if (level == 0) count += n - 2;
    else if (cage.scheme == mesh::Scheme::Loop) count += 1;
    else count += 2.0 * n / 4.0;
  }
  return static_cast<size_t>(count * std::pow(4.0, level));
}

}  // namespace

TriangleMesh tessellateUniform(const subdiv::LimitSurface& surface, int level,
                               size_t maxTriangles) {
  size_t predicted = predictedTriangles(surface.mesh(), level);
  if (predicted > maxTriangles) {
    throw InputError(InputError::Kind::LimitExceeded, "maxTriangles",
                     "uniform level " + std::to_string(level) + " would make " +
                         std::to_string(predicted) + " triangles: exceeds limit maxTriangles " +
                         std::to_string(maxTriangles));
  }
  if (level == 0) return tessellateCoarse(surface);

  std::unique_ptr<Far::TopologyRefiner> refiner = surface.createRefiner();
  Far::TopologyRefiner::UniformOptions options(level);
  options.fullTopologyInLastLevel = true;
  refiner->RefineUniform(options);

  // Interpolate positions through every level.
  std::vector<Point> points(refiner->GetNumVerticesTotal());
  const mesh::ControlMesh& cage = surface.mesh();
  for (int v = 0; v < cage.vertexCount(); ++v) {
    points[v] = {cage.points[v].x, cage.points[v].y, cage.points[v].z};
  }
  Far::PrimvarRefiner primvar(*refiner);
  Point* src = points.data();
  for (int l = 1; l <= level; ++l) {
    Point* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
    primvar.Interpolate(l, src, dst);
    src = dst;
  }
  const Far::TopologyLevel& last = refiner->GetLevel(level);
  const int vertexCount = last.GetNumVertices();
  std::vector<Point> limit(vertexCount), du(vertexCount), dv(vertexCount);
  primvar.Limit(src, limit, du, dv);

  TriangleMesh out;
  out.positions.reserve(vertexCount);
  for (int v = 0; v < vertexCount; ++v) {
    out.positions.emplace_back(src[v].vec());
    out.limitPositions.emplace_back(limit[v].vec());
  }

  // Faces, and per-vertex face normals to orient the limit normals consistently.
  std::vector<Vec3> faceNormalSum(vertexCount, Vec3{0, 0, 0});
  std::set<std::pair<int, int>> seen;
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    if (last.IsFaceHole(f)) continue;
    Far::ConstIndexArray fv = last.GetFaceVertices(f);
    for (int k = 1; k + 1 < fv.size(); ++k) {
      out.indices.insert(out.indices.end(), {static_cast<uint32_t>(fv[0]),
                                             static_cast<uint32_t>(fv[k]),
                                             static_cast<uint32_t>(fv[k + 1])});
      Vec3 n = cross(src[fv[k]].vec() - src[fv[0]].vec(), src[fv[k + 1]].vec() - src[fv[0]].vec());
      faceNormalSum[fv[0]] += n;
      faceNormalSum[fv[k]] += n;
      faceNormalSum[fv[k + 1]] += n;
    }
    for (int k = 0; k < fv.size(); ++k) {
      int a = fv[k], b = fv[(k + 1) % fv.size()];
      if (seen.insert({std::min(a, b), std::max(a, b)}).second) {
        out.lines.insert(out.lines.end(), {static_cast<uint32_t>(a), static_cast<uint32_t>(b)});
      }
    }
  }
  out.normals.resize(vertexCount);
  for (int v = 0; v < vertexCount; ++v) {
    Vec3 n = normalize(cross(du[v].vec(), dv[v].vec()));
    Vec3 around = faceNormalSum[v];
    if (length(n) == 0) n = normalize(around);  // degenerate tangents: use the faces' normal
    if (dot(n, around) < 0) n = -n;
    out.normals[v] = Vec3f(n);
  }
  return out;
}

}  // namespace limn::render::tessellate
