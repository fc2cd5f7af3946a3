#include "render/silhouette/edge_tables.h"

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>

#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

namespace Bfr = OpenSubdiv::Bfr;
namespace Far = OpenSubdiv::Far;

namespace {

// ---- Gathering an edge's support ----

int faceSizeOf(mesh::Scheme scheme) { return scheme == mesh::Scheme::Loop ? 3 : 4; }

// A face around a vertex, and the vertex's position in it.
struct Corner {
  int face = -1;
  int local = -1;
};

struct Ring {
  int count = 0;
  std::array<Corner, kMaxTableValence> corners;
};

int localIndex(Far::ConstIndexArray vertices, int vertex) {
  for (int i = 0; i < vertices.size(); ++i) {
    if (vertices[i] == vertex) return i;
  }
  return -1;
}

// The faces around interior vertex `v` in the order of their windings, starting with `start`:
// each next face lies across the edge that enters v in the one before. False when the walk does
// not close after exactly `valence` faces (a non-manifold or inconsistently wound fan).
bool walkAround(const Far::TopologyLevel& level, int v, int start, int valence, Ring& ring) {
  int face = start;
  ring.count = 0;
  while (ring.count < valence) {
    Far::ConstIndexArray vertices = level.GetFaceVertices(face);
    const int local = localIndex(vertices, v);
    if (local < 0) return false;
    ring.corners[ring.count++] = {face, local};
    const int size = vertices.size();
    const int entering = level.GetFaceEdges(face)[(local + size - 1) % size];
    Far::ConstIndexArray across = level.GetEdgeFaces(entering);
    if (across.size() != 2) return false;
    face = across[0] == face ? across[1] : across[0];
    if (face == start) return ring.count == valence;
  }
  return false;
}

// The vertices of the ring's faces after v in each winding, less each face's last one (the
// next face's first): for quads an edge neighbour and a diagonal one per face, for triangles
// an edge neighbour.
int ringVertices(const Far::TopologyLevel& level, const Ring& ring, int* out) {
  int count = 0;
  for (int i = 0; i < ring.count; ++i) {
    Far::ConstIndexArray vertices = level.GetFaceVertices(ring.corners[i].face);
    const int size = vertices.size();
    for (int j = 1; j + 1 < size; ++j) out[count++] = vertices[(ring.corners[i].local + j) % size];
  }
  return count;
}

// No tag, boundary or non-manifold topology at the vertex, and valence 3 or more (faces around
// an interior valence-2 vertex are evaluated through Far's patches, not Bfr).
bool isSmoothVertex(const Far::TopologyLevel& level, int v) {
  return !level.IsVertexBoundary(v) && !level.IsVertexNonManifold(v) &&
         level.GetVertexSharpness(v) == 0.0f && level.GetVertexEdges(v).size() >= 3;
}

// Every face of the ring has the scheme's size, is no hole, and has only smooth edges. (Its
// vertices are the support points, checked once each.)
bool isSmoothRing(const Far::TopologyLevel& level, const Ring& ring, int faceSize) {
  for (int i = 0; i < ring.count; ++i) {
    const int face = ring.corners[i].face;
    if (level.IsFaceHole(face) || level.GetFaceVertices(face).size() != faceSize) return false;
    for (int e : level.GetFaceEdges(face)) {
      if (level.GetEdgeSharpness(e) != 0.0f || level.IsEdgeNonManifold(e)) return false;
    }
  }
  return true;
}

bool allDistinct(const int* points, int count) {
  std::array<int, kMaxSupportPoints> sorted;
  std::copy(points, points + count, sorted.begin());
  std::sort(sorted.begin(), sorted.begin() + count);
  return std::adjacent_find(sorted.begin(), sorted.begin() + count) == sorted.begin() + count;
}

// ---- The canonical mesh ----

// Vertex a of valence n in the middle of n sectors, each a grid of `kSectorSize` rings of quads
// (Catmull-Clark) or triangles (Loop), so that every vertex within two rings of the middle is
// interior and regular. Sector i runs from ray i (its b = 0 side) to ray i + 1 (a = 0), so the
// middle's edge to (1, 0) of sector 0 is the table's edge A -> B.
constexpr int kSectorSize = 3;

class CanonicalMesh {
 public:
  CanonicalMesh(mesh::Scheme scheme, int valence) : valence_(valence) {
    mesh_.scheme = scheme;
    id(0, 0, 0);
    for (int sector = 0; sector < valence; ++sector) {
      for (int a = 0; a < kSectorSize; ++a) {
        for (int b = 0; b < kSectorSize; ++b) {
          if (scheme == mesh::Scheme::Loop) {
            addLoopCell(sector, a, b);
          } else {
            addFace({id(sector, a, b), id(sector, a + 1, b), id(sector, a + 1, b + 1),
                     id(sector, a, b + 1)});
          }
        }
      }
    }
    mesh_.points.resize(ids_.size());  // geometry is irrelevant: only impulses are evaluated
  }

  const mesh::ControlMesh& mesh() const { return mesh_; }
  int middle() const { return 0; }
  int firstNeighbour() { return id(0, 1, 0); }

 private:
  void addLoopCell(int sector, int a, int b) {
    if (a + b >= kSectorSize) return;
    addFace({id(sector, a, b), id(sector, a + 1, b), id(sector, a, b + 1)});
    if (a + b + 1 < kSectorSize) {
      addFace({id(sector, a + 1, b), id(sector, a + 1, b + 1), id(sector, a, b + 1)});
    }
  }

  void addFace(std::initializer_list<int> vertices) {
    mesh_.faceVertexCounts.push_back(static_cast<int>(vertices.size()));
    mesh_.faceVertexIndices.insert(mesh_.faceVertexIndices.end(), vertices);
  }

  // The vertex at (a, b) of a sector; ray i + 1 (a = 0) is the next sector's b = 0 side.
  int id(int sector, int a, int b) {
    if (a == 0 && b == 0) sector = 0;
    if (a == 0 && b > 0) std::tie(sector, a, b) = std::make_tuple((sector + 1) % valence_, b, 0);
    auto [it, inserted] = ids_.try_emplace({sector, a, b}, static_cast<int>(ids_.size()));
    return it->second;
  }

  int valence_;
  mesh::ControlMesh mesh_;
  std::map<std::tuple<int, int, int>, int> ids_;
};

// Bfr's (u, v) of a face's corner.
Vec2 cornerCoord(const Bfr::Surface<double>& surface, int corner) {
  double uv[2];
  surface.GetParameterization().GetVertexCoord(corner, uv);
  return {uv[0], uv[1]};
}

}  // namespace

std::optional<EdgeSupport> gatherEdgeSupport(const Far::TopologyLevel& level, mesh::Scheme scheme,
                                             int edge) {
  if (scheme == mesh::Scheme::Bilinear) return std::nullopt;
  Far::ConstIndexArray faces = level.GetEdgeFaces(edge);
  if (faces.size() != 2 || level.IsEdgeNonManifold(edge) || level.IsEdgeBoundary(edge)) {
    return std::nullopt;
  }
  Far::ConstIndexArray ends = level.GetEdgeVertices(edge);
  if (!isSmoothVertex(level, ends[0]) || !isSmoothVertex(level, ends[1])) return std::nullopt;
  const int regular = EdgeTables::regularValence(scheme);
  const int valence0 = level.GetVertexFaces(ends[0]).size();
  const int valence1 = level.GetVertexFaces(ends[1]).size();
  if (valence0 != regular && valence1 != regular) return std::nullopt;

  EdgeSupport support;
  support.reversed = valence0 == regular && valence1 != regular;
  const int a = ends[support.reversed ? 1 : 0], b = ends[support.reversed ? 0 : 1];
  support.valence = support.reversed ? valence1 : valence0;
  if (support.valence < kMinTableValence || support.valence > kMaxTableValence) {
    return std::nullopt;
  }
  Far::ConstIndexArray first = level.GetFaceVertices(faces[0]);
  const int local = localIndex(first, a);
  const bool firstIsLeft = first[(local + 1) % first.size()] == b;
  support.leftFace = firstIsLeft ? faces[0] : faces[1];
  support.rightFace = firstIsLeft ? faces[1] : faces[0];

  const int faceSize = faceSizeOf(scheme);
  Ring ringA, ringB;
  if (!walkAround(level, a, support.leftFace, support.valence, ringA) ||
      !walkAround(level, b, support.rightFace, regular, ringB) ||
      !isSmoothRing(level, ringA, faceSize) || !isSmoothRing(level, ringB, faceSize)) {
    return std::nullopt;
  }

  // A, then A's ring (its first entry is B), then what B's ring adds. B's ring starts in the
  // right face: A, then A's last edge neighbour (and, for quads, A's last diagonal); it ends on
  // A's first diagonal and second edge neighbour (quads) or second edge neighbour (triangles).
  int* points = support.points.data();
  points[0] = a;
  const int ringSizeA = ringVertices(level, ringA, points + 1);
  std::array<int, 2 * kMaxTableValence> fromB;
  const int ringSizeB = ringVertices(level, ringB, fromB.data());
  const int leading = faceSize == 4 ? 3 : 2, trailing = faceSize == 4 ? 2 : 1;
  const int* aRing = points + 1;
  const bool ringsMeet = points[1] == b && fromB[0] == a &&
                         fromB[1] == aRing[ringSizeA - (faceSize - 2)] &&
                         (faceSize == 3 || fromB[2] == aRing[ringSizeA - 1]) &&
                         fromB[ringSizeB - 1] == aRing[faceSize - 2] &&
                         (faceSize == 3 || fromB[ringSizeB - 2] == aRing[1]);
  if (!ringsMeet) return std::nullopt;
  support.count = 1 + ringSizeA;
  for (int i = leading; i < ringSizeB - trailing; ++i) points[support.count++] = fromB[i];
  if (!allDistinct(points, support.count)) return std::nullopt;
  for (int i = 2; i < support.count; ++i) {
    if (!isSmoothVertex(level, points[i])) return std::nullopt;
  }
  return support;
}

EdgeTable::EdgeTable(mesh::Scheme scheme, int valence) : valence_(valence) {
  CanonicalMesh canonical(scheme, valence);
  std::unique_ptr<Far::TopologyRefiner> refiner = subdiv::createTopologyRefiner(canonical.mesh());
  const Far::TopologyLevel& level = refiner->GetLevel(0);
  const int edge = level.FindEdge(canonical.middle(), canonical.firstNeighbour());
  std::optional<EdgeSupport> support = gatherEdgeSupport(level, scheme, edge);
  if (!support || support->valence != valence) {
    throw std::logic_error("edge tables: the canonical edge of valence " + std::to_string(valence) +
                           " is not eligible");
  }
  supportSize_ = support->count;
  const int a = support->points[0], b = support->points[1];

  // Same options as LimitSurface, so that the responses are those of the surface it evaluates.
  Bfr::RefinerSurfaceFactory<>::Options options;
  options.SetApproxLevelSmooth(subdiv::kApproxLevel);
  options.SetApproxLevelSharp(subdiv::kApproxLevel);
  Bfr::RefinerSurfaceFactory<> factory(*refiner, options);

  // Point j of the mesh is the j-th unit vector: every coordinate of a result is one point's
  // response.
  const int n = level.GetNumVertices();
  std::vector<double> impulses(static_cast<size_t>(n) * n, 0.0);
  for (int j = 0; j < n; ++j) impulses[static_cast<size_t>(j) * n + j] = 1.0;
  const Bfr::Surface<double>::PointDescriptor unitVectors(n);

  std::vector<bool> inSupport(n, false);
  for (int j = 0; j < supportSize_; ++j) inSupport[support->points[j]] = true;

  // The left face's surface, with the impulses as its points.
  Bfr::Surface<double> surface;
  if (!factory.InitVertexSurface(support->leftFace, &surface) || !surface.IsValid()) {
    throw std::logic_error("edge tables: Bfr has no surface for the canonical face");
  }
  std::vector<double> patchPoints(static_cast<size_t>(surface.GetNumPatchPoints()) * n);
  surface.PreparePatchPoints(impulses.data(), unitVectors, patchPoints.data(), unitVectors);
  Far::ConstIndexArray corners = level.GetFaceVertices(support->leftFace);
  const Vec2 from = cornerCoord(surface, localIndex(corners, a));
  const Vec2 to = cornerCoord(surface, localIndex(corners, b));

  weights_.assign(static_cast<size_t>(kEdgeTableSteps + 1) * supportSize_ * 3, 0.0);
  std::vector<double> p(n), du(n), dv(n);
  for (int k = 0; k <= kEdgeTableSteps; ++k) {
    const double t = static_cast<double>(k) / kEdgeTableSteps;
    const double uv[2] = {from.x + (to.x - from.x) * t, from.y + (to.y - from.y) * t};
    surface.Evaluate(uv, patchPoints.data(), unitVectors, p.data(), du.data(), dv.data());
    double* w = &weights_[static_cast<size_t>(k) * supportSize_ * 3];
    for (int j = 0; j < supportSize_; ++j) {
      const int point = support->points[j];
      w[3 * j] = p[point];
      w[3 * j + 1] = du[point];
      w[3 * j + 2] = dv[point];
    }
    for (int j = 0; j < n; ++j) {
      if (inSupport[j]) continue;
      leakage_ = std::max({leakage_, std::fabs(p[j]), std::fabs(du[j]), std::fabs(dv[j])});
    }
  }
}

EdgeTables::EdgeTables(mesh::Scheme scheme) {
  for (int valence = kMinTableValence; valence <= kMaxTableValence; ++valence) {
    tables_.emplace_back(scheme, valence);
  }
}

const EdgeTables& EdgeTables::forScheme(mesh::Scheme scheme) {
  // Function-local statics: each built once, on its first use, safely across threads.
  if (scheme == mesh::Scheme::Loop) {
    static const EdgeTables loop(mesh::Scheme::Loop);
    return loop;
  }
  static const EdgeTables catmullClark(mesh::Scheme::CatmullClark);
  return catmullClark;
}

EdgeCurve::EdgeCurve(const EdgeSupport& support, const std::vector<Vec3>& meshPoints,
                     mesh::Scheme scheme)
    : table_(EdgeTables::forScheme(scheme).table(support.valence)),
      reversed_(support.reversed),
      count_(support.count) {
  for (int j = 0; j < count_; ++j) points_[j] = meshPoints[support.points[j]];
}

EdgeSample EdgeCurve::sample(int step) const {
  const double* w = table_.weights(reversed_ ? kEdgeTableSteps - step : step);
  Vec3 position, du, dv;
  for (int j = 0; j < count_; ++j, w += 3) {
    position += w[0] * points_[j];
    du += w[1] * points_[j];
    dv += w[2] * points_[j];
  }
  return {position, normalize(cross(du, dv))};
}

Vec3 EdgeCurve::position(int step) const {
  const double* w = table_.weights(reversed_ ? kEdgeTableSteps - step : step);
  Vec3 position;
  for (int j = 0; j < count_; ++j, w += 3) position += w[0] * points_[j];
  return position;
}

}  // namespace limn::render::silhouette
