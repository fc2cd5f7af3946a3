#include "render/subdiv/limit_surface.h"

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <string>

#include "render/core/error.h"
#include "render/subdiv/closed_pieces.h"
#include "render/subdiv/far_patch_surface.h"

namespace limn::render::subdiv {

namespace Bfr = OpenSubdiv::Bfr;
namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

struct LimitSurface::FaceSurface {
  Bfr::Surface<double> surface;
  std::vector<double> patchPoints;  // xyz per patch point
};

namespace {

// How often construction looks at the request's cancel token: a face costs microseconds, or
// about a millisecond around a vertex at the valence limit.
constexpr int kFacesBetweenChecks = 16;

// Far reports topology errors through one process-wide callback. The last message seen on this
// thread is kept so the 422 can say what OpenSubdiv objected to.
thread_local std::string farLastError;

void recordFarError(Far::ErrorType, const char* message) { farLastError = message; }

void installFarErrorCallback() {
  static std::once_flag once;
  std::call_once(once, [] { Far::SetErrorCallback(recordFarError); });
}

Sdc::SchemeType schemeType(mesh::Scheme scheme) {
  switch (scheme) {
    case mesh::Scheme::Loop:
      return Sdc::SCHEME_LOOP;
    case mesh::Scheme::Bilinear:
      return Sdc::SCHEME_BILINEAR;
    case mesh::Scheme::CatmullClark:
      break;
  }
  return Sdc::SCHEME_CATMARK;
}

Sdc::Options schemeOptions(const mesh::ControlMesh& m) {
  Sdc::Options options;
  switch (m.boundary) {
    case mesh::BoundaryInterpolation::None:
      options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE);
      break;
    case mesh::BoundaryInterpolation::EdgeOnly:
      options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
      break;
    case mesh::BoundaryInterpolation::EdgeAndCorner:
      options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
      break;
  }
  options.SetCreasingMethod(m.creaseMethod == mesh::CreaseMethod::Chaikin
                                ? Sdc::Options::CREASE_CHAIKIN
                                : Sdc::Options::CREASE_UNIFORM);
  options.SetTriangleSubdivision(m.triangleSubdivision == mesh::TriangleSubdivision::Smooth
                                     ? Sdc::Options::TRI_SUB_SMOOTH
                                     : Sdc::Options::TRI_SUB_CATMARK);
  return options;
}

bool isInteriorValenceTwo(const Far::TopologyLevel& base, int v) {
  return base.GetVertexEdges(v).size() == 2 && base.GetVertexFaces(v).size() == 2 &&
         !base.IsVertexBoundary(v) && !base.IsVertexNonManifold(v);
}

bool isNonManifoldWithSharpEdge(const Far::TopologyLevel& base, int v) {
  if (!base.IsVertexNonManifold(v)) return false;
  for (int e : base.GetVertexEdges(v)) {
    if (base.GetEdgeSharpness(e) > 0) return true;
  }
  return false;
}

}  // namespace

std::unique_ptr<Far::TopologyRefiner> createTopologyRefiner(const mesh::ControlMesh& m) {
  installFarErrorCallback();
  std::vector<int> creaseVertices;
  std::vector<float> creaseWeights;
  for (const mesh::Crease& c : m.creases) {
    creaseVertices.push_back(c.v0);
    creaseVertices.push_back(c.v1);
    creaseWeights.push_back(c.sharpness);
  }
  std::vector<int> cornerVertices;
  std::vector<float> cornerWeights;
  for (const mesh::Corner& c : m.corners) {
    cornerVertices.push_back(c.vertex);
    cornerWeights.push_back(c.sharpness);
  }

  Far::TopologyDescriptor desc;
  desc.numVertices = m.vertexCount();
  desc.numFaces = m.faceCount();
  desc.numVertsPerFace = m.faceVertexCounts.data();
  desc.vertIndicesPerFace = m.faceVertexIndices.data();
  desc.numCreases = static_cast<int>(m.creases.size());
  desc.creaseVertexIndexPairs = creaseVertices.data();
  desc.creaseWeights = creaseWeights.data();
  desc.numCorners = static_cast<int>(m.corners.size());
  desc.cornerVertexIndices = cornerVertices.data();
  desc.cornerWeights = cornerWeights.data();
  desc.numHoles = static_cast<int>(m.holes.size());
  desc.holeIndices = m.holes.data();

  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  farLastError.clear();
  std::unique_ptr<Far::TopologyRefiner> refiner(
      Factory::Create(desc, Factory::Options(schemeType(m.scheme), schemeOptions(m))));
  if (!refiner) {
    throw InputError(InputError::Kind::InvalidMesh, "topology",
                     "OpenSubdiv rejected the mesh topology" +
                         (farLastError.empty() ? std::string() : ": " + farLastError));
  }
  return refiner;
}

LimitSurface::LimitSurface(mesh::ControlMesh mesh, const std::vector<int>& alsoOnFarPatches)
    : mesh_(std::move(mesh)),
      bounds_(mesh_.bounds()),
      refiner_(createTopologyRefiner(mesh_)),
      alsoOnFarPatches_(alsoOnFarPatches) {}

LimitSurface::LimitSurface(mesh::ControlMesh mesh, const CancelToken& cancel)
    : LimitSurface(std::move(mesh), cancel, DisplacementSpec{}) {}

LimitSurface::LimitSurface(mesh::ControlMesh mesh, const CancelToken& cancel,
                           const DisplacementSpec& displacement)
    : mesh_(std::move(mesh)),
      bounds_(mesh_.bounds()),
      displacementSpec_(displacement),
      displacement_(displacement, bounds_),
      refiner_(createTopologyRefiner(mesh_)) {
  cancel.check();
  const double reach = displacement_.reach();
  if (reach > 0 && !bounds_.empty()) {
    bounds_.extend(bounds_.lo - Vec3{reach, reach, reach});
    bounds_.extend(bounds_.hi + Vec3{reach, reach, reach});
  }
}

void LimitSurface::prepare() const {
  static const CancelToken never;
  prepare(never);
}

void LimitSurface::prepare(const CancelToken& cancel) const {
  if (prepared_.load(std::memory_order_acquire)) return;
  std::lock_guard lock(prepareMutex_);  // other threads wait here for the one building
  if (prepared_.load(std::memory_order_relaxed) || building_) return;
  building_ = true;
  try {
    build(cancel);
  } catch (...) {
    building_ = false;
    throw;
  }
  building_ = false;
  prepared_.store(true, std::memory_order_release);
}

void LimitSurface::build(const CancelToken& cancel) const {
  hiddenSide_ = hiddenSideOfFaces(baseLevel(), mesh_.points);
  std::vector<int> farPatchFaces = facesBfrCannotEvaluate();
  farPatchFaces.insert(farPatchFaces.end(), alsoOnFarPatches_.begin(), alsoOnFarPatches_.end());
  std::sort(farPatchFaces.begin(), farPatchFaces.end());
  farPatchFaces.erase(std::unique(farPatchFaces.begin(), farPatchFaces.end()), farPatchFaces.end());
  cancel.check();
  buildFaceSurfaces(farPatchFaces, cancel);
  computeControlLimits(cancel);
}

LimitSurface::~LimitSurface() = default;

std::unique_ptr<Far::TopologyRefiner> LimitSurface::createRefiner() const {
  return createTopologyRefiner(mesh_);
}

const Far::TopologyLevel& LimitSurface::baseLevel() const { return refiner_->GetLevel(0); }

// OpenSubdiv 3.5.0 (the Debian 12 version) reads or writes outside its arrays when Bfr builds
// the irregular patch of a face around
//  - an interior vertex of valence 2: it reads uninitialised memory and may crash (fixed
//    upstream after 3.6);
//  - a non-manifold vertex with a sharp edge: the patch's local mesh of the manifold part
//    around the vertex may lack the sharp edge (back-to-back faces), Bfr warns "Edge N
//    specified to be sharp does not exist" and tags the edge at index -1, corrupting the heap.
// Those faces go to Far's adaptive patch table instead, which handles both.
std::vector<int> LimitSurface::facesBfrCannotEvaluate() const {
  std::vector<int> faces;
  if (mesh_.scheme == mesh::Scheme::Bilinear) return faces;  // bilinear has no irregular patches
  const Far::TopologyLevel& base = baseLevel();
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    if (isInteriorValenceTwo(base, v) || isNonManifoldWithSharpEdge(base, v)) {
      Far::ConstIndexArray incident = base.GetVertexFaces(v);
      faces.insert(faces.end(), incident.begin(), incident.end());
    }
  }
  return faces;
}

std::vector<char> facesAtSpikes(const Far::TopologyLevel& base) {
  std::vector<char> atSpike(base.GetNumFaces(), 0);
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    if (base.IsVertexBoundary(v) || base.IsVertexNonManifold(v) ||
        base.GetVertexSharpness(v) < mesh::kInfiniteSharpness) {
      continue;
    }
    for (int f : base.GetVertexFaces(v)) atSpike[f] = 1;
  }
  return atSpike;
}

void LimitSurface::buildFaceSurfaces(const std::vector<int>& farPatchFaces,
                                     const CancelToken& cancel) const {
  if (!farPatchFaces.empty()) {
    // Far refines its refiner adaptively; refiner_ is shared (baseLevel()), so it gets its own.
    farPatches_ = std::make_unique<FarPatchSurface>(createRefiner(), farPatchFaces, mesh_.points);
  }
  Bfr::RefinerSurfaceFactory<>::Options options;
  options.SetApproxLevelSmooth(kApproxLevel);
  options.SetApproxLevelSharp(kApproxLevel);
  Bfr::RefinerSurfaceFactory<> factory(*refiner_, options);
  // Faces at a spike (kApproxLevelSharp says why) from a factory that goes deeper there.
  options.SetApproxLevelSharp(kApproxLevelSharp);
  Bfr::RefinerSurfaceFactory<> spikeFactory(*refiner_, options);
  const std::vector<char> atSpike = facesAtSpikes(baseLevel());

  std::vector<double> meshPoints;
  meshPoints.reserve(mesh_.points.size() * 3);
  for (const Vec3& p : mesh_.points) {
    meshPoints.insert(meshPoints.end(), {p.x, p.y, p.z});
  }
  const Bfr::Surface<double>::PointDescriptor xyz(3);

  faces_.assign(mesh_.faceCount(), FaceData{});
  surfaces_.clear();  // a build cancelled before may have left some
  surfaces_.reserve(mesh_.faceCount());
  for (int f = 0; f < mesh_.faceCount(); ++f) {
    if (f % kFacesBetweenChecks == 0) cancel.check();
    if (!factory.FaceHasLimitSurface(f)) continue;
    if (std::binary_search(farPatchFaces.begin(), farPatchFaces.end(), f)) {
      faces_[f].valid = farPatches_->covers(f, parameterization(f));
      faces_[f].onFarPatches = true;
      continue;
    }
    FaceSurface fs;
    Bfr::RefinerSurfaceFactory<>& from = atSpike[f] ? spikeFactory : factory;
    if (!from.InitVertexSurface(f, &fs.surface) || !fs.surface.IsValid()) continue;
    fs.patchPoints.resize(static_cast<size_t>(fs.surface.GetNumPatchPoints()) * 3);
    fs.surface.PreparePatchPoints(meshPoints.data(), xyz, fs.patchPoints.data(), xyz);
    faces_[f] = {true, false, static_cast<int>(surfaces_.size())};
    surfaces_.push_back(std::move(fs));
  }
}

Bfr::Parameterization LimitSurface::parameterization(int face) const {
  prepare();
  const int surface = faces_[face].surfaceIndex;
  if (surface >= 0) return surfaces_[surface].surface.GetParameterization();
  return Bfr::Parameterization(schemeType(mesh_.scheme), mesh_.faceVertexCounts[face]);
}

Vec2 LimitSurface::cornerUV(int face, int corner) const {
  double uv[2];
  parameterization(face).GetVertexCoord(corner, uv);
  return {uv[0], uv[1]};
}

Vec2 LimitSurface::centerUV(int face) const {
  double uv[2];
  parameterization(face).GetCenterCoord(uv);
  return {uv[0], uv[1]};
}

void LimitSurface::evaluateUndisplaced(int face, double u, double v, Vec3& position, Vec3& du,
                                       Vec3& dv) const {
  if (faces_[face].onFarPatches) {
    farPatches_->evaluate(face, parameterization(face), u, v, position, du, dv);
    return;
  }
  const FaceSurface& fs = surfaces_[faces_[face].surfaceIndex];
  const Bfr::Surface<double>::PointDescriptor xyz(3);
  double uv[2] = {u, v};
  double p[3], dpu[3], dpv[3];
  fs.surface.Evaluate(uv, fs.patchPoints.data(), xyz, p, dpu, dpv);
  position = {p[0], p[1], p[2]};
  du = {dpu[0], dpu[1], dpu[2]};
  dv = {dpv[0], dpv[1], dpv[2]};
}

SurfaceJet LimitSurface::evaluateJet(int face, double u, double v) const {
  if (faces_[face].onFarPatches)
    return farPatches_->evaluateJet(face, parameterization(face), u, v);
  const FaceSurface& fs = surfaces_[faces_[face].surfaceIndex];
  const Bfr::Surface<double>::PointDescriptor xyz(3);
  double uv[2] = {u, v};
  double p[3], du[3], dv[3], duu[3], duv[3], dvv[3];
  fs.surface.Evaluate(uv, fs.patchPoints.data(), xyz, p, du, dv, duu, duv, dvv);
  auto vec = [](const double* a) { return Vec3{a[0], a[1], a[2]}; };
  SurfaceJet jet{vec(p), vec(du), vec(dv), vec(duu), vec(duv), vec(dvv)};
  if (!fs.surface.IsRegular()) {  // displacement.h: Bfr's irregular patch trees
    differenceSecondDerivatives(jet, u, v, [&](double a, double b, Vec3& da, Vec3& db) {
      double at[2] = {a, b}, q[3], qa[3], qb[3];
      fs.surface.Evaluate(at, fs.patchPoints.data(), xyz, q, qa, qb);
      da = vec(qa);
      db = vec(qb);
    });
  }
  return jet;
}

void LimitSurface::evaluateDerivatives(int face, double u, double v, Vec3& position, Vec3& du,
                                       Vec3& dv) const {
  if (!displacement_.enabled()) {
    evaluateUndisplaced(face, u, v, position, du, dv);
    return;
  }
  const SurfaceJet jet = evaluateJet(face, u, v);
  if (displace(displacement_, jet, position, du, dv)) return;
  // The undisplaced normal is undefined here (a corner of some irregular patches): the normal
  // and its derivatives are their limits from a point nudged towards the centre.
  const Vec2 c = centerUV(face);
  SurfaceJet near = evaluateJet(face, u + (c.x - u) * 1e-5, v + (c.y - v) * 1e-5);
  near.position = jet.position;
  if (displace(displacement_, near, position, du, dv)) return;
  position = jet.position;
  du = jet.du;
  dv = jet.dv;
}

LimitSample LimitSurface::evaluate(int face, double u, double v) const {
  prepare();
  LimitSample s;
  evaluateDerivatives(face, u, v, s.position, s.du, s.dv);
  Vec3 n = cross(s.du, s.dv);
  double scale = dot(s.du, s.du) + dot(s.dv, s.dv);
  if (dot(n, n) <= 1e-20 * scale * scale) {
    // Degenerate derivatives (e.g. at a corner of some irregular patches): the normal there is
    // the limit of the normals approaching it, taken from a point nudged towards the centre.
    Vec2 c = centerUV(face);
    Vec3 p, du, dv;
    evaluateDerivatives(face, u + (c.x - u) * 1e-5, v + (c.y - v) * 1e-5, p, du, dv);
    n = cross(du, dv);
  }
  s.normal = normalize(n);
  return s;
}

Vec3 LimitSurface::position(int face, double u, double v) const {
  prepare();
  if (faces_[face].onFarPatches || displacement_.enabled()) {
    Vec3 p, du, dv;
    evaluateDerivatives(face, u, v, p, du, dv);
    return p;
  }
  const FaceSurface& fs = surfaces_[faces_[face].surfaceIndex];
  const Bfr::Surface<double>::PointDescriptor xyz(3);
  double uv[2] = {u, v};
  double p[3];
  fs.surface.Evaluate(uv, fs.patchPoints.data(), xyz, p);
  return {p[0], p[1], p[2]};
}

void LimitSurface::computeControlLimits(const CancelToken& cancel) const {
  controlLimitPositions_ = mesh_.points;
  controlLimitNormals_.assign(mesh_.points.size(), Vec3{0, 0, 0});
  std::vector<bool> done(mesh_.points.size(), false);
  size_t offset = 0;
  for (int f = 0; f < mesh_.faceCount(); ++f) {
    if (f % kFacesBetweenChecks == 0) cancel.check();
    int n = mesh_.faceVertexCounts[f];
    if (faces_[f].valid) {
      for (int k = 0; k < n; ++k) {
        int vertex = mesh_.faceVertexIndices[offset + k];
        if (done[vertex]) continue;
        Vec2 uv = cornerUV(f, k);
        LimitSample s = evaluate(f, uv.x, uv.y);
        controlLimitPositions_[vertex] = s.position;
        controlLimitNormals_[vertex] = s.normal;
        done[vertex] = true;
      }
    }
    offset += n;
  }
}

}  // namespace limn::render::subdiv
