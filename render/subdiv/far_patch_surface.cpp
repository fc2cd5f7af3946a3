#include "render/subdiv/far_patch_surface.h"

#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "render/subdiv/far_point.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::subdiv {

namespace Bfr = OpenSubdiv::Bfr;
namespace Far = OpenSubdiv::Far;

namespace {

// The most control points a patch has (a quad Gregory basis patch; Loop's are smaller).
constexpr int kMaxPatchPoints = 20;

double clampUnit(double x) { return std::clamp(x, 0.0, 1.0); }

}  // namespace

Far::PatchTableFactory::Options bfrPatchOptions(int isolation) {
  Far::PatchTableFactory::Options options(isolation);
  options.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  options.useInfSharpPatch = true;
  options.useSingleCreasePatch = false;
  options.generateLegacySharpCornerPatches = false;
  options.generateVaryingTables = false;
  options.generateVaryingLocalPoints = false;
  options.SetPatchPrecision<double>();
  return options;
}

FarPatchSurface::FarPatchSurface(std::unique_ptr<Far::TopologyRefiner> refiner,
                                 const std::vector<int>& faces, const std::vector<Vec3>& points) {
  Far::PtexIndices ptexIndices(*refiner);
  const int baseFaces = refiner->GetLevel(0).GetNumFaces();
  firstPtexFace_.resize(baseFaces);
  for (int f = 0; f < baseFaces; ++f) firstPtexFace_[f] = ptexIndices.GetFaceId(f);

  // Both isolation levels at kApproxLevel, as Bfr (away from spikes).
  Far::PatchTableFactory::Options options = bfrPatchOptions(kApproxLevel);
  Far::TopologyRefiner::AdaptiveOptions adaptive = options.GetRefineAdaptiveOptions();
  adaptive.secondaryLevel = kApproxLevel;
  Far::ConstIndexArray selected(faces.data(), static_cast<int>(faces.size()));
  refiner->RefineAdaptive(adaptive, selected);
  patches_.reset(Far::PatchTableFactory::Create(*refiner, options, selected));
  for (int a = 0; a < patches_->GetNumPatchArrays(); ++a) {
    if (patches_->GetPatchArrayDescriptor(a).GetNumControlVertices() > kMaxPatchPoints) {
      throw std::logic_error("Far built a patch type with more points than expected");
    }
  }
  patchMap_ = std::make_unique<Far::PatchMap>(*patches_);

  // Patch point indices run over the control points, then every refined level, then the end
  // caps' local points.
  const int refinedTotal = refiner->GetNumVerticesTotal();
  std::vector<FarPoint> buffer(refinedTotal + patches_->GetNumLocalPoints());
  for (size_t i = 0; i < points.size(); ++i) buffer[i].p = points[i];
  Far::PrimvarRefinerReal<double> primvars(*refiner);
  FarPoint* src = buffer.data();
  for (int level = 1; level <= refiner->GetMaxLevel(); ++level) {
    FarPoint* dst = src + refiner->GetLevel(level - 1).GetNumVertices();
    primvars.Interpolate(level, src, dst);
    src = dst;
  }
  // (PatchTable::ComputeLocalPointValues reads the single-precision stencils only.)
  if (const auto* endCaps = patches_->GetLocalPointStencilTable<double>()) {
    endCaps->UpdateValues(buffer.data(), buffer.data() + refinedTotal);
  }
  patchPoints_.reserve(buffer.size());
  for (const FarPoint& q : buffer) patchPoints_.push_back(q.p);
}

FarPatchSurface::~FarPatchSurface() = default;

// Bfr parameterises an n-gon of Catmull-Clark as n half-size quad tiles; the normalized
// coordinates of tile k are those of Ptex sub-face k (Bfr::Parameterization says so, and
// LimitSurface's tests check it against Bfr). Quads and triangles are one Ptex face each, in
// the same coordinates as Bfr's.
//
// Derivatives need no conversion: Far scales those of a sub-face's patches as if the sub-face
// had size 1/2 (its depth counts the split of the n-gon), which is Bfr's tile size.
FarPatchSurface::PtexPoint FarPatchSurface::toPtex(int face, const Bfr::Parameterization& param,
                                                   double u, double v) const {
  if (!param.HasSubFaces()) return {firstPtexFace_[face], u, v};
  double uv[2] = {u, v}, st[2];
  int subFace = param.ConvertCoordToNormalizedSubFace(uv, st);
  return {firstPtexFace_[face] + subFace, st[0], st[1]};
}

bool FarPatchSurface::covers(int face, const Bfr::Parameterization& param) const {
  if (face < 0 || face >= static_cast<int>(firstPtexFace_.size())) return false;
  int subFaces = param.HasSubFaces() ? param.GetFaceSize() : 1;
  for (int k = 0; k < subFaces; ++k) {
    double centre = param.GetType() == Bfr::Parameterization::TRI ? 1.0 / 3.0 : 0.5;
    if (!patchMap_->FindPatch(firstPtexFace_[face] + k, centre, centre)) return false;
  }
  return true;
}

const Far::PatchMap::Handle& FarPatchSurface::patchAt(int face, const PtexPoint& at) const {
  // The patch map wants coordinates inside the face; a point a little outside (callers allow a
  // small slack) is evaluated on the nearest patch, extended.
  const Far::PatchMap::Handle* handle =
      patchMap_->FindPatch(at.ptexFace, clampUnit(at.s), clampUnit(at.t));
  if (!handle) {
    throw std::logic_error("face " + std::to_string(face) + " has no Far patch");
  }
  return *handle;
}

void FarPatchSurface::evaluate(int face, const Bfr::Parameterization& param, double u, double v,
                               Vec3& position, Vec3& du, Vec3& dv) const {
  const PtexPoint at = toPtex(face, param, u, v);
  evaluateFarPoint(*patches_, patchAt(face, at), at.s, at.t, patchPoints_, position, du, dv);
}

void evaluateFarPoint(const Far::PatchTable& table, const Far::PatchTable::PatchHandle& handle,
                      double s, double t, const std::vector<Vec3>& points, Vec3& position, Vec3& ds,
                      Vec3& dt) {
  std::array<double, kMaxPatchPoints> w, wDs, wDt;
  table.EvaluateBasis(handle, s, t, w.data(), wDs.data(), wDt.data());
  const Far::ConstIndexArray cvs = table.GetPatchVertices(handle);
  position = ds = dt = Vec3{0, 0, 0};
  for (int i = 0; i < cvs.size(); ++i) {
    const Vec3& p = points[cvs[i]];
    position += p * w[i];
    ds += p * wDs[i];
    dt += p * wDt[i];
  }
}

SurfaceJet FarPatchSurface::evaluateJet(int face, const Bfr::Parameterization& param, double u,
                                        double v) const {
  const PtexPoint at = toPtex(face, param, u, v);
  return evaluateFarJet(*patches_, patchAt(face, at), at.s, at.t, patchPoints_);
}

SurfaceJet evaluateFarJet(const Far::PatchTable& table, const Far::PatchTable::PatchHandle& handle,
                          double s, double t, const std::vector<Vec3>& points) {
  std::array<double, kMaxPatchPoints> w, wDs, wDt, wDss, wDst, wDtt;
  table.EvaluateBasis(handle, s, t, w.data(), wDs.data(), wDt.data(), wDss.data(), wDst.data(),
                      wDtt.data());
  const Far::ConstIndexArray cvs = table.GetPatchVertices(handle);
  SurfaceJet jet{};
  for (int i = 0; i < cvs.size(); ++i) {
    const Vec3& p = points[cvs[i]];
    jet.position += p * w[i];
    jet.du += p * wDs[i];
    jet.dv += p * wDt[i];
    jet.duu += p * wDss[i];
    jet.duv += p * wDst[i];
    jet.dvv += p * wDtt[i];
  }
  // Where Far's own second derivatives are not the patch's (displacement.h).
  const Far::PatchDescriptor::Type type =
      table.GetPatchArrayDescriptor(handle.arrayIndex).GetType();
  if (type == Far::PatchDescriptor::GREGORY || type == Far::PatchDescriptor::GREGORY_BASIS ||
      type == Far::PatchDescriptor::GREGORY_TRIANGLE) {
    differenceSecondDerivatives(jet, s, t, [&](double a, double b, Vec3& da, Vec3& db) {
      Vec3 ignored;
      evaluateFarPoint(table, handle, a, b, points, ignored, da, db);
    });
  } else if (type == Far::PatchDescriptor::LOOP &&
             table.GetPatchParam(handle).IsTriangleRotated()) {
    // (The bit means nothing for quads.)
    jet.duu = -jet.duu;
    jet.duv = -jet.duv;
    jet.dvv = -jet.dvv;
  }
  return jet;
}

}  // namespace limn::render::subdiv
