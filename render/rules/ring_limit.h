// RingLimit: the limit masks of one vertex from its ordered one-ring (limit.h describes the
// masks), shared by limitOf() over a Topology and the halfedge levels' limit (halfedge_level.h),
// which read their rings differently. Internal to render/rules.
#pragma once

#include <cstdint>
#include <vector>

#include "render/core/vec.h"
#include "render/mesh/control_mesh.h"
#include "render/rules/sharpness.h"

namespace limn::render::rules {

struct Tangents {
  Vec3 t1{0, 0, 0}, t2{0, 0, 0};
};

inline Vec3 unitCross(const Tangents& t) { return normalize(cross(t.t1, t.t2)); }

// The weights of the interior tangents at valence n, computed once per valence.
struct SmoothWeights {
  std::vector<double> cosines, sines;  // cos(2 pi i / n), sin(2 pi i / n)
  double faceScale = 0;                // Catmull-Clark: 1 / (4 lambda - 1)
};

// The smooth-tangent weights at valence n (Catmull-Clark and Loop share the cosines).
SmoothWeights smoothWeightsOf(int n);

// One side of a vertex: the ends of its edges E[0..m] and, for Catmull-Clark, the corners
// diagonal to the vertex in its faces F[0..m-1] (face i between edges i and i+1), in
// counter-clockwise order. Used for the two sides of a crease and the whole of a boundary.
struct Side {
  Vec3 v;
  std::vector<Vec3> E, F;
};

class RingLimit {
 public:
  explicit RingLimit(mesh::Scheme scheme);

  // The ring, in orderedRing() order (topology.h), filled by the caller before evaluate():
  Vec3 v;                      // the vertex
  std::vector<Vec3> E;         // the far end of each ring edge
  std::vector<Vec3> F;         // Catmull-Clark: the corner of each ring face diagonal to v
  std::vector<uint8_t> sharp;  // per ring edge: sharp at this level
  bool boundary = false;

  // The vertex's limit under `rule` (currentRule()): its position, tangents and the normal of
  // each ring face's side.
  void evaluate(Rule rule);
  Vec3 position;
  Tangents tangents;
  std::vector<Vec3> faceNormals;

 private:
  int faceCount() const { return static_cast<int>(F.size()); }
  // E[i] on a whole ring, where E[faces] is E[0] again.
  const Vec3& edgeEnd(int i) const { return E[i % E.size()]; }
  void cornerSides();
  void creaseSides();
  void smooth();
  const SmoothWeights& weights(int n);

  mesh::Scheme scheme_;
  Side side_;
  std::vector<SmoothWeights> weights_;
};

}  // namespace limn::render::rules
