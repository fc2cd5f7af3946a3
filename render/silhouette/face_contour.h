// The contour inside one face (step 3 of the silhouette method): the face's boundary with the
// edge points the search found, the crossings paired into curves, and each curve sampled.
//
// Pairing. Around the boundary the crossings x0, x1, ... alternate the sign of g. Two
// crossings are joined trivially; with four or more, the curves either cut off the arcs
// x0->x1, x2->x3, ... or the arcs x1->x2, x3->x0, ...; the sign of g at the face centre says
// which region is the middle one (the asymptotic decider of marching squares).
//
// Curves. "pn": a cubic Bezier through the two points with PN-triangle inner control points
// b1 = (2 p0 + p1 - w01 n0) / 3, w01 = dot(p1 - p0, n0) (and symmetrically b2): the original
// heuristic, which can leave the surface. "exact": samples spread along the straight line
// between the two crossings in the face's parameter plane, each moved across that line onto
// g = 0 on the limit surface (bracketing, then bisection/false position), so every sample lies
// on the surface and its normal is perpendicular to the view.
#pragma once

#include <vector>

#include "render/core/camera.h"
#include "render/silhouette/contour_search.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

enum class CurveMode { PN, Exact };

struct FacePoint {
  Vec2 uv;        // in the face's domain (face_domain.h)
  Vec3 position;  // on the limit surface (pn curve samples excepted)
  Vec3 normal;    // the face's limit normal there
};

// A face's boundary, counter-clockwise in (u, v): corner 0, the edge points of edge 0 in
// order, corner 1, ... Edge points are those of the shared edge (every face of the edge has
// them); `crossing` says whether g changes sign there as seen from this face.
struct FaceBoundary {
  int face = -1;
  std::vector<FacePoint> points;
  std::vector<bool> crossing;
  std::vector<int> edge;       // base edge holding each edge point (-1 for corners)
  std::vector<int> edgePoint;  // index into ContourSearch::edgePoints[edge], -1 for corners
  int edgePointCount = 0;
};

struct FaceCurve {
  int from = -1, to = -1;          // boundary indices of its two crossings
  std::vector<FacePoint> samples;  // strictly between the two, in order from `from`
  int unresolved = 0;              // exact samples that found no root (left on the line)
};

struct CurveOptions {
  CurveMode mode = CurveMode::Exact;
  int curveSamples = 32;  // at most this many samples between two crossings
  double pixelsPerSample = 2.0;
  // Exact curves: more samples where a chord between two lies farther than this from the
  // curve in the image (a tight turn), within curveSamples.
  double maxSagPx = 0.1;
};

FaceBoundary faceBoundary(const FaceDomains& domains, const ContourSearch& search, int face);

// The face's crossings paired and sampled; empty when it has none. `oddCrossings` is set when
// the count is odd (numerical trouble at a vertex): then no curve is made.
std::vector<FaceCurve> faceCurves(const FaceDomains& domains, const Camera& camera,
                                  const FaceBoundary& boundary, const CurveOptions& options,
                                  bool* oddCrossings);

}  // namespace limn::render::silhouette
