#include "render/silhouette/face_contour.h"

#include <algorithm>
#include <cmath>

namespace limn::render::silhouette {

namespace Far = OpenSubdiv::Far;

namespace {

int signOf(double g) { return g < 0 ? -1 : 1; }

Vec2 lerp(const Vec2& a, const Vec2& b, double s) {
  return {a.x + (b.x - a.x) * s, a.y + (b.y - a.y) * s};
}

// g = 0 along a line across the curve, in one face's parameter domain.
class CrossLineSolver {
 public:
  CrossLineSolver(const FaceDomains& domains, const Camera& camera, int face)
      : domains_(domains), camera_(camera), face_(face) {}

  int face() const { return face_; }
  bool inside(const Vec2& uv) const { return domains_.contains(face_, uv); }

  double g(const Vec2& uv) const {
    subdiv::LimitSample s = domains_.evaluate(face_, uv);
    return contourFunction(camera_, s.position, s.normal);
  }

  // The root of g on origin + s * dir nearest s = 0, or false when none is bracketed inside
  // the domain. `reach` is the first step out from the origin.
  bool solve(const Vec2& origin, const Vec2& dir, double reach, Vec2* root) const {
    auto at = [&](double s) { return Vec2{origin.x + dir.x * s, origin.y + dir.y * s}; };
    double g0 = g(origin);
    if (g0 == 0) {
      *root = origin;
      return true;
    }
    double lo = 0, glo = g0, hi = 0, ghi = 0;
    bool bracketed = false;
    bool open[2] = {true, true};
    double last[2] = {0, 0}, lastG[2] = {g0, g0};
    for (double step = reach; !bracketed && (open[0] || open[1]) && step < 4; step *= 2) {
      for (int side = 0; side < 2 && !bracketed; ++side) {
        if (!open[side]) continue;
        double s = side == 0 ? step : -step;
        if (!inside(at(s))) {
          // Probe the domain edge itself once, then stop going this way.
          double inner = last[side], outer = s;
          for (int k = 0; k < 40; ++k) {
            double m = 0.5 * (inner + outer);
            (inside(at(m)) ? inner : outer) = m;
          }
          s = inner;
          open[side] = false;
          if (s == last[side]) continue;
        }
        double gs = g(at(s));
        if (signOf(gs) != signOf(g0)) {
          lo = last[side];
          glo = lastG[side];
          hi = s;
          ghi = gs;
          bracketed = true;
        }
        last[side] = s;
        lastG[side] = gs;
      }
    }
    if (!bracketed) return false;
    // Illinois false position: superlinear, and never leaves the bracket.
    int lastSide = 0;
    for (int it = 0; it < 40 && std::fabs(hi - lo) > 1e-10; ++it) {
      double s = hi - ghi * (hi - lo) / (ghi - glo);
      double gs = g(at(s));
      if (gs == 0) {
        lo = hi = s;
        break;
      }
      if (signOf(gs) == signOf(ghi)) {
        hi = s;
        ghi = gs;
        if (lastSide == 1) glo *= 0.5;
        lastSide = 1;
      } else {
        lo = s;
        glo = gs;
        if (lastSide == -1) ghi *= 0.5;
        lastSide = -1;
      }
    }
    *root = at(0.5 * (lo + hi));
    return true;
  }

 private:
  const FaceDomains& domains_;
  const Camera& camera_;
  int face_;
};

// Samples spaced evenly in (u, v) bunch where the curve turns fastest in the image least: at a
// tip (a slat's rounded end, a leaf's point, a leg's tapering end) two samples a few pixels
// apart cut the turn with a chord a pixel inside it (the held-out fence's slat end, 2.16 px),
// and a curve whose ends lie within 2 px had no sample at all (a leg's end cap, its contour
// round the tip 1.9 px across and 3.3 px long, cut straight across). Between two samples found
// on the curve (or the curve's ends), the curve's point halfway in (u, v) is found across
// their line; where it lies more than options.maxSagPx from their chord in the image it is
// added, and both halves are checked again, up to options.curveSamples samples in all. In a
// face with other curves, a point found farther off than the chord is long may lie on one of
// them (a hairpin's other leg), which the curve must not cross, and is not added; `alone`
// says there is no other.
void refineSagging(const FaceDomains& domains, const Camera& camera, const CrossLineSolver& solver,
                   const FacePoint& a, const FacePoint& b, const CurveOptions& options, bool alone,
                   std::vector<bool>& resolved, std::vector<FacePoint>& samples) {
  auto pointAt = [&](size_t i) -> const FacePoint& {  // 0: a, samples.size() + 1: b
    return i == 0 ? a : i == samples.size() + 1 ? b : samples[i - 1];
  };
  auto onCurve = [&](size_t i) { return i == 0 || i == samples.size() + 1 || resolved[i - 1]; };
  for (size_t i = 0;
       i <= samples.size() && static_cast<int>(samples.size()) < options.curveSamples;) {
    const FacePoint &p = pointAt(i), &q = pointAt(i + 1);
    const Vec2 along{q.uv.x - p.uv.x, q.uv.y - p.uv.y};
    const double span = std::hypot(along.x, along.y);
    const Vec3 pi = camera.project(p.position), qi = camera.project(q.position);
    const double chordPx = std::hypot(qi.x - pi.x, qi.y - pi.y);
    Vec2 uv = lerp(p.uv, q.uv, 0.5);
    const bool split = onCurve(i) && onCurve(i + 1) && span > 1e-6 && chordPx > options.maxSagPx &&
                       solver.solve(uv, {-along.y / span, along.x / span}, 0.02 * span, &uv);
    if (split) {
      const subdiv::LimitSample s = domains.evaluate(solver.face(), uv);
      const double sag = distanceToSegment2D(camera.project(s.position), pi, qi);
      if (sag > options.maxSagPx && (alone || sag < chordPx)) {
        samples.insert(samples.begin() + static_cast<long>(i), {uv, s.position, s.normal});
        resolved.insert(resolved.begin() + static_cast<long>(i), true);
        continue;  // the same i again: the first half
      }
    }
    ++i;
  }
}

// Samples strictly between boundary points a and b.
FaceCurve sampleCurve(const FaceDomains& domains, const Camera& camera,
                      const FaceBoundary& boundary, int from, int to, const CurveOptions& options,
                      bool alone) {
  FaceCurve curve;
  curve.from = from;
  curve.to = to;
  const FacePoint& a = boundary.points[from];
  const FacePoint& b = boundary.points[to];
  Vec3 pa = camera.project(a.position), pb = camera.project(b.position);
  double pixels = std::hypot(pa.x - pb.x, pa.y - pb.y);
  int count = std::clamp(static_cast<int>(std::ceil(pixels / options.pixelsPerSample)) - 1, 0,
                         std::max(0, options.curveSamples));
  curve.samples.reserve(count);

  if (options.mode == CurveMode::PN) {
    // The curve's (u, v) only decides the triangulation. When both ends lie on one edge, the
    // straight line between them would run along the edge: bow it towards the face centre.
    Vec2 bow{0, 0};
    if (boundary.edge[from] == boundary.edge[to]) {
      Vec2 c = domains.center(boundary.face), mid = lerp(a.uv, b.uv, 0.5);
      bow = {0.5 * (c.x - mid.x), 0.5 * (c.y - mid.y)};
    }
    Vec3 d = b.position - a.position;
    Vec3 b1 = (2.0 * a.position + b.position - dot(d, a.normal) * a.normal) / 3.0;
    Vec3 b2 = (2.0 * b.position + a.position + dot(d, b.normal) * b.normal) / 3.0;
    for (int i = 1; i <= count; ++i) {
      double s = static_cast<double>(i) / (count + 1), r = 1 - s;
      Vec3 p =
          r * r * r * a.position + 3 * r * r * s * b1 + 3 * r * s * s * b2 + s * s * s * b.position;
      Vec2 uv = lerp(a.uv, b.uv, s);
      uv = {uv.x + 4 * s * r * bow.x, uv.y + 4 * s * r * bow.y};
      curve.samples.push_back({uv, p, normalize(r * a.normal + s * b.normal)});
    }
    return curve;
  }

  CrossLineSolver solver(domains, camera, boundary.face);
  Vec2 along{b.uv.x - a.uv.x, b.uv.y - a.uv.y};
  double span = std::hypot(along.x, along.y);
  Vec2 across = span > 0 ? Vec2{-along.y / span, along.x / span} : Vec2{1, 0};
  std::vector<bool> resolved;
  for (int i = 1; i <= count; ++i) {
    Vec2 origin = lerp(a.uv, b.uv, static_cast<double>(i) / (count + 1));
    Vec2 uv = origin;
    const bool found = solver.solve(origin, across, std::max(0.02 * span, 1e-4), &uv);
    if (!found) ++curve.unresolved;
    subdiv::LimitSample s = domains.evaluate(boundary.face, uv);
    curve.samples.push_back({uv, s.position, s.normal});
    resolved.push_back(found);
  }
  refineSagging(domains, camera, solver, a, b, options, alone, resolved, curve.samples);
  return curve;
}

}  // namespace

FaceBoundary faceBoundary(const FaceDomains& domains, const ContourSearch& search, int face) {
  const subdiv::LimitSurface& surface = domains.surface();
  const Far::TopologyLevel& base = surface.baseLevel();
  Far::ConstIndexArray verts = base.GetFaceVertices(face);
  Far::ConstIndexArray edges = base.GetFaceEdges(face);
  const size_t offset = search.faceOffsets[face];
  FaceBoundary out;
  out.face = face;
  auto push = [&](const FacePoint& p, bool crossing, int edge, int edgePoint) {
    out.points.push_back(p);
    out.crossing.push_back(crossing);
    out.edge.push_back(edge);
    out.edgePoint.push_back(edgePoint);
  };
  for (int k = 0; k < verts.size(); ++k) {
    push({domains.corner(face, k), surface.controlLimitPositions()[verts[k]],
          search.cornerNormals[offset + k]},
         false, -1, -1);
    const int e = edges[k];
    const std::vector<EdgePoint>& points = search.edgePoints[e];
    if (points.empty()) continue;
    Far::ConstIndexArray edgeFaces = base.GetEdgeFaces(e);
    int bit = 0;
    while (bit < edgeFaces.size() && edgeFaces[bit] != face) ++bit;
    const bool forward = base.GetEdgeVertices(e)[0] == verts[k];
    for (size_t j = 0; j < points.size(); ++j) {
      size_t i = forward ? j : points.size() - 1 - j;
      Vec2 uv = edgeUV(domains, face, e, points[i].t);
      push({uv, points[i].position, domains.evaluate(face, uv).normal},
           bit < 32 && (points[i].sides >> bit & 1u), e, static_cast<int>(i));
      ++out.edgePointCount;
    }
  }
  return out;
}

std::vector<FaceCurve> faceCurves(const FaceDomains& domains, const Camera& camera,
                                  const FaceBoundary& boundary, const CurveOptions& options,
                                  bool* oddCrossings) {
  std::vector<int> x;
  for (size_t i = 0; i < boundary.points.size(); ++i) {
    if (boundary.crossing[i]) x.push_back(static_cast<int>(i));
  }
  if (oddCrossings) *oddCrossings = x.size() % 2 != 0;
  if (x.empty() || x.size() % 2 != 0) return {};

  int offset = 0;
  if (x.size() > 2) {
    CrossLineSolver solver(domains, camera, boundary.face);
    Vec2 c = domains.center(boundary.face);
    // The arc from x1 towards x2 starts with the boundary segment after x1.
    const size_t n = boundary.points.size();
    Vec2 arc = lerp(boundary.points[x[1]].uv, boundary.points[(x[1] + 1) % n].uv, 0.5);
    offset = signOf(solver.g(c)) == signOf(solver.g(arc)) ? 0 : 1;
  }
  std::vector<FaceCurve> curves;
  for (size_t i = 0; i < x.size(); i += 2) {
    int from = x[(i + offset) % x.size()], to = x[(i + offset + 1) % x.size()];
    curves.push_back(sampleCurve(domains, camera, boundary, from, to, options, x.size() == 2));
  }
  return curves;
}

}  // namespace limn::render::silhouette
