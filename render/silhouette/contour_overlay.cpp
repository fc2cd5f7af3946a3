#include "render/silhouette/contour_overlay.h"

namespace limn::render::silhouette {

namespace Far = OpenSubdiv::Far;

namespace {

using Color = std::array<uint8_t, 4>;
constexpr Color kFront{60, 170, 60, 255}, kBack{70, 100, 220, 255}, kMixed{240, 200, 0, 255},
    kCorrected{250, 140, 0, 255}, kContour{230, 20, 20, 255};

void addSegment(LineOverlay& overlay, const Vec3f& a, const Vec3f& b, const Color& color) {
  overlay.points.push_back(a);
  overlay.points.push_back(b);
  overlay.colors.push_back(color);
}

}  // namespace

LineOverlay contourOverlay(const subdiv::LimitSurface& surface, const SilhouetteMesh& built,
                           const std::string& pass) {
  LineOverlay overlay;
  overlay.pass = pass;
  const Far::TopologyLevel& base = surface.baseLevel();
  const std::vector<Vec3>& limit = surface.controlLimitPositions();
  const mesh::ControlMesh& cage = surface.mesh();

  // Facing of each vertex as its first face sees it.
  std::vector<int> facing(cage.vertexCount(), 0);
  for (size_t i = 0; i < built.search.cornerG.size(); ++i) {
    int v = cage.faceVertexIndices[i];
    if (facing[v] == 0) facing[v] = built.search.cornerG[i] < 0 ? -1 : 1;
  }
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    Far::ConstIndexArray ends = base.GetEdgeVertices(e);
    int a = facing[ends[0]], b = facing[ends[1]];
    const Color& color = a != b ? kMixed : (a < 0 ? kFront : kBack);
    addSegment(overlay, Vec3f(limit[ends[0]]), Vec3f(limit[ends[1]]), color);
  }

  const tessellate::TriangleMesh& mesh = built.mesh;
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    if (!built.corrected[mesh.triangleFaces[t]]) continue;
    for (int k = 0; k < 3; ++k) {
      addSegment(overlay, mesh.positions[mesh.indices[3 * t + k]],
                 mesh.positions[mesh.indices[3 * t + (k + 1) % 3]], kCorrected);
    }
  }
  for (const ContourCurve& curve : built.curves) {
    for (size_t i = 0; i + 1 < curve.points.size(); ++i) {
      addSegment(overlay, Vec3f(curve.points[i].position), Vec3f(curve.points[i + 1].position),
                 kContour);
    }
  }
  return overlay;
}

}  // namespace limn::render::silhouette
