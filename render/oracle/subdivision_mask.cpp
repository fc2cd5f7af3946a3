// embreeSubdivisionMask: the second, independent reference of coverage. Embree tessellates the
// Catmull-Clark limit surface itself (its own patch evaluation, its own grids), so where this
// mask and the dense-tessellation mask agree, both are right to within their grids.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "render/oracle/embree_device.h"
#include "render/oracle/ray_caster.h"
#include "render/oracle/reference.h"
#include "render/oracle/surface_probe.h"

namespace limn::render::oracle {

namespace Far = OpenSubdiv::Far;

namespace {

// Embree's subdivision faces have 3 to 15 vertices.
constexpr int kEmbreeMaxFaceSize = 15;
// Edge levels: Embree dices each edge into `level` segments, 1 to 4096.
constexpr float kMaxLevel = 4096.0f;
// Embree's grid: chord error and longest piece, in pixels of the camera it is given (the
// supersampled one when used for masks), and the most grid points it may make.
constexpr double kChordErrorPx = 0.02;
constexpr double kMaxGridPx = 8.0;
constexpr double kMaxGridPoints = 32e6;
// Offsets of the rays that tell a crack from a hole, in pixels: the near ones first; cracks
// where several patch grids meet can be wider than them (measured on the 1,000-face torus at
// 1024^2 x 4: isolated pinholes deep inside the surface, read as a 20-80 px Hausdorff
// "disagreement"), hence a second ring at a quarter pixel.
constexpr double kCrackProbesPx[] = {0.05, 0.25};

// Why Embree cannot represent this mesh as OpenSubdiv subdivides it, or "" when it can.
std::string unsupportedReason(const subdiv::LimitSurface& surface) {
  const mesh::ControlMesh& m = surface.mesh();
  if (surface.displaced()) return "Embree's subdivision geometry is drawn without displacement";
  if (m.scheme != mesh::Scheme::CatmullClark) {
    return std::string("Embree subdivision geometry is Catmull-Clark only; the mesh is ") +
           mesh::schemeName(m.scheme);
  }
  if (m.creaseMethod == mesh::CreaseMethod::Chaikin) {
    for (const mesh::Crease& c : m.creases) {
      if (c.sharpness > 0 && c.sharpness < mesh::kInfiniteSharpness) {
        return "Embree has only the uniform crease rule; the mesh asks for Chaikin creases";
      }
    }
  }
  for (int f = 0; f < m.faceCount(); ++f) {
    int size = m.faceVertexCounts[f];
    if (size == 3 && m.triangleSubdivision == mesh::TriangleSubdivision::Smooth) {
      return "Embree has no smooth triangle subdivision rule; the mesh asks for it (face " +
             std::to_string(f) + ")";
    }
    if (size > kEmbreeMaxFaceSize) {
      return "Embree takes faces of at most 15 vertices; face " + std::to_string(f) + " has " +
             std::to_string(size);
    }
  }
  // Measured against Far's limit: Embree matches OpenSubdiv on semi-sharp creases only where
  // all the creases at a vertex have one sharpness, and not at semi-sharp corners (there its
  // surface is off by 2-15% of the model size), so those meshes cannot be cross-checked.
  for (const mesh::Corner& c : m.corners) {
    if (c.sharpness > 0 && c.sharpness < mesh::kInfiniteSharpness) {
      return "Embree's semi-sharp corner rule differs from OpenSubdiv's (vertex " +
             std::to_string(c.vertex) + ")";
    }
  }
  const Far::TopologyLevel& base = surface.baseLevel();
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    float lo = INFINITY, hi = 0;
    bool semiSharp = false;
    for (int e : base.GetVertexEdges(v)) {
      float s = base.GetEdgeSharpness(e);
      if (s <= 0) continue;
      lo = std::min(lo, s);
      hi = std::max(hi, s);
      semiSharp = semiSharp || s < mesh::kInfiniteSharpness;
    }
    if (semiSharp && lo != hi) {
      return "Embree's rule where creases of different sharpness meet differs from "
             "OpenSubdiv's (vertex " +
             std::to_string(v) + ")";
    }
  }
  // Measured on a grid with one lifted interior vertex of valence 2: Embree's surface there is
  // 234 px (at 1024^2) from OpenSubdiv's, whose uniform refinement agrees with the reference.
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    if (base.GetVertexEdges(v).size() == 2 && !base.IsVertexBoundary(v) &&
        !base.IsVertexNonManifold(v)) {
      return "Embree's rule at interior vertices of valence 2 differs from OpenSubdiv's (vertex " +
             std::to_string(v) + ")";
    }
  }
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    if (base.IsEdgeNonManifold(e)) {
      Far::ConstIndexArray v = base.GetEdgeVertices(e);
      return "Embree treats non-manifold topology differently from OpenSubdiv; edge " +
             std::to_string(v[0]) + "-" + std::to_string(v[1]) + " is non-manifold";
    }
  }
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    if (base.IsVertexNonManifold(v)) {
      return "Embree treats non-manifold topology differently from OpenSubdiv; vertex " +
             std::to_string(v) + " is non-manifold";
    }
  }
  return "";
}

// Embree makes every border edge infinitely sharp in all modes, as OpenSubdiv's EdgeOnly does;
// PIN_CORNERS also pins valence-2 boundary vertices, as EdgeAndCorner does. For None, OpenSubdiv
// removes the faces at boundary vertices but keeps them as support for their neighbours: the
// surface of the remaining faces does not depend on the boundary rule, so Embree gets the smooth
// boundary (its border edges infinitely sharp, as Far sharpens them in None too) and the excluded
// faces are hidden (see hiddenFaces).
RTCSubdivisionMode subdivisionMode(mesh::BoundaryInterpolation boundary) {
  return boundary == mesh::BoundaryInterpolation::EdgeAndCorner
             ? RTC_SUBDIVISION_MODE_PIN_CORNERS
             : RTC_SUBDIVISION_MODE_SMOOTH_BOUNDARY;
}

// Faces OpenSubdiv renders no surface for but keeps in the topology: holes, and with boundary
// None every face at a boundary vertex that has a boundary edge not tagged infinitely sharp
// (Far's rule). Embree's own holes (RTC_BUFFER_TYPE_HOLE) would instead cut the mesh, turning
// the hole's edges into boundaries and changing the neighbouring surface, so these faces stay in
// Embree's mesh and an occlusion filter ignores hits on them.
std::vector<char> hiddenFaces(const subdiv::LimitSurface& surface) {
  const mesh::ControlMesh& m = surface.mesh();
  std::vector<char> hidden(m.faceCount(), 0);
  for (int f : m.holes) hidden[f] = 1;
  if (m.boundary != mesh::BoundaryInterpolation::None) return hidden;
  std::set<std::pair<int, int>> sharp;
  for (const mesh::Crease& c : m.creases) {
    if (c.sharpness >= mesh::kInfiniteSharpness) sharp.insert(std::minmax(c.v0, c.v1));
  }
  const Far::TopologyLevel& base = surface.baseLevel();
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    if (base.GetEdgeFaces(e).size() != 1) continue;
    Far::ConstIndexArray ends = base.GetEdgeVertices(e);
    if (sharp.count(std::minmax(ends[0], ends[1]))) continue;
    for (int v : ends) {
      for (int f : base.GetVertexFaces(v)) hidden[f] = 1;
    }
  }
  return hidden;
}

void skipHiddenFaces(const RTCFilterFunctionNArguments* args) {
  const char* hidden = static_cast<const char*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != 0 && hidden[RTCHitN_primID(args->hit, args->N, i)]) args->valid[i] = 0;
  }
}

float embreeSharpness(float s) { return s >= mesh::kInfiniteSharpness ? INFINITY : s; }

// Embree's one tessellation level for all edges (see the caller): enough segments for every edge
// to keep its chords within kChordErrorPx of the surface (surface_probe.h; 3D lengths, so edges
// running towards the viewer at the silhouette are not under-sampled), and pieces of at most
// kMaxGridPx, capped so that the grids stay within kMaxGridPoints. (A grid of 0.5 px everywhere,
// the first plan, took a minute at 1024^2 x 4 on a 1000-face mesh: Embree builds every grid up
// front.)
float uniformLevel(const subdiv::LimitSurface& surface, const Camera& camera) {
  double level = 1, patches = 0;
  for (int f = 0; f < surface.faceCount(); ++f) {
    int size = surface.mesh().faceVertexCounts[f];
    patches += size == 4 ? 1 : size;  // Embree splits other faces into quads
  }
  for (const FaceProbe& probe : probeFaces(surface, camera)) {
    for (size_t k = 0; k < probe.segmentsAtOnePixel.size(); ++k) {
      level = std::max({level, probe.segmentsAtOnePixel[k] / std::sqrt(kChordErrorPx),
                        probe.lengthPx[k] / kMaxGridPx});
    }
  }
  double cap = std::sqrt(kMaxGridPoints / std::max(patches, 1.0));
  return static_cast<float>(std::clamp(std::ceil(level), 1.0, std::min(cap, double(kMaxLevel))));
}

// Embree's grids of neighbouring patches are evaluated separately and can leave cracks of zero
// width between them, through which an occasional ray slips (measured: one pixel in 10^5 on an
// open 3-face mesh). A missed pixel whose four neighbours are covered is cast again at eight
// points kCrackProbesPx around its centre, along the axes and the diagonals: a crack is a line,
// which passes through at most two opposite probes, so six or more hits make it a crack and the
// pixel covered; a hole in the surface has area and gets none.
void closeCracks(RTCScene scene, const Camera& camera, Mask& mask, const CancelToken& cancel) {
  constexpr int kProbes = 8, kHitsForACrack = 6;
  constexpr int kDirections[kProbes][2] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1},
                                           {-1, 0},  {1, 0},  {0, -1}, {0, 1}};
  const int w = mask.width, h = mask.height;
  std::vector<std::pair<int, int>> suspects;
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      if (!mask.at(x, y) && mask.at(x - 1, y) && mask.at(x + 1, y) && mask.at(x, y - 1) &&
          mask.at(x, y + 1)) {
        suspects.emplace_back(x, y);
      }
    }
  }
  std::vector<Vec2> probes;
  std::vector<char> covered;
  for (double offset : kCrackProbesPx) {
    probes.clear();
    for (auto [x, y] : suspects) {
      for (const auto& d : kDirections)
        probes.push_back({x + 0.5 + d[0] * offset, y + 0.5 + d[1] * offset});
    }
    castCoverageAt(scene, camera, probes, covered, cancel);
    std::vector<std::pair<int, int>> stillOpen;
    for (size_t k = 0; k < suspects.size(); ++k) {
      int hits = 0;
      for (int i = 0; i < kProbes; ++i) hits += covered[k * kProbes + i];
      if (hits >= kHitsForACrack) {
        mask.at(suspects[k].first, suspects[k].second) = 1;
      } else {
        stillOpen.push_back(suspects[k]);
      }
    }
    suspects = std::move(stillOpen);
  }
}

template <typename T>
T* newBuffer(RTCGeometry g, RTCBufferType type, RTCFormat format, size_t count) {
  return static_cast<T*>(rtcSetNewGeometryBuffer(g, type, 0, format, sizeof(T), count));
}

}  // namespace

std::optional<Mask> embreeSubdivisionMask(const subdiv::LimitSurface& surface, const Camera& camera,
                                          const CancelToken& cancel, std::string* whyNot,
                                          int supersample, metrics::Outline* outline) {
  auto refuse = [&](std::string reason) -> std::optional<Mask> {
    if (whyNot) *whyNot = std::move(reason);
    return std::nullopt;
  };
  if (std::string reason = unsupportedReason(surface); !reason.empty()) return refuse(reason);

  const mesh::ControlMesh& m = surface.mesh();
  FlushDenormalsScope ftz;
  RTCDevice device = embreeDevice();
  takeEmbreeError();  // start clean: report only this mesh's errors
  EmbreeScene scene(rtcNewScene(device));
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SUBDIVISION);

  struct Float3 {
    float x, y, z;
  };
  auto* vertices = newBuffer<Float3>(g, RTC_BUFFER_TYPE_VERTEX, RTC_FORMAT_FLOAT3, m.points.size());
  auto* faces = newBuffer<unsigned>(g, RTC_BUFFER_TYPE_FACE, RTC_FORMAT_UINT, m.faceCount());
  auto* indices =
      newBuffer<unsigned>(g, RTC_BUFFER_TYPE_INDEX, RTC_FORMAT_UINT, m.faceVertexIndices.size());
  auto* levels =
      newBuffer<float>(g, RTC_BUFFER_TYPE_LEVEL, RTC_FORMAT_FLOAT, m.faceVertexIndices.size());
  if (!vertices || !faces || !indices || !levels) {
    rtcReleaseGeometry(g);
    return refuse("Embree could not allocate the subdivision mesh: " + takeEmbreeError());
  }
  for (size_t i = 0; i < m.points.size(); ++i) {
    vertices[i] = {static_cast<float>(m.points[i].x), static_cast<float>(m.points[i].y),
                   static_cast<float>(m.points[i].z)};
  }
  // One level for all edges: where a face's edges have different levels Embree stitches its grid
  // with T-junctions, and rays slip through the cracks (pinholes measured on an open grid).
  const float level = uniformLevel(surface, camera);
  size_t offset = 0;
  for (int f = 0; f < m.faceCount(); ++f) {
    int size = m.faceVertexCounts[f];
    faces[f] = static_cast<unsigned>(size);
    for (int k = 0; k < size; ++k) {
      indices[offset + k] = static_cast<unsigned>(m.faceVertexIndices[offset + k]);
    }
    offset += size;
  }
  std::fill(levels, levels + m.faceVertexIndices.size(), level);
  if (!m.creases.empty()) {
    auto* pairs = newBuffer<unsigned[2]>(g, RTC_BUFFER_TYPE_EDGE_CREASE_INDEX, RTC_FORMAT_UINT2,
                                         m.creases.size());
    auto* weights =
        newBuffer<float>(g, RTC_BUFFER_TYPE_EDGE_CREASE_WEIGHT, RTC_FORMAT_FLOAT, m.creases.size());
    for (size_t i = 0; pairs && weights && i < m.creases.size(); ++i) {
      pairs[i][0] = static_cast<unsigned>(m.creases[i].v0);
      pairs[i][1] = static_cast<unsigned>(m.creases[i].v1);
      weights[i] = embreeSharpness(m.creases[i].sharpness);
    }
  }
  if (!m.corners.empty()) {
    auto* ids = newBuffer<unsigned>(g, RTC_BUFFER_TYPE_VERTEX_CREASE_INDEX, RTC_FORMAT_UINT,
                                    m.corners.size());
    auto* weights = newBuffer<float>(g, RTC_BUFFER_TYPE_VERTEX_CREASE_WEIGHT, RTC_FORMAT_FLOAT,
                                     m.corners.size());
    for (size_t i = 0; ids && weights && i < m.corners.size(); ++i) {
      ids[i] = static_cast<unsigned>(m.corners[i].vertex);
      weights[i] = embreeSharpness(m.corners[i].sharpness);
    }
  }
  std::vector<char> hidden = hiddenFaces(surface);
  if (std::find(hidden.begin(), hidden.end(), 1) != hidden.end()) {
    rtcSetGeometryUserData(g, hidden.data());
    rtcSetGeometryOccludedFilterFunction(g, skipHiddenFaces);
    rtcSetGeometryIntersectFilterFunction(g, skipHiddenFaces);
  }
  rtcSetGeometrySubdivisionMode(g, 0, subdivisionMode(m.boundary));
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene.get(), g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene.get());
  if (std::string error = takeEmbreeError(); !error.empty()) {
    return refuse("Embree rejected the subdivision mesh: " + error);
  }
  cancel.check();
  Mask mask = castCoverage(scene.get(), camera, RayPacking::Packet16, cancel);
  closeCracks(scene.get(), camera, mask, cancel);
  if (outline) {
    // The outline's points are in output pixels; the rays go through the same points of the
    // supersampled camera.
    const double s = supersample;
    auto query = [&](const std::vector<Vec2>& points, std::vector<char>& covered) {
      std::vector<Vec2> fine(points.size());
      for (size_t k = 0; k < points.size(); ++k) fine[k] = {points[k].x * s, points[k].y * s};
      castCoverageAt(scene.get(), camera, fine, covered, cancel);
    };
    *outline = metrics::locateOutline(mask, supersample, query, cancel);
  }
  return mask;
}

}  // namespace limn::render::oracle
