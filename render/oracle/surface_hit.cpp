#include "render/oracle/surface_hit.h"

#include <opensubdiv/bfr/parameterization.h>

#include <cmath>

namespace limn::render::oracle {

namespace Bfr = OpenSubdiv::Bfr;

namespace {

constexpr int kMaxIterations = 6;
// A Newton step longer than this (in parameter units) is divergence, not refinement: the start
// is within the tessellation's chord error of the answer.
constexpr double kMaxStep = 0.25;
// How far past the face's parameter domain a converged point may lie (in units of a quad face or
// a normalised sub-face). The patch extends smoothly there, and the neighbour's surface differs
// from that extension by far less than the convergence tolerance at such distances.
constexpr double kDomainSlack = 1e-3;

// One face's parameter domain. For n-gons split into quad sub-faces it tracks the current
// sub-face, whose normalised coordinates (s, t) run from its vertex (0, 0) along its edge
// (s = 1: the spoke from that edge's midpoint to the centre) and back along the previous edge
// (t = 1: the spoke from the previous edge's midpoint to the centre).
class FaceDomain {
 public:
  explicit FaceDomain(const Bfr::Parameterization& p)
      : param_(p), size_(p.GetFaceSize()), subFaces_(p.HasSubFaces()) {}

  bool hasSubFaces() const { return subFaces_; }
  int size() const { return size_; }

  // Sub-face containing a point, and its normalised coordinates there.
  int locate(Vec2 uv, Vec2* st) const {
    double in[2] = {uv.x, uv.y}, out[2];
    int sub = param_.ConvertCoordToNormalizedSubFace(in, out);
    *st = {out[0], out[1]};
    return sub;
  }
  Vec2 toCoord(int sub, Vec2 st) const {
    double in[2] = {st.x, st.y}, out[2];
    param_.ConvertNormalizedSubFaceToCoord(sub, in, out);
    return {out[0], out[1]};
  }

  // Normalised coordinates in sub-face `sub` of a point given in any sub-face: crossing a spoke
  // into the next sub-face maps (s, t) to (t, 2 - s), into the previous one (2 - t, s). Points
  // near a spoke (Bfr tessellates each sub-face with its own inner points, so triangles straddle
  // spokes) land just outside [0, 1]^2, where the map continues the sub-face smoothly.
  Vec2 localIn(int sub, Vec2 uv) const {
    Vec2 st;
    int k = locate(uv, &st);
    int forward = ((sub - k) % size_ + size_) % size_;
    if (2 * forward <= size_) {
      for (int i = 0; i < forward; ++i) st = {st.y, 2 - st.x};
    } else {
      for (int i = 0; i < size_ - forward; ++i) st = {2 - st.y, st.x};
    }
    return st;
  }

  // After a Newton step: moves (uv, sub) across spokes into the sub-face that contains the point
  // and says whether it is still inside the face (within the slack).
  bool settle(Vec2* uv, int* sub) const {
    if (!subFaces_) {
      double u = uv->x, v = uv->y;
      if (u < -kDomainSlack || v < -kDomainSlack) return false;
      if (param_.GetType() == Bfr::Parameterization::TRI) return u + v <= 1 + kDomainSlack;
      return u <= 1 + kDomainSlack && v <= 1 + kDomainSlack;
    }
    Vec2 origin = toCoord(*sub, {0, 0});
    Vec2 st{(uv->x - origin.x) * 2, (uv->y - origin.y) * 2};
    for (int i = 0; i < size_ && (st.x > 1 || st.y > 1); ++i) {
      if (st.x > 1) {  // across the spoke s = 1 into the next sub-face, where it is t = 1
        *sub = (*sub + 1) % size_;
        st = {st.y, 2 - st.x};
      } else {  // across t = 1 into the previous sub-face, where it is s = 1
        *sub = (*sub + size_ - 1) % size_;
        st = {2 - st.y, st.x};
      }
    }
    if (st.x > 1 + kDomainSlack || st.y > 1 + kDomainSlack) return false;
    if (st.x < -kDomainSlack || st.y < -kDomainSlack) return false;
    *uv = toCoord(*sub, st);
    return true;
  }

 private:
  Bfr::Parameterization param_;
  int size_;
  bool subFaces_;
};

}  // namespace

bool triangleHitUV(const subdiv::LimitSurface& surface, const tessellate::TriangleMesh& mesh,
                   uint32_t triangle, float bu, float bv, int* face, Vec2* uv) {
  *face = mesh.triangleFaces[triangle];
  const Vec2f* c = &mesh.cornerUVs[3 * static_cast<size_t>(triangle)];
  const double w[3] = {1.0 - bu - bv, bu, bv};
  FaceDomain domain(surface.parameterization(*face));
  if (!domain.hasSubFaces()) {
    *uv = {w[0] * c[0].x + w[1] * c[1].x + w[2] * c[2].x,
           w[0] * c[0].y + w[1] * c[1].y + w[2] * c[2].y};
    return true;
  }
  // Corners carry the coordinates of their own sub-face: write all three in the first one's,
  // interpolate there, then move the point into the sub-face that contains it.
  Vec2 ignored;
  int sub = domain.locate({c[0].x, c[0].y}, &ignored);
  Vec2 st[3];
  for (int k = 0; k < 3; ++k) st[k] = domain.localIn(sub, {c[k].x, c[k].y});
  *uv = domain.toCoord(sub, {w[0] * st[0].x + w[1] * st[1].x + w[2] * st[2].x,
                             w[0] * st[0].y + w[1] * st[1].y + w[2] * st[2].y});
  return domain.settle(uv, &sub);
}

SurfaceHit refineHit(const subdiv::LimitSurface& surface, int face, Vec2 uv0, const PixelRay& ray,
                     double t0, double tolerance) {
  FaceDomain domain(surface.parameterization(face));
  int sub = 0;
  if (domain.hasSubFaces()) {
    Vec2 ignored;
    sub = domain.locate(uv0, &ignored);
  }
  SurfaceHit hit;
  hit.face = face;
  Vec2 uv = uv0;
  double t = t0;
  for (int iteration = 0;; ++iteration) {
    subdiv::LimitSample s = surface.evaluate(face, uv.x, uv.y);
    Vec3 residual = s.position - (ray.origin + ray.direction * t);
    if (length(residual) < tolerance) {
      if (t < ray.tNear || t > ray.tFar) break;  // converged outside the clipped ray
      hit.refined = true;
      hit.uv = uv;
      hit.t = t;
      hit.position = s.position;
      hit.normal = s.normal;
      hit.iterations = iteration;
      return hit;
    }
    if (iteration == kMaxIterations) break;
    // Solve [Pu Pv -d] (du, dv, dt) = -F by Cramer's rule.
    const Vec3& a = s.du;
    const Vec3& b = s.dv;
    const Vec3 c = -ray.direction;
    const Vec3 r = -residual;
    Vec3 bc = cross(b, c);
    double det = dot(a, bc);
    if (!(std::fabs(det) > 1e-14 * length(cross(a, b)))) break;  // ray in the tangent plane
    double du = dot(r, bc) / det;
    double dv = dot(a, cross(r, c)) / det;
    double dt = dot(a, cross(b, r)) / det;
    if (!std::isfinite(du) || !std::isfinite(dv) || !std::isfinite(dt)) break;
    if (std::hypot(du, dv) > kMaxStep) break;
    uv = {uv.x + du, uv.y + dv};
    t += dt;
    if (!domain.settle(&uv, &sub)) break;
  }
  return unrefinedHit(surface, face, uv0, ray, t0);
}

SurfaceHit unrefinedHit(const subdiv::LimitSurface& surface, int face, Vec2 uv, const PixelRay& ray,
                        double t) {
  SurfaceHit hit;
  hit.face = face;
  hit.uv = uv;
  hit.t = t;
  hit.position = ray.origin + ray.direction * t;
  hit.normal = surface.evaluate(face, uv.x, uv.y).normal;
  return hit;
}

}  // namespace limn::render::oracle
