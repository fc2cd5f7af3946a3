#include "render/silhouette/chord_refinement.h"

#include <algorithm>
#include <cmath>

#include "render/core/parallel.h"

namespace limn::render::silhouette {

namespace Far = OpenSubdiv::Far;

namespace {

// Segments that bring a sag of `sagPx` under `tolerancePx` (sag ~ 1 / segments^2).
int segmentsFor(double sagPx, const ChordOptions& options) {
  if (!(sagPx > options.tolerancePx)) return 1;
  int n = static_cast<int>(std::ceil(std::sqrt(sagPx / options.tolerancePx)));
  return std::clamp(n, 2, std::max(2, options.maxSegments));
}

void sortByT(std::vector<EdgePoint>& points) {
  std::sort(points.begin(), points.end(),
            [](const EdgePoint& a, const EdgePoint& b) { return a.t < b.t; });
}

// The uniform points bring the chord's sag under the tolerance where the edge bends evenly; an
// edge into an infinitely sharp corner bends most next to it (the spike's cusp), so segments
// between the points (crossings included) still over the tolerance are halved until they are
// not, with at most options.maxSegments points on the edge. True when it added any.
template <typename Evaluate>
bool halveOutsideSegments(const Camera& camera, const Vec3& first, const Vec3& last,
                          const Evaluate& at, int side, const ChordOptions& options,
                          std::vector<EdgePoint>& points) {
  bool added = false;
  for (size_t i = 0; i <= points.size();) {
    if (static_cast<int>(points.size()) >= options.maxSegments) break;
    const double t0 = i == 0 ? 0.0 : points[i - 1].t;
    const double t1 = i == points.size() ? 1.0 : points[i].t;
    const Vec3& p0 = i == 0 ? first : points[i - 1].position;
    const Vec3& p1 = i == points.size() ? last : points[i].position;
    const double t = 0.5 * (t0 + t1);
    const subdiv::LimitSample middle = at(t);
    if (t1 - t0 < 1e-4 ||
        outsidePixels(camera, 0.5 * (p0 + p1), middle, side) <= options.tolerancePx) {
      ++i;
      continue;
    }
    points.insert(points.begin() + static_cast<long>(i), {t, middle.position, 0u});
    added = true;  // the same i again: the first half of the segment
  }
  return added;
}
}  // namespace

double outsidePixels(const Camera& camera, const Vec3& chordPoint,
                     const subdiv::LimitSample& sample, int side) {
  const double offset = dot(chordPoint - sample.position, sample.normal);
  if (side == 0 ? offset == 0 : side * offset <= 0) return 0;
  Vec3 a = camera.project(chordPoint), b = camera.project(sample.position);
  return std::hypot(a.x - b.x, a.y - b.y);
}

std::vector<bool> contourFaces(const subdiv::LimitSurface& surface, const ContourSearch& search) {
  const Far::TopologyLevel& base = surface.baseLevel();
  std::vector<bool> out(surface.faceCount(), false);
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    Far::ConstIndexArray faces = base.GetEdgeFaces(e);
    for (const EdgePoint& p : search.edgePoints[e]) {
      for (int k = 0; k < faces.size() && k < 32; ++k) {
        if (p.sides >> k & 1u) out[faces[k]] = true;
      }
    }
  }
  return out;
}

ChordRefinement refineConcaveChords(const FaceDomains& domains, const Camera& camera,
                                    const std::vector<bool>& contourFace,
                                    const ChordOptions& options, ContourSearch& search) {
  const subdiv::LimitSurface& surface = domains.surface();
  const Far::TopologyLevel& base = surface.baseLevel();
  const std::vector<Vec3>& limit = surface.controlLimitPositions();
  ChordRefinement out;
  out.edgeRates.assign(base.GetNumEdges(), 0);
  out.interiorRates.assign(surface.faceCount(), 0);

  // The contour faces and `options.rings` rings of faces around them (sharing a vertex).
  std::vector<bool> near = contourFace;
  for (int ring = 0; ring < options.rings; ++ring) {
    std::vector<bool> grown = near;
    for (int f = 0; f < surface.faceCount(); ++f) {
      if (!near[f]) continue;
      for (int v : base.GetFaceVertices(f)) {
        for (int g : base.GetVertexFaces(v)) grown[g] = true;
      }
    }
    near.swap(grown);
  }
  std::vector<bool> candidate(base.GetNumEdges(), false);
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!near[f] || !surface.hasLimit(f)) continue;
    for (int e : base.GetFaceEdges(f)) candidate[e] = true;
  }

  parallelFor(base.GetNumEdges(), 64, [&](size_t begin, size_t end) {
    for (size_t e = begin; e < end; ++e) {
      if (!candidate[e]) continue;
      std::vector<EdgePoint>& points = search.edgePoints[e];
      bool outline = std::any_of(points.begin(), points.end(),
                                 [](const EdgePoint& p) { return p.sides == 0; });
      if (outline) continue;
      int owner = -1;
      for (int f : base.GetEdgeFaces(static_cast<int>(e))) {
        if (surface.hasLimit(f)) {
          owner = f;
          break;
        }
      }
      if (owner < 0) continue;
      Far::ConstIndexArray ends = base.GetEdgeVertices(static_cast<int>(e));
      auto at = [&](double t) {
        return domains.evaluate(owner, edgeUV(domains, owner, static_cast<int>(e), t));
      };
      int segments = segmentsFor(outsidePixels(camera, 0.5 * (limit[ends[0]] + limit[ends[1]]),
                                               at(0.5), outsideSide(surface, owner)),
                                 options);
      if (segments >= 2) {
        out.edgeRates[e] = segments;
        for (int i = 1; i < segments; ++i) {
          double t = static_cast<double>(i) / segments;
          points.push_back({t, at(t).position, 0u});
        }
        sortByT(points);
      }
      if (halveOutsideSegments(camera, limit[ends[0]], limit[ends[1]], at,
                               outsideSide(surface, owner), options, points)) {
        out.edgeRates[e] = std::max(out.edgeRates[e], 2);
      }
    }
  });
  for (int rate : out.edgeRates) out.refinedEdges += rate > 0;

  // Interiors of ring faces (contour faces are cut by their curves instead).
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!near[f] || contourFace[f] || !surface.hasLimit(f)) continue;
    Vec3 centroid{0, 0, 0};
    Far::ConstIndexArray verts = base.GetFaceVertices(f);
    for (int v : verts) centroid += limit[v];
    centroid = centroid / static_cast<double>(verts.size());
    int rate = segmentsFor(outsidePixels(camera, centroid, domains.evaluate(f, domains.center(f)),
                                         outsideSide(surface, f)),
                           options);
    for (int e : base.GetFaceEdges(f)) rate = std::max(rate, out.edgeRates[e]);
    if (rate < 2) continue;
    out.interiorRates[f] = rate;
    ++out.refinedFaces;
  }
  return out;
}

}  // namespace limn::render::silhouette
