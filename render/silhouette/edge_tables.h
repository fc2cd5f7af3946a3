// Edge tables: the limit curve of a control edge, and the limit normal along it, as fixed
// weighted sums of the edge's support points (the seed method's way of evaluating an edge).
//
// In a smooth region the limit surface along an edge depends only on the 1-rings of its two
// ends: 2n + 4 points for Catmull-Clark and n + 4 for Loop, when one end has valence n and the
// other is regular. The weights of those points at t = k / kEdgeTableSteps are found once per
// scheme and valence by unit impulses: a canonical local mesh with that configuration is built,
// each of its points in turn carries the value 1 (all at once, as the coordinates of an identity
// matrix), and Bfr evaluates the limit along the edge, so each point's response is its column of
// weights. The tables therefore reproduce LimitSurface's own Bfr evaluation, rounding aside.
//
// At use, gatherEdgeSupport() collects an edge's support points in the canonical order (the
// order the tables were made in: it is the same walk, run on the canonical mesh), or says the
// edge is not eligible: a crease, corner, boundary, hole or non-manifold vertex in its support,
// a face around an end that is not a quad (Catmull-Clark) or triangle (Loop), both ends
// extraordinary, or a valence outside [kMinTableValence, kMaxTableValence]. Callers evaluate such
// edges with LimitSurface instead. EdgeCurve then sums the weights for one edge. The derivatives
// are those of the face in which A -> B runs forward; Bfr's normals from the edge's two faces
// agree to about 1e-12 rad, so one set serves both.
//
// The tables are built on first use of a scheme (a few milliseconds), after which everything is
// const and safe to share between threads.
#pragma once

#include <opensubdiv/far/topologyLevel.h>

#include <array>
#include <optional>
#include <vector>

#include "render/core/vec.h"
#include "render/mesh/control_mesh.h"

namespace limn::render::silhouette {

// The tables hold t = k / kEdgeTableSteps, k = 0 .. kEdgeTableSteps: every parameter the
// contour search's sampling and bisection reach (4 samples, 5 bisections: multiples of 1/128).
inline constexpr int kEdgeTableSteps = 128;
inline constexpr int kMinTableValence = 3;
inline constexpr int kMaxTableValence = 16;
inline constexpr int kMaxSupportPoints = 2 * kMaxTableValence + 4;

// An eligible edge's support in canonical order: A (the extraordinary end, or the edge's first
// vertex when both are regular), the vertices of A's faces in turn from the face in which A -> B
// runs forward ("left"), then the three vertices of B's 1-ring not already listed.
struct EdgeSupport {
  int valence = 0;        // of A
  bool reversed = false;  // A is the edge's second vertex: t runs from B to A
  int leftFace = -1;      // the face in which A -> B runs forward
  int rightFace = -1;     // the other face
  int count = 0;          // points used: 2n + 4 (Catmull-Clark) or n + 4 (Loop)
  std::array<int, kMaxSupportPoints> points{};
};

// Nothing when the edge is not eligible (see above).
std::optional<EdgeSupport> gatherEdgeSupport(const OpenSubdiv::Far::TopologyLevel& level,
                                             mesh::Scheme scheme, int edge);

struct EdgeSample {
  Vec3 position;
  Vec3 normal;  // unit, oriented like the face windings
};

// The weights of one scheme and valence: for each step, per support point the weights of the
// position and of the two derivatives in the left face's Bfr (u, v).
class EdgeTable {
 public:
  EdgeTable(mesh::Scheme scheme, int valence);

  int valence() const { return valence_; }
  int supportSize() const { return supportSize_; }
  // The largest response of a canonical-mesh point outside the support (0 up to rounding when
  // the support is what the tables assume; tests check it).
  double leakage() const { return leakage_; }
  // Weights {position, du, dv} of the support points at step k (from A), three per point.
  const double* weights(int k) const {
    return &weights_[static_cast<size_t>(k) * supportSize_ * 3];
  }

 private:
  int valence_;
  int supportSize_;
  double leakage_ = 0;
  std::vector<double> weights_;
};

class EdgeTables {
 public:
  // The tables of `scheme` (Catmull-Clark or Loop), built on the first call.
  static const EdgeTables& forScheme(mesh::Scheme scheme);
  static int regularValence(mesh::Scheme scheme) { return scheme == mesh::Scheme::Loop ? 6 : 4; }

  const EdgeTable& table(int valence) const { return tables_[valence - kMinTableValence]; }

 private:
  explicit EdgeTables(mesh::Scheme scheme);
  std::vector<EdgeTable> tables_;
};

// One edge's limit curve through the tables. Steps count from the edge's first vertex, like the
// contour search's t.
class EdgeCurve {
 public:
  EdgeCurve(const EdgeSupport& support, const std::vector<Vec3>& meshPoints, mesh::Scheme scheme);

  EdgeSample sample(int step) const;
  Vec3 position(int step) const;

 private:
  const EdgeTable& table_;
  bool reversed_;
  int count_;
  std::array<Vec3, kMaxSupportPoints> points_;
};

}  // namespace limn::render::silhouette
