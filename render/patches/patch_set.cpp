#include "render/patches/patch_set.h"

#include <opensubdiv/bfr/parameterization.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTableFactory.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "render/subdiv/closed_pieces.h"
#include "render/subdiv/far_patch_surface.h"
#include "render/subdiv/far_point.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::patches {

namespace Far = OpenSubdiv::Far;

namespace {

// The most points a patch has (a quad Gregory basis patch).
constexpr int kMaxPatchPoints = 20;

// Stencils from the control points to every refined point, then to every end-cap point.
std::unique_ptr<const Far::StencilTableReal<double>> pointStencils(
    const Far::TopologyRefiner& refiner, const Far::PatchTable& table) {
  using Factory = Far::StencilTableFactoryReal<double>;
  Factory::Options options;
  options.generateIntermediateLevels = true;
  options.factorizeIntermediateLevels = true;
  options.generateOffsets = true;
  std::unique_ptr<const Far::StencilTableReal<double>> refined(Factory::Create(refiner, options));
  const Far::StencilTableReal<double>* endCaps = table.GetLocalPointStencilTable<double>();
  if (endCaps == nullptr || endCaps->GetNumStencils() == 0) return refined;
  return std::unique_ptr<const Far::StencilTableReal<double>>(
      Factory::AppendLocalPointStencilTable(refiner, refined.get(), endCaps));
}

std::vector<bool> facesOnTheBoundary(const Far::TopologyLevel& base) {
  std::vector<bool> out(base.GetNumFaces(), false);
  for (int f = 0; f < base.GetNumFaces(); ++f) {
    for (int e : base.GetFaceEdges(f)) {
      if (base.IsEdgeBoundary(e) || base.IsEdgeNonManifold(e)) out[f] = true;
    }
  }
  return out;
}

PatchKind kindOf(Far::PatchDescriptor::Type type, const Far::PatchParam& param, bool onBoundary) {
  if (type != Far::PatchDescriptor::REGULAR && type != Far::PatchDescriptor::LOOP) {
    return PatchKind::Irregular;
  }
  if (param.GetBoundary() == 0) return PatchKind::Regular;
  return onBoundary ? PatchKind::Boundary : PatchKind::Crease;
}

}  // namespace

const char* patchKindName(PatchKind kind) {
  switch (kind) {
    case PatchKind::Regular:
      return "regular";
    case PatchKind::Boundary:
      return "boundary";
    case PatchKind::Crease:
      return "crease";
    case PatchKind::Irregular:
      return "irregular";
  }
  return "?";
}

int sharpIsolation(const Far::TopologyLevel& base, int isolation) {
  const std::vector<char> atSpike = subdiv::facesAtSpikes(base);
  if (std::none_of(atSpike.begin(), atSpike.end(), [](char c) { return c != 0; })) {
    return isolation;
  }
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    if (base.IsEdgeNonManifold(e)) return isolation;
  }
  return std::min(isolation + subdiv::kApproxLevelSharp - subdiv::kApproxLevel,
                  subdiv::kApproxLevelSharp);
}

PatchSet::PatchSet(const mesh::ControlMesh& mesh, int isolation, const CancelToken& cancel,
                   const subdiv::DisplacementSpec& displacement)
    : scheme_(mesh.scheme),
      controlPoints_(mesh.points.size()),
      displacement_(displacement, mesh.bounds()) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<Far::TopologyRefiner> refiner = subdiv::createTopologyRefiner(mesh);
  const Far::TopologyLevel& base = refiner->GetLevel(0);
  const std::vector<bool> onBoundary = facesOnTheBoundary(base);
  hiddenSide_ = subdiv::hiddenSideOfFaces(base, mesh.points);
  // Ptex faces (one per quad or triangle, one per corner of an n-gon) back to base faces.
  std::vector<std::pair<int, int>> ptexToFace;
  {
    Far::PtexIndices ptex(*refiner);
    for (int f = 0; f < base.GetNumFaces(); ++f) {
      const int first = ptex.GetFaceId(f);
      const int count =
          (f + 1 < base.GetNumFaces() ? ptex.GetFaceId(f + 1) : ptex.GetNumFaces()) - first;
      for (int k = 0; k < count; ++k) ptexToFace.push_back({f, count > 1 ? k : -1});
    }
  }
  cancel.check();

  Far::PatchTableFactory::Options options =
      subdiv::bfrPatchOptions(sharpIsolation(base, isolation));
  Far::TopologyRefiner::AdaptiveOptions adaptive = options.GetRefineAdaptiveOptions();
  adaptive.secondaryLevel = isolation;
  refiner->RefineAdaptive(adaptive);
  // Refining appends levels to a vector inside the refiner: `base` may now dangle.
  const Far::TopologyLevel& refinedBase = refiner->GetLevel(0);
  cancel.check();
  table_.reset(Far::PatchTableFactory::Create(*refiner, options));
  cancel.check();
  stencils_ = pointStencils(*refiner, *table_);
  cancel.check();

  stats_.isolation = isolation;
  stats_.refinedPoints = refiner->GetNumVerticesTotal() - controlPoints_;
  stats_.endCapPoints = table_->GetNumLocalPoints();
  for (int a = 0; a < table_->GetNumPatchArrays(); ++a) {
    const Far::PatchDescriptor descriptor = table_->GetPatchArrayDescriptor(a);
    if (descriptor.GetNumControlVertices() > kMaxPatchPoints) {
      throw std::logic_error("Far built a patch type with more points than expected");
    }
    const bool triangle = descriptor.GetType() == Far::PatchDescriptor::LOOP ||
                          descriptor.GetType() == Far::PatchDescriptor::GREGORY_TRIANGLE;
    for (int i = 0; i < table_->GetNumPatches(a); ++i) {
      Patch patch;
      patch.param = table_->GetPatchParam(a, i);
      patch.type = descriptor.GetType();
      patch.handle.arrayIndex = a;
      patch.handle.patchIndex = static_cast<int>(patches_.size());
      patch.handle.vertIndex = i * descriptor.GetNumControlVertices();
      const auto [face, subFace] = ptexToFace.at(patch.param.GetFaceId());
      patch.baseFace = face;
      patch.subFace = subFace;
      patch.faceSize = refinedBase.GetFaceVertices(face).size();
      patch.depth = patch.param.GetDepth();
      patch.kind = kindOf(descriptor.GetType(), patch.param, onBoundary[face]);
      patch.triangle = triangle;
      patch.inHull = patch.param.GetBoundary() == 0;
      // Displaced, a patch's normals leave the cone of its control points' differences.
      // (Loop patches are not: the box-spline cone test culled visible patches from some
      // views through the server; patch_tessellation.cpp keeps it for when that is found.)
      patch.cullable = descriptor.GetType() == Far::PatchDescriptor::REGULAR && patch.inHull &&
                       !displacement_.enabled();
      if (static_cast<int>(stats_.byLevel.size()) <= patch.depth) {
        stats_.byLevel.resize(patch.depth + 1, {});
      }
      ++stats_.byLevel[patch.depth][static_cast<int>(patch.kind)];
      patches_.push_back(patch);
    }
  }
  stats_.patches = patches_.size();
  setControlPoints(mesh.points);
  stats_.buildMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

PatchSet::~PatchSet() = default;

void PatchSet::setControlPoints(const std::vector<Vec3>& points) {
  if (points.size() != controlPoints_) {
    throw std::invalid_argument("a frame has " + std::to_string(points.size()) +
                                " points; the mesh has " + std::to_string(controlPoints_));
  }
  std::vector<subdiv::FarPoint> buffer(controlPoints_ +
                                       (stencils_ ? stencils_->GetNumStencils() : 0));
  for (size_t i = 0; i < controlPoints_; ++i) buffer[i].p = points[i];
  if (stencils_ && stencils_->GetNumStencils() > 0) {
    stencils_->UpdateValues(buffer.data(), buffer.data() + controlPoints_);
  }
  controlBounds_ = Bounds{};
  for (const Vec3& p : points) controlBounds_.extend(p);
  if (const double reach = displacement_.reach(); reach > 0) {
    controlBounds_.extend(controlBounds_.lo - Vec3{reach, reach, reach});
    controlBounds_.extend(controlBounds_.hi + Vec3{reach, reach, reach});
  }
  points_.resize(buffer.size());
  for (size_t i = 0; i < buffer.size(); ++i) points_[i] = buffer[i].p;
}

Vec2 PatchSet::toPtex(const Patch& patch, double s, double t) const {
  if (patch.triangle) {
    patch.param.UnnormalizeTriangle(s, t);
  } else {
    patch.param.Unnormalize(s, t);
  }
  return {s, t};
}

Vec2 PatchSet::toFaceUV(const Patch& patch, double s, double t) const {
  const Vec2 ptex = toPtex(patch, s, t);
  if (patch.subFace < 0) return ptex;
  const OpenSubdiv::Bfr::Parameterization param(scheme_ == mesh::Scheme::Loop
                                                    ? OpenSubdiv::Sdc::SCHEME_LOOP
                                                    : OpenSubdiv::Sdc::SCHEME_CATMARK,
                                                patch.faceSize);
  double st[2] = {ptex.x, ptex.y}, uv[2];
  param.ConvertNormalizedSubFaceToCoord(patch.subFace, st, uv);
  return {uv[0], uv[1]};
}

void PatchSet::evaluateUndisplaced(const Patch& patch, Vec2 ptex, Vec3& position, Vec3& ds,
                                   Vec3& dt) const {
  subdiv::evaluateFarPoint(*table_, patch.handle, ptex.x, ptex.y, points_, position, ds, dt);
}

subdiv::SurfaceJet PatchSet::evaluateJet(const Patch& patch, Vec2 ptex) const {
  return subdiv::evaluateFarJet(*table_, patch.handle, ptex.x, ptex.y, points_);
}

void PatchSet::evaluate(const Patch& patch, double s, double t, Vec3& position, Vec3& ds,
                        Vec3& dt) const {
  if (!displacement_.enabled()) {
    evaluateUndisplaced(patch, toPtex(patch, s, t), position, ds, dt);
    return;
  }
  const subdiv::SurfaceJet jet = evaluateJet(patch, toPtex(patch, s, t));
  if (subdiv::displace(displacement_, jet, position, ds, dt)) return;
  // The patch normal is undefined here (some end-cap corners): the normal and its derivatives
  // are their limits from a point nudged towards the patch's centre.
  const double centre = patch.triangle ? 1.0 / 3.0 : 0.5;
  subdiv::SurfaceJet near =
      evaluateJet(patch, toPtex(patch, s + (centre - s) * 1e-5, t + (centre - t) * 1e-5));
  near.position = jet.position;
  if (subdiv::displace(displacement_, near, position, ds, dt)) return;
  position = jet.position;
  ds = jet.du;
  dt = jet.dv;
}

Far::ConstIndexArray PatchSet::pointIndices(const Patch& patch) const {
  return table_->GetPatchVertices(patch.handle);
}

std::vector<Vec3> PatchSet::controlPoints(const Patch& patch) const {
  std::vector<Vec3> out;
  for (int index : table_->GetPatchVertices(patch.handle)) out.push_back(points_[index]);
  return out;
}

}  // namespace limn::render::patches
