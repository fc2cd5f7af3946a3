#include "render/silhouette/face_domain.h"

#include <opensubdiv/bfr/parameterization.h>

#include <algorithm>
#include <cmath>

namespace limn::render::silhouette {

namespace Bfr = OpenSubdiv::Bfr;

namespace {

constexpr double kTwoPi = 6.28318530717958647692;
constexpr double kEps = 1e-9;

// Corner k of the regular n-gon inscribed in the circle of radius 1/2 about (1/2, 1/2),
// counter-clockwise like the face's vertices (and like Bfr's corners of a quad).
Vec2 polygonCorner(int n, int k) {
  double a = kTwoPi * (k % n) / n;
  return {0.5 + 0.5 * std::cos(a), 0.5 + 0.5 * std::sin(a)};
}

Vec2 mid(const Vec2& a, const Vec2& b) { return {0.5 * (a.x + b.x), 0.5 * (a.y + b.y)}; }
double cross2(const Vec2& a, const Vec2& b) { return a.x * b.y - a.y * b.x; }
Vec2 minus(const Vec2& a, const Vec2& b) { return {a.x - b.x, a.y - b.y}; }

// (s, t) with p = c + s (m1 - c) + t (m0 - c) + s t (o - m1 - m0 + c), by Newton's method from
// the kite's centre (the map is a bilinear patch of a convex quadrilateral, so it converges).
Vec2 invertBilinear(const Vec2& c, const Vec2& m1, const Vec2& o, const Vec2& m0, const Vec2& p) {
  const Vec2 e1 = minus(m1, c), e0 = minus(m0, c);
  const Vec2 q{o.x - m1.x - m0.x + c.x, o.y - m1.y - m0.y + c.y};
  double s = 0.5, t = 0.5;
  for (int it = 0; it < 20; ++it) {
    Vec2 f{c.x + s * e1.x + t * e0.x + s * t * q.x - p.x,
           c.y + s * e1.y + t * e0.y + s * t * q.y - p.y};
    Vec2 ds{e1.x + t * q.x, e1.y + t * q.y}, dt{e0.x + s * q.x, e0.y + s * q.y};
    double det = cross2(ds, dt);
    if (det == 0) break;
    double stepS = cross2(f, dt) / det, stepT = cross2(ds, f) / det;
    s -= stepS;
    t -= stepT;
    if (std::fabs(stepS) + std::fabs(stepT) < 1e-15) break;
  }
  return {std::clamp(s, 0.0, 1.0), std::clamp(t, 0.0, 1.0)};
}

}  // namespace

FaceDomains::FaceDomains(const subdiv::LimitSurface& surface) : surface_(surface) {
  const int faces = surface.faceCount();
  kind_.assign(faces, Kind::Quad);
  sizes_.assign(faces, 4);
  for (int f = 0; f < faces; ++f) {
    sizes_[f] = surface.mesh().faceVertexCounts[f];
    if (!surface.hasLimit(f)) continue;
    Bfr::Parameterization param = surface.parameterization(f);
    kind_[f] = param.HasSubFaces()                             ? Kind::Polygon
               : param.GetType() == Bfr::Parameterization::TRI ? Kind::Triangle
                                                               : Kind::Quad;
  }
}

Vec2 FaceDomains::corner(int face, int k) const {
  if (kind_[face] == Kind::Polygon) return polygonCorner(sizes_[face], k);
  return surface_.cornerUV(face, k % sizes_[face]);
}

Vec2 FaceDomains::center(int face) const {
  if (kind_[face] == Kind::Polygon) return {0.5, 0.5};
  return surface_.centerUV(face);
}

Vec2 FaceDomains::alongEdge(int face, int k, double t) const {
  Vec2 a = corner(face, k), b = corner(face, k + 1);
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
}

bool FaceDomains::contains(int face, const Vec2& uv) const {
  const double eps = 1e-12;
  switch (kind_[face]) {
    case Kind::Quad:
      return uv.x >= -eps && uv.y >= -eps && uv.x <= 1 + eps && uv.y <= 1 + eps;
    case Kind::Triangle:
      return uv.x >= -eps && uv.y >= -eps && uv.x + uv.y <= 1 + eps;
    case Kind::Polygon:
      break;
  }
  const int n = sizes_[face];
  for (int k = 0; k < n; ++k) {
    if (cross2(minus(corner(face, k + 1), corner(face, k)), minus(uv, corner(face, k))) < -eps) {
      return false;
    }
  }
  return true;
}

bool FaceDomains::onOneSide(int face, const Vec2& a, const Vec2& b) const {
  const int n = sizes_[face];
  for (int k = 0; k < n; ++k) {
    Vec2 c0 = corner(face, k), side = minus(corner(face, k + 1), c0);
    double len = std::hypot(side.x, side.y);
    if (std::fabs(cross2(side, minus(a, c0))) < kEps * len &&
        std::fabs(cross2(side, minus(b, c0))) < kEps * len) {
      return true;
    }
  }
  return false;
}

Vec2 FaceDomains::toSurface(int face, const Vec2& uv) const {
  if (kind_[face] != Kind::Polygon) return uv;
  const int n = sizes_[face];
  // Kite k spans the angles within pi/n of corner k's, seen from the centre.
  double angle = std::atan2(uv.y - 0.5, uv.x - 0.5);
  if (angle < 0) angle += kTwoPi;
  const int k = static_cast<int>(std::lround(angle * n / kTwoPi)) % n;
  const Vec2 c = corner(face, k);
  const Vec2 m1 = mid(c, corner(face, k + 1)), m0 = mid(c, corner(face, k + n - 1));
  const Vec2 local = invertBilinear(c, m1, {0.5, 0.5}, m0, uv);
  const double sub[2] = {local.x, local.y};
  double out[2];
  surface_.parameterization(face).ConvertNormalizedSubFaceToCoord(k, sub, out);
  return {out[0], out[1]};
}

subdiv::LimitSample FaceDomains::evaluate(int face, const Vec2& uv) const {
  const Vec2 at = toSurface(face, uv);
  return surface_.evaluate(face, at.x, at.y);
}

}  // namespace limn::render::silhouette
