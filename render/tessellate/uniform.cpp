// Uniform refinement of the cage, by OpenSubdiv's Far (positions interpolated level by level,
// then PrimvarRefiner::Limit) or by limn's own rules (render/rules: masks or factored, then the
// limit masks). Both give every vertex of the last level its refined position, its limit
// position and its limit normal; the mesh is assembled from those the same way.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <cmath>
#include <set>
#include <string>

#include "render/core/error.h"
#include "render/rules/limit.h"
#include "render/rules/refine.h"
#include "render/subdiv/far_limit.h"
#include "render/subdiv/far_point.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::tessellate {

namespace Far = OpenSubdiv::Far;

namespace {

// The last level of a refinement, whoever made it.
struct Refined {
  std::vector<Vec3> points, limit, normals;  // normals: any length, or zero where unknown
  std::vector<int> faceOffsets{0}, faceVertices;
  std::vector<uint8_t> hole;
};

// Triangles the refined mesh will have: Loop splits every triangle into 4 per level;
// Catmull-Clark and bilinear split an n-gon into n quads at the first level, each quad into 4
// after that, and every quad is drawn as 2 triangles.
size_t predictedTriangles(const mesh::ControlMesh& cage, int level) {
  double count = 0;
  for (int n : cage.faceVertexCounts) {
    if (level == 0)
      count += n - 2;
    else if (cage.scheme == mesh::Scheme::Loop)
      count += 1;
    else
      count += 2.0 * n / 4.0;
  }
  return static_cast<size_t>(count * std::pow(4.0, level));
}

Refined refineWithFar(const subdiv::LimitSurface& surface, int level) {
  std::unique_ptr<Far::TopologyRefiner> refiner = surface.createRefiner();
  Far::TopologyRefiner::UniformOptions options(level);
  options.fullTopologyInLastLevel = true;
  refiner->RefineUniform(options);

  // Interpolate positions through every level.
  std::vector<subdiv::FarPoint> points(refiner->GetNumVerticesTotal());
  const mesh::ControlMesh& cage = surface.mesh();
  for (int v = 0; v < cage.vertexCount(); ++v) {
    points[v].p = cage.points[v];
  }
  Far::PrimvarRefiner primvar(*refiner);
  subdiv::FarPoint* src = points.data();
  for (int l = 1; l <= level; ++l) {
    subdiv::FarPoint* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
    primvar.Interpolate(l, src, dst);
    src = dst;
  }
  const Far::TopologyLevel& last = refiner->GetLevel(level);
  const int vertexCount = last.GetNumVertices();
  std::vector<subdiv::FarPoint> limit, du, dv;
  subdiv::limitOfLastLevel(*refiner, src, limit, du, dv);  // not PrimvarRefiner::Limit: far_limit.h

  Refined out;
  for (int v = 0; v < vertexCount; ++v) {
    out.points.push_back(src[v].p);
    out.limit.push_back(limit[v].p);
    out.normals.push_back(cross(du[v].p, dv[v].p));
  }
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    Far::ConstIndexArray fv = last.GetFaceVertices(f);
    out.faceVertices.insert(out.faceVertices.end(), fv.begin(), fv.end());
    out.faceOffsets.push_back(static_cast<int>(out.faceVertices.size()));
    out.hole.push_back(last.IsFaceHole(f));
  }
  return out;
}

Refined refineWithRules(const mesh::ControlMesh& cage, int level, rules::Method method) {
  rules::Level refined = rules::refineUniform(cage, level, method);
  rules::Limit limit = rules::limitOf(refined);
  Refined out;
  out.points = std::move(refined.points);
  out.limit = std::move(limit.positions);
  out.normals = std::move(limit.normals);
  out.faceOffsets = std::move(refined.topology.faceOffsets);
  out.faceVertices = std::move(refined.topology.faceVertices);
  out.hole = std::move(refined.topology.faceHole);
  if (level == 0) {
    // Level 0 is the cage, drawn as the OpenSubdiv engine draws it (tessellateCoarse): only
    // the mesh's own holes are left out, not the faces "none" boundaries give no limit.
    out.hole.assign(out.hole.size(), 0);
    for (int f : cage.holes) out.hole[f] = 1;
  }
  return out;
}

TriangleMesh assemble(const Refined& r, bool pushToLimit) {
  const int vertexCount = static_cast<int>(r.points.size());
  const std::vector<Vec3>& drawn = pushToLimit ? r.limit : r.points;
  TriangleMesh out;
  out.positions.reserve(vertexCount);
  for (int v = 0; v < vertexCount; ++v) {
    out.positions.emplace_back(drawn[v]);
    out.limitPositions.emplace_back(r.limit[v]);
  }

  // Faces, and per-vertex face normals to orient the limit normals consistently.
  std::vector<Vec3> faceNormalSum(vertexCount, Vec3{0, 0, 0});
  std::set<std::pair<int, int>> seen;
  const int faceCount = static_cast<int>(r.faceOffsets.size()) - 1;
  for (int f = 0; f < faceCount; ++f) {
    if (r.hole[f]) continue;
    const int* fv = r.faceVertices.data() + r.faceOffsets[f];
    const int n = r.faceOffsets[f + 1] - r.faceOffsets[f];
    for (int k = 1; k + 1 < n; ++k) {
      out.indices.insert(out.indices.end(),
                         {static_cast<uint32_t>(fv[0]), static_cast<uint32_t>(fv[k]),
                          static_cast<uint32_t>(fv[k + 1])});
      Vec3 normal = cross(drawn[fv[k]] - drawn[fv[0]], drawn[fv[k + 1]] - drawn[fv[0]]);
      faceNormalSum[fv[0]] += normal;
      faceNormalSum[fv[k]] += normal;
      faceNormalSum[fv[k + 1]] += normal;
    }
    for (int k = 0; k < n; ++k) {
      int a = fv[k], b = fv[(k + 1) % n];
      if (seen.insert({std::min(a, b), std::max(a, b)}).second) {
        out.lines.insert(out.lines.end(), {static_cast<uint32_t>(a), static_cast<uint32_t>(b)});
      }
    }
  }
  out.normals.resize(vertexCount);
  for (int v = 0; v < vertexCount; ++v) {
    Vec3 n = normalize(r.normals[v]);
    Vec3 around = faceNormalSum[v];
    if (length(n) == 0) n = normalize(around);  // degenerate tangents: use the faces' normal
    if (dot(n, around) < 0) n = -n;
    out.normals[v] = Vec3f(n);
  }
  return out;
}

}  // namespace

TriangleMesh tessellateUniform(const subdiv::LimitSurface& surface, const UniformOptions& o) {
  size_t predicted = predictedTriangles(surface.mesh(), o.level);
  if (predicted > o.maxTriangles) {
    throw InputError(InputError::Kind::LimitExceeded, "maxTriangles",
                     "uniform level " + std::to_string(o.level) + " would make " +
                         std::to_string(predicted) + " triangles: exceeds limit maxTriangles " +
                         std::to_string(o.maxTriangles));
  }
  if (o.engine != UniformEngine::OpenSubdiv) {
    rules::Method method =
        o.engine == UniformEngine::Masks ? rules::Method::Masks : rules::Method::Factored;
    std::string whyNot = rules::unsupportedReason(surface.mesh(), method);
    if (!whyNot.empty()) throw InputError(InputError::Kind::InvalidParameter, "engine", whyNot);
    return assemble(refineWithRules(surface.mesh(), o.level, method), o.pushToLimit);
  }
  if (o.level == 0) {
    TriangleMesh coarse = tessellateCoarse(surface);
    if (o.pushToLimit) coarse.positions = coarse.limitPositions;
    return coarse;
  }
  return assemble(refineWithFar(surface, o.level), o.pushToLimit);
}

TriangleMesh tessellateUniform(const subdiv::LimitSurface& surface, int level,
                               size_t maxTriangles) {
  UniformOptions options;
  options.level = level;
  options.maxTriangles = maxTriangles;
  return tessellateUniform(surface, options);
}

}  // namespace limn::render::tessellate
