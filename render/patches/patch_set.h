// PatchSet: a control mesh as OpenSubdiv's feature-adaptive patches (Far::PatchTable).
//
// Far refines the mesh only around what is not a regular B-spline (Catmull-Clark) or box-spline
// (Loop) patch: extraordinary vertices, semi-sharp creases, irregular boundaries. Each level of
// isolation halves the irregular region, so the patch count grows with the mesh's features,
// not 4x per level as uniform refinement does. What stays irregular at the isolation level is
// closed by Gregory end caps. Infinitely sharp edges become patch boundaries.
//
// The topology, refiner, patch table and the stencils that map control points to every patch
// point are built once; setControlPoints() re-evaluates only the points (animation frames).
#pragma once

#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/stencilTable.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "render/core/cancel.h"
#include "render/core/vec.h"
#include "render/mesh/control_mesh.h"
#include "render/subdiv/displacement.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::patches {

// What a patch is, for stats and the "patches" image: a regular B-spline / box-spline patch,
// one bounded by a mesh boundary, one bounded by an infinitely sharp crease, or an irregular
// Gregory end cap.
enum class PatchKind { Regular, Boundary, Crease, Irregular };
inline constexpr int kPatchKinds = 4;
const char* patchKindName(PatchKind kind);

// The default isolation: Bfr's (subdiv::kApproxLevel), so the patches are the limit surface the
// reference draws; lower levels approximate it near extraordinary vertices, semi-sharp creases
// and sharp corners (bench/patches_results.md). And the most a request may ask for.
inline constexpr int kDefaultIsolation = 6;
inline constexpr int kMaxIsolation = 8;
// On meshes with a spike (subdiv::facesAtSpikes), sharp features are isolated deeper than
// smooth ones, as Bfr does there (subdiv::kApproxLevelSharp says why): at the default isolation
// to Bfr's spike level, elsewhere as many levels deeper, up to the deepest Far supports. Far
// isolates every sharp feature of the mesh so, not only the spikes (Bfr only those: other sharp
// features of such a mesh come out more exact than the reference's). Not on meshes with
// non-manifold edges: there Far isolates whole sharp creases, and each level doubles their
// patches (a corpus mesh took 33 s and exceeded the limits at level 10).
int sharpIsolation(const OpenSubdiv::Far::TopologyLevel& base, int isolation);

struct Patch {
  OpenSubdiv::Far::PatchTable::PatchHandle handle;
  // REGULAR (16 points), GREGORY_BASIS (20), LOOP (12) or GREGORY_TRIANGLE (18).
  OpenSubdiv::Far::PatchDescriptor::Type type = OpenSubdiv::Far::PatchDescriptor::REGULAR;
  OpenSubdiv::Far::PatchParam param;
  int baseFace = 0;
  int subFace = -1;  // the Ptex sub-face of a Catmull-Clark n-gon, -1 for quads and triangles
  int faceSize = 4;  // corners of the base face
  int depth = 0;     // refinement level of the patch (0: a regular base face)
  PatchKind kind = PatchKind::Regular;
  bool triangle = false;  // Loop: the unit triangle; Catmull-Clark: the unit square
  // A regular B-spline or box-spline patch without boundary, undisplaced: its points bound it
  // and their differences bound its derivatives (the back-patch cone test).
  bool cullable = false;
  // Its points are convex combinations of its control points (every patch but those with a
  // boundary edge, whose extrapolated phantom points give some points negative weights).
  bool inHull = false;
};

struct PatchTableStats {
  int isolation = 0;
  size_t patches = 0;
  // Patches per depth (index) and kind (regular, boundary, crease, irregular).
  std::vector<std::array<size_t, kPatchKinds>> byLevel;
  size_t refinedPoints = 0, endCapPoints = 0;
  double buildMs = 0;
};

class PatchSet {
 public:
  // Throws InputError(InvalidMesh) when OpenSubdiv rejects the topology; checks `cancel`
  // between the stages.
  // `displacement` (resolved against the mesh's bounds, kept for every frame) moves every
  // evaluated point along the patch normal; no patch is then culled for facing away.
  PatchSet(const mesh::ControlMesh& mesh, int isolation, const CancelToken& cancel,
           const subdiv::DisplacementSpec& displacement = {});
  ~PatchSet();
  PatchSet(const PatchSet&) = delete;
  PatchSet& operator=(const PatchSet&) = delete;

  // New positions of the same control points (one animation frame): refined and end-cap points
  // are recomputed from the stencils, nothing else. Throws std::invalid_argument on a size
  // mismatch.
  void setControlPoints(const std::vector<Vec3>& points);

  const std::vector<Patch>& patches() const { return patches_; }
  const PatchTableStats& stats() const { return stats_; }
  mesh::Scheme scheme() const { return scheme_; }
  // Per base face, which side of it is hidden when seen from outside its piece: +1 / -1 on a
  // closed piece wound outward / inward, 0 on an open one (subdiv/closed_pieces.h). Decided
  // from the control points the set was made with (setControlPoints keeps it).
  int hiddenSide(int baseFace) const { return hiddenSide_[baseFace]; }
  // The control points' bounds, widened by the displacement's reach: they hold the whole
  // surface (its points are convex combinations of the control points, then displaced).
  const Bounds& controlBounds() const { return controlBounds_; }
  // How far displacement may move a point off the patches' hull (0: not displaced).
  double displacementReach() const { return displacement_.reach(); }
  const subdiv::Displacement& displacement() const { return displacement_; }

  // Position and first derivatives at patch-local (s, t): [0,1]^2, or the unit triangle; of the
  // displaced surface when there is a displacement.
  void evaluate(const Patch& patch, double s, double t, Vec3& position, Vec3& ds, Vec3& dt) const;
  // The patch's local (s, t) in its Ptex face's coordinates (a sub-face's for n-gons).
  Vec2 toPtex(const Patch& patch, double s, double t) const;
  // The patch's local (s, t) as Bfr's (u, v) on its base face (subdiv::LimitSurface's).
  Vec2 toFaceUV(const Patch& patch, double s, double t) const;
  // The patch's control points (any type).
  std::vector<Vec3> controlPoints(const Patch& patch) const;
  // Where they are in points().
  OpenSubdiv::Far::ConstIndexArray pointIndices(const Patch& patch) const;
  // Control, refined and end-cap points, as the patch table indexes them (for the GPU).
  const std::vector<Vec3>& points() const { return points_; }

 private:
  mesh::Scheme scheme_;
  std::vector<int8_t> hiddenSide_;
  Bounds controlBounds_;
  size_t controlPoints_ = 0;
  subdiv::Displacement displacement_;
  std::unique_ptr<OpenSubdiv::Far::PatchTable> table_;
  std::unique_ptr<const OpenSubdiv::Far::StencilTableReal<double>> stencils_;
  std::vector<Vec3> points_;  // control, refined and end-cap points, as the table indexes them
  std::vector<Patch> patches_;
  PatchTableStats stats_;

  void evaluateUndisplaced(const Patch& patch, Vec2 ptex, Vec3& position, Vec3& ds, Vec3& dt) const;
  subdiv::SurfaceJet evaluateJet(const Patch& patch, Vec2 ptex) const;
};

}  // namespace limn::render::patches
