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
