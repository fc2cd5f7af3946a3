// LimitSurface: the smooth limit surface of a ControlMesh, through OpenSubdiv.
//
// Built once per request from a validated ControlMesh: Far holds the topology (with creases,
// corners, holes, boundary and crease rules), Bfr gives one Surface per face. The Far topology
// is made at construction; the per-face Bfr surfaces (most of the cost) by prepare(), which
// every accessor that needs them calls first, so a request that never evaluates the surface
// (uniform refinement without a reference) never pays for them. evaluate() is const and safe to
// call from many threads at once.
//
// Faces around an interior vertex of valence 2, whose Bfr patches OpenSubdiv 3.5.0 cannot build
// safely, are evaluated through Far's adaptive patch table instead (FarPatchSurface), in the
// same parameterisation; callers see no difference.
//
// Parameterisation is Bfr's: quads (u, v) in [0,1]^2, triangles (u, v) with u + v <= 1, and
// other faces of Catmull-Clark meshes tiled into quad sub-faces (see Bfr::Parameterization).
// The approximation levels Bfr uses near irregular features are fixed (kApproxLevel, and
// kApproxLevelSharp at spikes) so that every reference made from this surface agrees.
#pragma once

#include <opensubdiv/bfr/parameterization.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "render/core/cancel.h"
#include "render/core/vec.h"
#include "render/mesh/control_mesh.h"
#include "render/subdiv/displacement.h"

namespace limn::render::subdiv {

class FarPatchSurface;

// Bfr refinement level used to approximate irregular regions, for smooth and sharp features
// alike. At 6, Bfr, Far and Embree agree to about 4e-7 of the model size.
inline constexpr int kApproxLevel = 6;
// Except on the faces around a spike: an interior vertex that is an infinitely sharp corner
// (facesAtSpikes). There the surface converges much more slowly: each level removes only about
// a third of the remaining error, so level 6 left the spikes of a cube with sharp corners 9e-3
// of the cube's size (3 px at 512^2) off. 10 is the deepest OpenSubdiv's patches can describe
// (Far::PatchParam has 10 bits per coordinate; Far's patch map crashes beyond) and leaves about
// a fifth of that. Only there: Far's patch tables (FarPatchSurface, the patches method) cannot
// follow Bfr's sharp level everywhere (Far counts irregular boundary vertices of Loop meshes
// as smooth, Bfr as sharp), and they agree with Bfr exactly at kApproxLevel.
inline constexpr int kApproxLevelSharp = 10;

// Per base face: it has a spike corner (an infinitely sharp corner inside a manifold surface).
std::vector<char> facesAtSpikes(const OpenSubdiv::Far::TopologyLevel& base);

struct LimitSample {
  Vec3 position;
  Vec3 du, dv;  // first derivatives in the face's parameterisation
  Vec3 normal;  // unit; cross(du, dv) oriented by the face winding
};

// A Far topology refiner for `mesh` with its scheme, tags and rules (what LimitSurface is built
// on; also what anything comparing against OpenSubdiv should refine with). Throws
// InputError(InvalidMesh) when OpenSubdiv rejects the topology.
std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> createTopologyRefiner(
    const mesh::ControlMesh& mesh);

class LimitSurface {
 public:
  // Throws InputError(InvalidMesh) when OpenSubdiv cannot build the topology.
  // `alsoOnFarPatches` (for tests): faces to evaluate through Far's patch table although Bfr
  // could, to compare the two.
  explicit LimitSurface(mesh::ControlMesh mesh, const std::vector<int>& alsoOnFarPatches = {});
  // The same for a request: Cancelled is thrown when `cancel` has expired already (the per-face
  // surfaces check it while prepare(cancel) builds them).
  LimitSurface(mesh::ControlMesh mesh, const CancelToken& cancel);
  // The limit surface displaced along its normals (displacement.h): every evaluation below,
  // bounds() and the control limits are then of the displaced surface.
  LimitSurface(mesh::ControlMesh mesh, const CancelToken& cancel,
               const DisplacementSpec& displacement);
  ~LimitSurface();
  LimitSurface(const LimitSurface&) = delete;
  LimitSurface& operator=(const LimitSurface&) = delete;

  // ---- The control mesh ----
  const mesh::ControlMesh& mesh() const { return mesh_; }
  int faceCount() const { return mesh_.faceCount(); }
  // The control points' bounds (which hold the limit surface), widened by the displacement's
  // reach.
  Bounds bounds() const { return bounds_; }
  const DisplacementSpec& displacementSpec() const { return displacementSpec_; }
  bool displaced() const { return displacement_.enabled(); }
  // A new refiner for the same topology (uniform refinement mutates its refiner, so each
  // caller gets its own).
  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> createRefiner() const;
  // The base level's topology (edges, faces, vertices), read-only and shared.
  const OpenSubdiv::Far::TopologyLevel& baseLevel() const;

  // Builds the per-face surfaces now, checking `cancel` every few faces (a face around a vertex
  // of valence n costs about n^2) and throwing Cancelled when it expires; a request does this
  // up front when it will evaluate the surface, which also times the build. Otherwise the first
  // accessor that needs them builds them, uncancellable.
  void prepare(const CancelToken& cancel) const;

  // ---- Per-face limit surfaces ----
  // False for holes and for faces OpenSubdiv gives no limit surface.
  bool hasLimit(int face) const {
    prepare();
    return faces_[face].valid;
  }
  // +1 / -1: the face is on a closed piece wound outward / inward, whose side facing away from
  // the eye (by the limit normal, times this) is hidden; 0: on an open piece (closed_pieces.h).
  int hiddenSide(int face) const {
    prepare();
    return hiddenSide_[face];
  }
  // -1 where the face's limit normal points into its closed piece (an inside-out piece), else 1:
  // times the normal, the side that is outside the surface.
  int outwardSign(int face) const { return hiddenSide(face) < 0 ? -1 : 1; }
  // True when the face is evaluated through Far's patch table rather than Bfr.
  bool onFarPatches(int face) const {
    prepare();
    return faces_[face].onFarPatches;
  }
  OpenSubdiv::Bfr::Parameterization parameterization(int face) const;
  // Parametric coordinates of the face's k-th corner.
  Vec2 cornerUV(int face, int corner) const;
  // Parametric centre of the face.
  Vec2 centerUV(int face) const;

  // ---- Evaluation (thread-safe) ----
  LimitSample evaluate(int face, double u, double v) const;
  Vec3 position(int face, double u, double v) const;

  // Limit positions and normals of the control vertices (vertex-sharing faces agree), for
  // shading and measuring the cage. Vertices of holes only get the value of any non-hole face.
  const std::vector<Vec3>& controlLimitPositions() const {
    prepare();
    return controlLimitPositions_;
  }
  const std::vector<Vec3>& controlLimitNormals() const {
    prepare();
    return controlLimitNormals_;
  }

 private:
  struct FaceSurface;
  std::vector<int> facesBfrCannotEvaluate() const;
  void build(const CancelToken& cancel) const;
  void buildFaceSurfaces(const std::vector<int>& farPatchFaces, const CancelToken& cancel) const;
  void computeControlLimits(const CancelToken& cancel) const;
  void evaluateDerivatives(int face, double u, double v, Vec3& position, Vec3& du, Vec3& dv) const;
  void evaluateUndisplaced(int face, double u, double v, Vec3& position, Vec3& du, Vec3& dv) const;
  SurfaceJet evaluateJet(int face, double u, double v) const;

  mesh::ControlMesh mesh_;
  Bounds bounds_;
  DisplacementSpec displacementSpec_;
  Displacement displacement_;
  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner_;
  struct FaceData {
    bool valid = false;
    bool onFarPatches = false;
    int surfaceIndex = -1;  // into surfaces_, for faces on Bfr
  };
  void prepare() const;
  // Made by prepare(), once; `building_` lets the build itself read what it has made so far.
  std::vector<int> alsoOnFarPatches_;
  mutable std::atomic<bool> prepared_{false};
  mutable std::recursive_mutex prepareMutex_;
  mutable bool building_ = false;
  mutable std::vector<FaceData> faces_;
  mutable std::vector<int8_t> hiddenSide_;  // per face, see hiddenSide()
  mutable std::vector<FaceSurface> surfaces_;
  mutable std::unique_ptr<FarPatchSurface> farPatches_;  // only when some face needs it
  mutable std::vector<Vec3> controlLimitPositions_;
  mutable std::vector<Vec3> controlLimitNormals_;
};

}  // namespace limn::render::subdiv
