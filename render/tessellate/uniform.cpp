// Uniform refinement of the cage, by OpenSubdiv's Far (positions interpolated level by level,
// then the limit masks, far_limit.h) or by limn's own rules (render/rules: masks or factored,
// then the limit masks). Every vertex of the last level gets its refined position, its limit
// position and its limit normal; assemble() makes the mesh from those. The masks' levels that
// run on halfedges (rules/halfedge_level.h) skip that step: assembleHalfedges() writes the mesh
// straight from them.
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include "render/core/error.h"
#include "render/core/parallel.h"
#include "render/rules/halfedge_level.h"
#include "render/rules/limit.h"
#include "render/rules/refine.h"
#include "render/subdiv/far_limit.h"
#include "render/subdiv/far_point.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::tessellate {

namespace Far = OpenSubdiv::Far;

namespace {

// The last level of a refinement, whoever made it: its points, their limits and limit normals,
// and the topology the mesh is assembled from, as flat offset + index arrays.
struct Refined {
  std::vector<Vec3> points, limit, normals;  // normals: any length, or zero where unknown
  std::vector<int> faceOffsets{0}, faceVertices;
  std::vector<uint8_t> hole;
  std::vector<std::array<int, 2>> edgeVertices;
  // Which faces lie around each edge and vertex (offset + index arrays).
  std::vector<int> edgeFaceOffsets, edgeFaces;
  std::vector<int> vertexFaceOffsets, vertexFaces;
  int faceCount() const { return static_cast<int>(faceOffsets.size()) - 1; }
};

// Adds the time since the previous lap to one stage of UniformOptions::stages, when asked for.
class StageTimer {
 public:
  explicit StageTimer(UniformOptions::Stages* stages) : stages_(stages) {}
  void lap(double UniformOptions::Stages::*stage) {
    const auto now = std::chrono::steady_clock::now();
    if (stages_) stages_->*stage += std::chrono::duration<double, std::milli>(now - start_).count();
    start_ = now;
  }

 private:
  UniformOptions::Stages* stages_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// Loops over this many elements per task: enough to amortise a task, few enough to balance.
constexpr size_t kGrain = 16384;

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

Refined refineWithFar(const subdiv::LimitSurface& surface, int level, StageTimer& timer) {
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
  timer.lap(&UniformOptions::Stages::refineMs);
  std::vector<subdiv::FarPoint> limit, du, dv;
  subdiv::limitOfLastLevel(*refiner, src, limit, du, dv);  // not PrimvarRefiner::Limit: far_limit.h

  Refined out;
  out.points.resize(vertexCount);
  out.limit.resize(vertexCount);
  out.normals.resize(vertexCount);
  parallelFor(vertexCount, kGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      out.points[v] = src[v].p;
      out.limit[v] = limit[v].p;
      out.normals[v] = cross(du[v].p, dv[v].p);
    }
  });
  timer.lap(&UniformOptions::Stages::limitMs);
  // Far's accessors hand out arrays of its own; copy them into flat offset + index arrays.
  const auto flatten = [](int count, auto arrayOf, std::vector<int>& offsets,
                          std::vector<int>& values) {
    offsets.assign(count + 1, 0);
    for (int i = 0; i < count; ++i) offsets[i + 1] = offsets[i] + arrayOf(i).size();
    values.resize(offsets[count]);
    parallelFor(count, kGrain, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        Far::ConstIndexArray a = arrayOf(static_cast<int>(i));
        std::copy(a.begin(), a.end(), values.begin() + offsets[i]);
      }
    });
  };
  flatten(
      last.GetNumFaces(), [&](int f) { return last.GetFaceVertices(f); }, out.faceOffsets,
      out.faceVertices);
  flatten(
      last.GetNumEdges(), [&](int e) { return last.GetEdgeFaces(e); }, out.edgeFaceOffsets,
      out.edgeFaces);
  flatten(
      vertexCount, [&](int v) { return last.GetVertexFaces(v); }, out.vertexFaceOffsets,
      out.vertexFaces);
  out.hole.resize(last.GetNumFaces());
  for (int f = 0; f < last.GetNumFaces(); ++f) out.hole[f] = last.IsFaceHole(f);
  out.edgeVertices.resize(last.GetNumEdges());
  for (int e = 0; e < last.GetNumEdges(); ++e) {
    Far::ConstIndexArray ev = last.GetEdgeVertices(e);
    out.edgeVertices[e] = {ev[0], ev[1]};
  }
  return out;
}

// A level of limn's rules (refined on its Topology) with its limit.
Refined fromRules(rules::Level refined, const mesh::ControlMesh& cage, int level,
                  StageTimer& timer) {
  rules::Limit limit = rules::limitOf(refined, /*cornerNormals=*/false);
  timer.lap(&UniformOptions::Stages::limitMs);
  Refined out;
  out.points = std::move(refined.points);
  out.limit = std::move(limit.positions);
  out.normals = std::move(limit.normals);
  rules::Topology& t = refined.topology;
  out.faceOffsets = std::move(t.faceOffsets);
  out.faceVertices = std::move(t.faceVertices);
  out.hole = std::move(t.faceHole);
  out.edgeVertices = std::move(t.edgeVertices);
  out.edgeFaceOffsets = std::move(t.edgeFaceOffsets);
  out.edgeFaces = std::move(t.edgeFaces);
  out.vertexFaceOffsets = std::move(t.vertexFaceOffsets);
  out.vertexFaces = std::move(t.vertexFaces);
  if (level == 0) {
    // Level 0 is the cage, drawn as the OpenSubdiv engine draws it (tessellateCoarse): only
    // the mesh's own holes are left out, not the faces "none" boundaries give no limit.
    out.hole.assign(out.hole.size(), 0);
    for (int f : cage.holes) out.hole[f] = 1;
  }
  return out;
}

// The mesh the rasteriser takes, every stage a parallel loop whose elements are written by one
// task each (so the result does not depend on the number of threads): vertices, triangles
// (faces fanned, holes left out), per-vertex limit normals turned to the side their faces face,
// and the polygon edges of the faces drawn.
TriangleMesh assemble(const Refined& r, bool pushToLimit) {
  const size_t vertexCount = r.points.size();
  const int faceCount = r.faceCount();
  const std::vector<Vec3>& drawn = pushToLimit ? r.limit : r.points;
  TriangleMesh out;
  out.positions.resize(vertexCount);
  out.limitPositions.resize(vertexCount);
  parallelFor(vertexCount, kGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      out.positions[v] = Vec3f(drawn[v]);
      out.limitPositions[v] = Vec3f(r.limit[v]);
    }
  });

  // Each face's fan: where its triangles start, and the face's area-weighted normal.
  std::vector<uint32_t> firstTriangle(faceCount + 1, 0);
  for (int f = 0; f < faceCount; ++f) {
    const int n = r.faceOffsets[f + 1] - r.faceOffsets[f];
    firstTriangle[f + 1] = firstTriangle[f] + (r.hole[f] ? 0 : n - 2);
  }
  out.indices.resize(3 * size_t{firstTriangle[faceCount]});
  std::vector<Vec3> faceNormal(faceCount);
  parallelFor(faceCount, kGrain, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if (r.hole[f]) continue;
      const int* fv = r.faceVertices.data() + r.faceOffsets[f];
      const int n = r.faceOffsets[f + 1] - r.faceOffsets[f];
      uint32_t* triangle = out.indices.data() + 3 * size_t{firstTriangle[f]};
      Vec3 normal{0, 0, 0};
      for (int k = 1; k + 1 < n; ++k, triangle += 3) {
        triangle[0] = static_cast<uint32_t>(fv[0]);
        triangle[1] = static_cast<uint32_t>(fv[k]);
        triangle[2] = static_cast<uint32_t>(fv[k + 1]);
        normal += cross(drawn[fv[k]] - drawn[fv[0]], drawn[fv[k + 1]] - drawn[fv[0]]);
      }
      faceNormal[f] = normal;
    }
  });

  // The limit normal, turned to the side of the faces around the vertex (the faces' own
  // normal where the limit tangents are degenerate).
  out.normals.resize(vertexCount);
  parallelFor(vertexCount, kGrain, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      Vec3 around{0, 0, 0};
      for (int i = r.vertexFaceOffsets[v]; i < r.vertexFaceOffsets[v + 1]; ++i) {
        if (!r.hole[r.vertexFaces[i]]) around += faceNormal[r.vertexFaces[i]];
      }
      Vec3 n = normalize(r.normals[v]);
      if (length(n) == 0) n = normalize(around);
      if (dot(n, around) < 0) n = -n;
      out.normals[v] = Vec3f(n);
    }
  });

  // The wireframe: every edge of a face that is drawn.
  const auto drawnEdge = [&](size_t e) {
    for (int i = r.edgeFaceOffsets[e]; i < r.edgeFaceOffsets[e + 1]; ++i) {
      if (!r.hole[r.edgeFaces[i]]) return true;
    }
    return false;
  };
  out.lines.reserve(2 * r.edgeVertices.size());
  for (size_t e = 0; e < r.edgeVertices.size(); ++e) {
    if (!drawnEdge(e)) continue;
    out.lines.push_back(static_cast<uint32_t>(r.edgeVertices[e][0]));
    out.lines.push_back(static_cast<uint32_t>(r.edgeVertices[e][1]));
  }
  return out;
}

// Where each element that `keep` keeps goes in a compacted array (its rank among the kept),
// and how many are kept; with keepAll, every element where it is (no pass over them).
struct Ranks {
  std::vector<uint32_t> rank;
  size_t kept = 0;
  size_t of(size_t i) const { return rank.empty() ? i : rank[i]; }
};

template <typename Keep>
Ranks ranksOf(size_t count, bool keepAll, Keep keep) {
  Ranks out;
  if (keepAll) {
    out.kept = count;
    return out;
  }
  out.rank.resize(count);
  for (size_t i = 0; i < count; ++i) {
    out.rank[i] = static_cast<uint32_t>(out.kept);
    out.kept += keep(i) ? 1 : 0;
  }
  return out;
}

// A level refined on halfedges (rules/halfedge_level.h), straight into the mesh the rasteriser
// takes: the vertices in one pass over their rings, the faces that are not holes as triangles
// (a quad as two), and the edges of the faces drawn.
template <int N>
TriangleMesh assembleHalfedges(const rules::HalfedgeLevel<N>& q, bool pushToLimit,
                               StageTimer& timer) {
  TriangleMesh out;
  out.positions.resize(q.vertexCount);
  out.limitPositions.resize(q.vertexCount);
  out.normals.resize(q.vertexCount);
  rules::drawnVertices(q, pushToLimit, out.positions.data(), out.limitPositions.data(),
                       out.normals.data());
  timer.lap(&UniformOptions::Stages::limitMs);

  // Without holes every face and edge is drawn, in order.
  const bool noHoles =
      std::none_of(q.faceHole.begin(), q.faceHole.end(), [](uint8_t h) { return h; });
  const Ranks faceRank = ranksOf(q.faceCount(), noHoles, [&](size_t f) { return !q.faceHole[f]; });
  constexpr int kIndicesPerFace = 3 * (N - 2);
  out.indices.resize(kIndicesPerFace * faceRank.kept);
  parallelFor(q.faceCount(), kGrain, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if (q.faceHole[f]) continue;
      const int* c = q.vert.data() + N * f;
      uint32_t* t = out.indices.data() + kIndicesPerFace * faceRank.of(f);
      for (int k = 1; k + 1 < N; ++k, t += 3) {  // fanned from the first corner
        t[0] = static_cast<uint32_t>(c[0]);
        t[1] = static_cast<uint32_t>(c[k]);
        t[2] = static_cast<uint32_t>(c[k + 1]);
      }
    }
  });

  const auto drawnEdge = [&](size_t e) {
    const int first = q.edgeFirst[e], other = q.twin[first];
    return !q.faceHole[rules::faceOfHalfedge<N>(first)] ||
           (other >= 0 && !q.faceHole[rules::faceOfHalfedge<N>(other)]);
  };
  const Ranks edgeRank = ranksOf(q.edgeCount(), noHoles, drawnEdge);
  out.lines.resize(2 * edgeRank.kept);
  parallelFor(q.edgeCount(), kGrain, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      if (!noHoles && !drawnEdge(e)) continue;
      out.lines[2 * edgeRank.of(e)] = static_cast<uint32_t>(q.edgeVertices[e][0]);
      out.lines[2 * edgeRank.of(e) + 1] = static_cast<uint32_t>(q.edgeVertices[e][1]);
    }
  });
  timer.lap(&UniformOptions::Stages::meshMs);
  return out;
}

// limn's own rules: the masks run their last levels on halfedges where the mesh allows
// (rules::refineUniformFast), the factored method level by level on the Topology.
TriangleMesh tessellateWithRules(const mesh::ControlMesh& cage, const UniformOptions& o,
                                 rules::Method method) {
  StageTimer timer(o.stages);
  rules::Level level;
  if (method == rules::Method::Masks) {
    rules::FastRefinement fast = rules::refineUniformFast(cage, o.level);
    timer.lap(&UniformOptions::Stages::refineMs);
    if (fast.quads) return assembleHalfedges(*fast.quads, o.pushToLimit, timer);
    if (fast.triangles) return assembleHalfedges(*fast.triangles, o.pushToLimit, timer);
    level = std::move(fast.level);
  } else {
    level = rules::refineUniform(cage, o.level, method);
    timer.lap(&UniformOptions::Stages::refineMs);
  }
  TriangleMesh mesh = assemble(fromRules(std::move(level), cage, o.level, timer), o.pushToLimit);
  timer.lap(&UniformOptions::Stages::meshMs);
  return mesh;
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
  const mesh::ControlMesh& cage = surface.mesh();
  if (o.engine == UniformEngine::Masks || o.engine == UniformEngine::Factored) {
    rules::Method method =
        o.engine == UniformEngine::Masks ? rules::Method::Masks : rules::Method::Factored;
    std::string whyNot = rules::unsupportedReason(cage, method);
    if (!whyNot.empty()) throw InputError(InputError::Kind::InvalidParameter, "engine", whyNot);
    return tessellateWithRules(cage, o, method);
  }
  if (o.engine == UniformEngine::Auto && o.level > 0 &&
      rules::unsupportedReason(cage, rules::Method::Masks).empty()) {
    try {
      return tessellateWithRules(cage, o, rules::Method::Masks);
    } catch (const InputError& e) {
      // Not manifold: limn's rules refuse it before refining anything; OpenSubdiv takes it.
      if (e.kind() != InputError::Kind::InvalidMesh) throw;
    }
  }
  if (o.level == 0) {
    TriangleMesh coarse = tessellateCoarse(surface);
    if (o.pushToLimit) coarse.positions = coarse.limitPositions;
    return coarse;
  }
  StageTimer timer(o.stages);
  TriangleMesh mesh = assemble(refineWithFar(surface, o.level, timer), o.pushToLimit);
  timer.lap(&UniformOptions::Stages::meshMs);
  return mesh;
}

TriangleMesh tessellateUniform(const subdiv::LimitSurface& surface, int level,
                               size_t maxTriangles) {
  UniformOptions options;
  options.level = level;
  options.engine = UniformEngine::OpenSubdiv;
  options.maxTriangles = maxTriangles;
  return tessellateUniform(surface, options);
}

}  // namespace limn::render::tessellate
