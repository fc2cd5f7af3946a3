#include "render/silhouette/presubdivide.h"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <memory>

#include "render/subdiv/far_point.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

namespace Far = OpenSubdiv::Far;

std::string presubdivisionReason(const mesh::ControlMesh& mesh) {
  if (mesh.faceCount() < kAutoFaceLimit) return "it has fewer than 500 faces";
  return {};
}

double chordDeviationPx(const subdiv::LimitSurface& surface, const Camera& camera) {
  const Far::TopologyLevel& base = surface.baseLevel();
  const std::vector<Vec3>& limit = surface.controlLimitPositions();
  auto pixels = [&](const Vec3& flat, const Vec3& onSurface) {
    const double depth = camera.depthOf(onSurface);
    if (depth <= camera.nearPlane()) return 0.0;  // behind the eye or clipped away
    return length(flat - onSurface) * camera.pixelsPerUnit(depth);
  };
  double worst = 0;
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!surface.hasLimit(f)) continue;
    Far::ConstIndexArray verts = base.GetFaceVertices(f);
    const int n = verts.size();
    const auto param = surface.parameterization(f);
    Vec3 mean{0, 0, 0};
    for (int v : verts) mean += limit[v];
    mean = mean / static_cast<double>(n);
    double uv[2];
    param.GetCenterCoord(uv);
    worst = std::max(worst, pixels(mean, surface.position(f, uv[0], uv[1])));
    for (int k = 0; k < n; ++k) {
      param.GetEdgeCoord(k, 0.5, uv);
      Vec3 chord = (limit[verts[k]] + limit[verts[(k + 1) % n]]) * 0.5;
      worst = std::max(worst, pixels(chord, surface.position(f, uv[0], uv[1])));
    }
  }
  return worst;
}

mesh::ControlMesh refineOnce(const mesh::ControlMesh& mesh) {
  subdiv::LimitSurface probe(mesh);
  std::unique_ptr<Far::TopologyRefiner> refiner = probe.createRefiner();
  Far::TopologyRefiner::UniformOptions options(1);
  options.fullTopologyInLastLevel = true;
  refiner->RefineUniform(options);
  const Far::TopologyLevel& fine = refiner->GetLevel(1);

  std::vector<subdiv::FarPoint> coarsePoints(mesh.points.size());
  for (size_t i = 0; i < mesh.points.size(); ++i) coarsePoints[i].p = mesh.points[i];
  std::vector<subdiv::FarPoint> finePoints(fine.GetNumVertices());
  subdiv::FarPoint* src = coarsePoints.data();
  subdiv::FarPoint* dst = finePoints.data();
  Far::PrimvarRefiner(*refiner).Interpolate(1, src, dst);

  mesh::ControlMesh out;
  out.scheme = mesh.scheme;
  out.boundary = mesh.boundary;
  out.creaseMethod = mesh.creaseMethod;
  out.triangleSubdivision = mesh.triangleSubdivision;
  out.points.reserve(finePoints.size());
  for (const subdiv::FarPoint& p : finePoints) out.points.push_back(p.p);
  for (int f = 0; f < fine.GetNumFaces(); ++f) {
    Far::ConstIndexArray verts = fine.GetFaceVertices(f);
    out.faceVertexCounts.push_back(verts.size());
    for (int v : verts) out.faceVertexIndices.push_back(v);
    if (fine.IsFaceHole(f)) out.holes.push_back(f);
  }
  for (int e = 0; e < fine.GetNumEdges(); ++e) {
    float sharpness = fine.GetEdgeSharpness(e);
    if (sharpness <= 0) continue;
    Far::ConstIndexArray ends = fine.GetEdgeVertices(e);
    out.creases.push_back({ends[0], ends[1], sharpness});
  }
  for (int v = 0; v < fine.GetNumVertices(); ++v) {
    float sharpness = fine.GetVertexSharpness(v);
    if (sharpness > 0) out.corners.push_back({v, sharpness});
  }
  return out;
}

}  // namespace limn::render::silhouette
