// FarPatchSurface: limit evaluation of some faces through Far's feature-adaptive PatchTable.
//
// LimitSurface evaluates faces with Bfr, except those whose Bfr patch OpenSubdiv 3.5.0 cannot
// build safely (faces around an interior vertex of valence 2): those are evaluated here. Far's
// adaptive refinement and Gregory end caps handle that topology, and are set up the way Bfr sets
// up its own per-face patch trees (the same isolation level for smooth and sharp features,
// infinitely sharp patches, Gregory end caps, exact smooth corners), so on faces both can
// evaluate the two agree to rounding.
//
// Coordinates in and derivatives out are Bfr's (see LimitSurface): the Ptex face and sub-face
// coordinates Far works in are converted here.
#pragma once

#include <opensubdiv/bfr/parameterization.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/topologyRefiner.h>

#include <memory>
#include <vector>

#include "render/core/vec.h"
#include "render/subdiv/displacement.h"

namespace limn::render::subdiv {

// Far's patch-table options as Bfr sets up its own per-face patch trees (Bfr::PatchTreeBuilder),
// at `isolation`: infinitely sharp features as patches, Gregory bases for what stays irregular,
// smooth corners kept smooth rather than Far's legacy sharp patches, double precision.
OpenSubdiv::Far::PatchTableFactory::Options bfrPatchOptions(int isolation);

// Position and first derivatives of one patch of `table` at its Ptex face's (s, t), the
// patch's points in `points`.
void evaluateFarPoint(const OpenSubdiv::Far::PatchTable& table,
                      const OpenSubdiv::Far::PatchTable::PatchHandle& handle, double s, double t,
                      const std::vector<Vec3>& points, Vec3& position, Vec3& ds, Vec3& dt);
// Position with first and second derivatives of one patch of `table` at its Ptex face's (s, t),
// the patch's points in `points`; with the second derivatives Far gets wrong (Gregory end caps,
// rotated Loop sub-triangles) made right as displacement.h says.
SurfaceJet evaluateFarJet(const OpenSubdiv::Far::PatchTable& table,
                          const OpenSubdiv::Far::PatchTable::PatchHandle& handle, double s,
                          double t, const std::vector<Vec3>& points);

class FarPatchSurface {
 public:
  // `refiner`: an unrefined refiner of the mesh, refined adaptively here (around `faces` only,
  // so the cost stays local) and released once the patches are built. `faces`: the base faces
  // to cover. `points`: the control points.
  FarPatchSurface(std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner,
                  const std::vector<int>& faces, const std::vector<Vec3>& points);
  ~FarPatchSurface();
  FarPatchSurface(const FarPatchSurface&) = delete;
  FarPatchSurface& operator=(const FarPatchSurface&) = delete;

  // True when every Ptex (sub-)face of `face` has patches (false for holes and faces not asked
  // for).
  bool covers(int face, const OpenSubdiv::Bfr::Parameterization& param) const;

  // Limit position and first derivatives at Bfr's (u, v) of `face`. Const and thread-safe.
  void evaluate(int face, const OpenSubdiv::Bfr::Parameterization& param, double u, double v,
                Vec3& position, Vec3& du, Vec3& dv) const;
  // The same with second derivatives (for displacement's Weingarten normals).
  SurfaceJet evaluateJet(int face, const OpenSubdiv::Bfr::Parameterization& param, double u,
                         double v) const;

 private:
  struct PtexPoint {
    int ptexFace;
    double s, t;  // coordinates in the Ptex (sub-)face, [0,1]^2 or the unit triangle
  };
  PtexPoint toPtex(int face, const OpenSubdiv::Bfr::Parameterization& param, double u,
                   double v) const;
  const OpenSubdiv::Far::PatchMap::Handle& patchAt(int face, const PtexPoint& at) const;

  std::unique_ptr<OpenSubdiv::Far::PatchTable> patches_;
  std::unique_ptr<OpenSubdiv::Far::PatchMap> patchMap_;
  std::vector<int> firstPtexFace_;  // per base face
  std::vector<Vec3> patchPoints_;   // control, refined and end-cap points, as patches_ indexes
};

}  // namespace limn::render::subdiv
