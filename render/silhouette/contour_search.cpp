#include "render/silhouette/contour_search.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

#include "render/core/parallel.h"
#include "render/mesh/control_mesh.h"
#include "render/silhouette/edge_tables.h"

namespace limn::render::silhouette {

namespace Far = OpenSubdiv::Far;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Corner normals this close to the vertex's shared normal are taken as the same normal, so
// faces around a smooth vertex agree exactly on the sign of g there.
constexpr double kSameNormalCos = 1.0 - 1e-10;

int signOf(double g) { return g < 0 ? -1 : 1; }

double angleBetween(const Vec3& a, const Vec3& b) {
  double c = dot(normalize(a), normalize(b));
  return std::acos(std::clamp(c, -1.0, 1.0));
}

// Where the edge sits in a face: its index among the face's edges and whether the face runs
// along it from the edge's first vertex to its second.
struct EdgeInFace {
  int corner = -1;
  bool forward = true;
};

EdgeInFace locateEdge(const Far::TopologyLevel& base, int face, int edge) {
  Far::ConstIndexArray edges = base.GetFaceEdges(face);
  Far::ConstIndexArray verts = base.GetFaceVertices(face);
  for (int k = 0; k < edges.size(); ++k) {
    if (edges[k] == edge) return {k, verts[k] == base.GetEdgeVertices(edge)[0]};
  }
  return {};
}

// g along one edge as seen from one face. With SearchOptions::edgeTables, where the tables cover
// the edge (gathered on the first sample, as most edges are never sampled), g at t = k/128 is
// summed from them; every other t (the slope probes, the extremum) and every other edge goes
// to the face's surface.
class EdgeProbe {
 public:
  EdgeProbe(const FaceDomains& domains, const Camera& camera, int face, int edge, bool useTables)
      : domains_(domains),
        camera_(camera),
        face_(face),
        edge_(edge),
        from_(edgeUV(domains, face, edge, 0.0)),
        to_(edgeUV(domains, face, edge, 1.0)),
        tablesLookedUp_(!useTables) {}

  double g(double t) const {
    const double step = t * kEdgeTableSteps;
    if (step == std::floor(step)) {
      if (const EdgeCurve* curve = tables()) {
        EdgeSample s = curve->sample(static_cast<int>(step));
        return contourFunction(camera_, s.position, s.normal);
      }
    }
    return surfaceG(t);
  }
  // Both ends of the difference from the surface, also where one is t = 0 or 1.
  double slope(double t) const {
    const double h = 1e-4;
    double a = std::max(0.0, t - h), b = std::min(1.0, t + h);
    return (surfaceG(b) - surfaceG(a)) / (b - a);
  }
  bool onTables() const { return curve_.has_value(); }

 private:
  const EdgeCurve* tables() const {
    if (!tablesLookedUp_) {
      tablesLookedUp_ = true;
      const subdiv::LimitSurface& surface = domains_.surface();
      if (auto support = gatherEdgeSupport(surface.baseLevel(), surface.mesh().scheme, edge_)) {
        curve_.emplace(*support, surface.mesh().points, surface.mesh().scheme);
      }
    }
    return curve_ ? &*curve_ : nullptr;
  }
  double surfaceG(double t) const {
    subdiv::LimitSample s = domains_.evaluate(
        face_, {from_.x + (to_.x - from_.x) * t, from_.y + (to_.y - from_.y) * t});
    return contourFunction(camera_, s.position, s.normal);
  }

  const FaceDomains& domains_;
  const Camera& camera_;
  int face_, edge_;
  Vec2 from_, to_;
  // Looked up lazily from the const g(); a probe serves one edge on one thread.
  mutable bool tablesLookedUp_;
  mutable std::optional<EdgeCurve> curve_;
};

// Narrows a sign change of g in [a, b] by bisection, then interpolates linearly.
double findCrossing(const EdgeProbe& probe, double a, double ga, double b, double gb, int steps) {
  for (int i = 0; i < steps; ++i) {
    double m = 0.5 * (a + b);
    double gm = probe.g(m);
    if (signOf(gm) == signOf(ga)) {
      a = m;
      ga = gm;
    } else {
      b = m;
      gb = gm;
    }
  }
  double denom = ga - gb;
  return denom != 0 ? a + (b - a) * (ga / denom) : 0.5 * (a + b);
}

}  // namespace

double contourFunction(const Camera& camera, const Vec3& position, const Vec3& normal) {
  return dot(normal, camera.viewVector(position));
}

Vec2 edgeUV(const FaceDomains& domains, int face, int edge, double t) {
  EdgeInFace where = locateEdge(domains.surface().baseLevel(), face, edge);
  return domains.alongEdge(face, where.corner, where.forward ? t : 1 - t);
}

namespace {

// Interior points sampled for a loop: on the fan from the domain's centre to each edge.
constexpr double kLoopFanSteps[] = {0.25, 0.5, 0.75};

// True when g keeps the corners' sign nowhere inside `face` can be ruled out and a sample
// inside has the other sign (ContourSearch::loopFaces).
bool holdsContourLoop(const FaceDomains& domains, const Camera& camera, const ContourSearch& out,
                      int face) {
  const subdiv::LimitSurface& surface = domains.surface();
  const std::vector<Vec3>& limitPositions = surface.controlLimitPositions();
  const mesh::ControlMesh& cage = surface.mesh();
  const size_t first = out.faceOffsets[face], last = out.faceOffsets[face + 1];
  const int sign = signOf(out.cornerG[first]);
  double nearest = kPi, turnNormals = 0, turnRays = 0;
  for (size_t i = first; i < last; ++i) {
    if (signOf(out.cornerG[i]) != sign) return false;  // its edges hold the crossings
    const Vec3 ray = camera.viewVector(limitPositions[cage.faceVertexIndices[i]]);
    nearest = std::min(nearest, std::asin(std::min(1.0, std::fabs(out.cornerG[i]) /
                                                            std::max(length(ray), 1e-300))));
    for (size_t j = first; j < i; ++j) {
      turnNormals = std::max(turnNormals, angleBetween(out.cornerNormals[i], out.cornerNormals[j]));
      turnRays =
          std::max(turnRays,
                   angleBetween(ray, camera.viewVector(limitPositions[cage.faceVertexIndices[j]])));
    }
  }
  if (nearest > 1.5 * turnNormals + turnRays + kPi / 180.0) return false;
  const int corners = static_cast<int>(last - first);
  const Vec2 centre = domains.center(face);
  auto differs = [&](const Vec2& uv) {
    const subdiv::LimitSample s = domains.evaluate(face, uv);
    return signOf(contourFunction(camera, s.position, s.normal)) != sign;
  };
  if (differs(centre)) return true;
  for (int k = 0; k < corners; ++k) {
    const Vec2 a = domains.corner(face, k), b = domains.corner(face, (k + 1) % corners);
    for (double s : kLoopFanSteps) {
      for (double t : kLoopFanSteps) {
        const Vec2 edge{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
        if (differs({centre.x + s * (edge.x - centre.x), centre.y + s * (edge.y - centre.y)})) {
          return true;
        }
      }
    }
  }
  return false;
}

// The faces holding a contour loop, in face order.
std::vector<int> findLoopFaces(const FaceDomains& domains, const Camera& camera,
                               const ContourSearch& out, const CancelToken& cancel) {
  const subdiv::LimitSurface& surface = domains.surface();
  const Far::TopologyLevel& base = surface.baseLevel();
  const int faceCount = surface.faceCount();
  std::vector<char> loop(faceCount, 0);
  parallelFor(faceCount, 64, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      if ((f & 255) == 0) cancel.check();
      const int face = static_cast<int>(f);
      if (!surface.hasLimit(face)) continue;
      bool crossed = false;
      for (int e : base.GetFaceEdges(face)) crossed = crossed || !out.edgePoints[e].empty();
      loop[f] = !crossed && holdsContourLoop(domains, camera, out, face);
    }
  });
  std::vector<int> faces;
  for (int f = 0; f < faceCount; ++f) {
    if (loop[f]) faces.push_back(f);
  }
  return faces;
}

// The face's own limit normal at its corner `k` where it differs from the vertex's (a sharp
// feature), taken a hair inside the face. At the corner itself Bfr's normal is the cross product
// of the derivatives along the face's two edges, which points the wrong way where the face's
// limit region turns back on itself there: a reflex corner of a flat n-gon between infinitely
// sharp edges (a gear's cap between two teeth) read (0, +1, 0) on a cap facing (0, -1, 0), and
// the edge search found contour curves on a flat cap whose triangles then spanned the gaps
// between the teeth (20 px on a scene of gears).
Vec3 faceNormalAtCorner(const FaceDomains& domains, int face, int k) {
  constexpr double kInside = 1e-4;  // of the way from the corner to the face's centre in (u, v)
  const Vec2 corner = domains.corner(face, k), centre = domains.center(face);
  const Vec2 uv{corner.x + kInside * (centre.x - corner.x),
                corner.y + kInside * (centre.y - corner.y)};
  return domains.evaluate(face, uv).normal;
}

// The length in the image of an outline edge's limit curve, as a polyline through `pieces` + 1
// uniform points: a short edge can bulge far past the chord between its ends (a leaf's rounded
// lobe at its tip, a boundary edge 1.7 px end to end whose curve stands 1.4 px off that chord).
double projectedLengthPx(const FaceDomains& domains, const Camera& camera, int face, int edge,
                         int pieces) {
  double length = 0;
  Vec3 last = camera.project(domains.position(face, edgeUV(domains, face, edge, 0.0)));
  for (int i = 1; i <= pieces; ++i) {
    const double t = static_cast<double>(i) / pieces;
    const Vec3 next = camera.project(domains.position(face, edgeUV(domains, face, edge, t)));
    length += std::hypot(next.x - last.x, next.y - last.y);
    last = next;
  }
  return length;
}

// The fewest uniform segments along an outline edge's limit curve whose chords stay within
// `tolerancePx` of it in the image, judged at `dense` uniform samples (the most it returns).
// A straight crease (a shelf's board, a box's edge) needs no interior point at all, where one
// every two pixels tripled the triangles of a piecewise flat model; a curved one needs about
// the square root of its sag over the tolerance.
int outlineSegments(const FaceDomains& domains, const Camera& camera, int face, int edge, int dense,
                    double tolerancePx) {
  auto imageAt = [&](double t) {
    return camera.project(domains.position(face, edgeUV(domains, face, edge, t)));
  };
  std::vector<Vec3> samples(dense + 1);
  for (int i = 0; i <= dense; ++i) samples[i] = imageAt(static_cast<double>(i) / dense);
  for (int n = 1; n < dense; n *= 2) {
    std::vector<Vec3> chords(n + 1);
    for (int j = 0; j <= n; ++j) {
      chords[j] = j == 0   ? samples.front()
                  : j == n ? samples.back()
                           : imageAt(static_cast<double>(j) / n);
    }
    bool within = true;
    for (int i = 1; i < dense && within; ++i) {
      const double t = static_cast<double>(i) / dense;
      const int j = std::min(n - 1, static_cast<int>(t * n));
      within = distanceToSegment2D(samples[i], chords[j], chords[j + 1]) <= tolerancePx;
    }
    if (within) return n;
  }
  return dense;
}

}  // namespace

ContourSearch searchContour(const FaceDomains& domains, const Camera& camera,
                            const SearchOptions& options, const CancelToken& cancel) {
  const subdiv::LimitSurface& surface = domains.surface();
  const mesh::ControlMesh& cage = surface.mesh();
  const Far::TopologyLevel& base = surface.baseLevel();
  const std::vector<Vec3>& limitPositions = surface.controlLimitPositions();
  const std::vector<Vec3>& limitNormals = surface.controlLimitNormals();
  ContourSearch out;

  // g at every face corner.
  out.faceOffsets.resize(cage.faceCount() + 1, 0);
  for (int f = 0; f < cage.faceCount(); ++f) {
    out.faceOffsets[f + 1] = out.faceOffsets[f] + cage.faceVertexCounts[f];
  }
  out.cornerG.resize(cage.faceVertexIndices.size());
  out.cornerNormals.resize(cage.faceVertexIndices.size());
  parallelFor(cage.faceCount(), 64, [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      for (size_t i = out.faceOffsets[f]; i < out.faceOffsets[f + 1]; ++i) {
        int v = cage.faceVertexIndices[i];
        Vec3 n = limitNormals[v];
        if (surface.hasLimit(static_cast<int>(f))) {
          const int k = static_cast<int>(i - out.faceOffsets[f]);
          Vec3 own =
              domains.evaluate(static_cast<int>(f), domains.corner(static_cast<int>(f), k)).normal;
          if (dot(own, n) < kSameNormalCos) n = faceNormalAtCorner(domains, static_cast<int>(f), k);
        }
        out.cornerNormals[i] = n;
        out.cornerG[i] = contourFunction(camera, limitPositions[v], n);
      }
    }
  });
  cancel.check();

  auto cornerIndex = [&](int face, int vertex) {
    for (size_t i = out.faceOffsets[face]; i < out.faceOffsets[face + 1]; ++i) {
      if (cage.faceVertexIndices[i] == vertex) return i;
    }
    return out.faceOffsets[face];
  };

  auto endNormalsDisagree = [&](Far::ConstIndexArray faces, Far::ConstIndexArray ends) {
    for (int end : {ends[0], ends[1]}) {
      const Vec3& a = out.cornerNormals[cornerIndex(faces[0], end)];
      const Vec3& b = out.cornerNormals[cornerIndex(faces[1], end)];
      if (dot(a, b) < kSameNormalCos) return true;
    }
    return false;
  };

  std::atomic<size_t> tested{0}, signChanges{0}, sampled{0}, doubles{0}, outlines{0}, onTables{0};
  out.edgePoints.resize(base.GetNumEdges());
  parallelFor(base.GetNumEdges(), 64, [&](size_t begin, size_t end) {
    std::vector<EdgePoint> found;
    for (size_t e = begin; e < end; ++e) {
      if ((e & 255) == 0) cancel.check();
      Far::ConstIndexArray faces = base.GetEdgeFaces(static_cast<int>(e));
      Far::ConstIndexArray ends = base.GetEdgeVertices(static_cast<int>(e));
      int validFaces = 0;
      uint32_t allSides = 0;
      for (int k = 0; k < faces.size() && k < 32; ++k) {
        if (!surface.hasLimit(faces[k])) continue;
        ++validFaces;
        allSides |= 1u << k;
      }
      if (validFaces == 0) continue;
      ++tested;
      const bool crease = validFaces > 2 ||
                          (validFaces == 2 &&
                           base.GetEdgeSharpness(static_cast<int>(e)) >= mesh::kInfiniteSharpness);
      // Faces that disagree on the normal at an end (an infinitely sharp corner, a dart, a
      // valence-2 vertex) see g jump there: each face's crossings must come from its own g,
      // or the count around a face comes out odd and its contour is lost.
      const bool split = crease || (validFaces == 2 && endNormalsDisagree(faces, ends));

      found.clear();
      bool signChange = false, wasSampled = false, sideSignsDiffer = false;
      int firstSign[2] = {0, 0};
      for (int k = 0; k < faces.size() && k < 32; ++k) {
        if (!(allSides >> k & 1u)) continue;
        const int face = faces[k];
        size_t c0 = cornerIndex(face, ends[0]), c1 = cornerIndex(face, ends[1]);
        double g0 = out.cornerG[c0], g1 = out.cornerG[c1];
        EdgeProbe probe(domains, camera, face, static_cast<int>(e), options.edgeTables);
        const uint32_t bits = split ? (1u << k) : allSides;

        bool sample = signOf(g0) != signOf(g1);
        signChange = signChange || sample;
        if (firstSign[0] == 0) {
          firstSign[0] = signOf(g0);
          firstSign[1] = signOf(g1);
        } else if (firstSign[0] != signOf(g0) || firstSign[1] != signOf(g1)) {
          sideSignsDiffer = true;
        }
        const size_t foundBefore = found.size();
        if (!sample) {
          const Vec3& p0 = limitPositions[ends[0]];
          const Vec3& p1 = limitPositions[ends[1]];
          Vec3 v0 = camera.viewVector(p0), v1 = camera.viewVector(p1);
          double phi0 = std::asin(std::min(1.0, std::fabs(g0) / std::max(length(v0), 1e-300)));
          double phi1 = std::asin(std::min(1.0, std::fabs(g1) / std::max(length(v1), 1e-300)));
          double turn = 1.5 * angleBetween(out.cornerNormals[c0], out.cornerNormals[c1]) +
                        angleBetween(v0, v1) + kPi / 180.0;
          sample = std::min(phi0, phi1) <= turn;
        }
        if (sample) {
          wasSampled = true;
          const int intervals = std::max(1, options.edgeSamples);
          std::vector<double> ts(intervals + 1), gs(intervals + 1);
          for (int i = 0; i <= intervals; ++i) {
            ts[i] = static_cast<double>(i) / intervals;
            gs[i] = i == 0 ? g0 : (i == intervals ? g1 : probe.g(ts[i]));
          }
          for (int i = 0; i < intervals; ++i) {
            double a = ts[i], b = ts[i + 1];
            if (signOf(gs[i]) != signOf(gs[i + 1])) {
              found.push_back(
                  {findCrossing(probe, a, gs[i], b, gs[i + 1], options.searchSteps), {}, bits});
              continue;
            }
            // Same sign at both ends: look for an extremum that reaches the other sign.
            const int sign = signOf(gs[i]);
            if (!(sign * probe.slope(a) < 0 && sign * probe.slope(b) > 0)) continue;
            double lo = a, hi = b;
            for (int step = 0; step < 12; ++step) {
              double m = 0.5 * (lo + hi);
              (sign * probe.slope(m) < 0 ? lo : hi) = m;
            }
            double tm = 0.5 * (lo + hi), gm = probe.g(tm);
            if (signOf(gm) == sign) continue;
            found.push_back({findCrossing(probe, a, gs[i], tm, gm, options.searchSteps), {}, bits});
            found.push_back(
                {findCrossing(probe, tm, gm, b, gs[i + 1], options.searchSteps), {}, bits});
          }
        }
        if (signOf(g0) == signOf(g1) && found.size() > foundBefore) ++doubles;
        if (probe.onTables()) ++onTables;
        if (!split) break;  // one face sees the whole edge
      }
      int owner = -1;  // the edge's first face with a limit surface: it positions the points
      for (int k = 0; k < faces.size() && owner < 0; ++k) {
        if (allSides >> k & 1u) owner = faces[k];
      }
      // Outline edges: shaped along their limit curve wherever they could show.
      const bool outline = validFaces == 1 || (crease && (sideSignsDiffer || !found.empty()));
      if (outline) {
        ++outlines;
        const double pixels = projectedLengthPx(domains, camera, owner, static_cast<int>(e), 8);
        int segments = std::clamp(static_cast<int>(std::ceil(pixels / options.pixelsPerSample)), 1,
                                  std::max(1, options.outlineSamples + 1));
        if (segments > 1) {
          segments = outlineSegments(domains, camera, owner, static_cast<int>(e), segments,
                                     options.outlineTolerancePx);
        }
        for (int i = 1; i < segments; ++i) {
          found.push_back({static_cast<double>(i) / segments, {}, 0u});
        }
      }
      if (signChange) ++signChanges;
      if (wasSampled) ++sampled;
      if (found.empty()) continue;

      // One point per distinct parameter, positioned once in the edge's first face.
      std::sort(found.begin(), found.end(),
                [](const EdgePoint& a, const EdgePoint& b) { return a.t < b.t; });
      std::vector<EdgePoint>& points = out.edgePoints[e];
      for (const EdgePoint& p : found) {
        if (!points.empty() && p.t - points.back().t < 1e-9) {
          points.back().sides |= p.sides;
          continue;
        }
        EdgePoint q = p;
        q.position = domains.position(owner, edgeUV(domains, owner, static_cast<int>(e), q.t));
        points.push_back(q);
      }
    }
  });
  cancel.check();

  out.loopFaces = findLoopFaces(domains, camera, out, cancel);

  out.stats.edgesTested = tested;
  out.stats.edgesWithSignChange = signChanges;
  out.stats.edgesSampled = sampled;
  out.stats.doubleCrossings = doubles;
  out.stats.outlineEdges = outlines;
  out.stats.edgesOnTables = onTables;
  for (const auto& points : out.edgePoints) out.stats.contourPoints += points.size();
  out.stats.interiorLoopFaces = out.loopFaces.size();
  return out;
}

}  // namespace limn::render::silhouette
