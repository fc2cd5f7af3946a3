// Contour polylines: the per-face contour curves of a SilhouetteMesh chained across faces into
// the lines a user sees (the outline, inner outlines, the loops of a torus), each point with its
// 3D position, its projection, and where on the surface it lies.
//
// Two curves join where they share an edge point: the same base edge and the same index into
// ContourSearch::edgePoints[edge], the identity every face of the edge uses. A chain is closed
// when it comes back to the edge point it started from; an open chain ends at an edge point
// only one curve uses (a contour running into a boundary, a hole, or an infinitely sharp edge
// whose other face sees no crossing there). Where more than two curves share an edge point
// (non-manifold edges), chains are joined greedily in curve order.
//
// Visibility and pieces are not decided here (that needs the reference surface, see
// oracle/visibility.h); splitPieces() cuts a polyline once each point has been marked.
#pragma once

#include <vector>

#include "render/core/camera.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

struct PolylinePoint {
  Vec3 position;           // 3D, on the limit surface ("exact" curves and edge points)
  Vec3 normal;             // the limit normal there: perpendicular to the view on the contour
  Vec3 pixel;              // Camera::project: x right, y down (pixels), z = linear depth
  int face = -1;           // face of the surface the curves were found on (after pre-subdivision)
  Vec2 uv;                 // in that face's parameterisation
  bool edgePoint = false;  // on a control edge: a junction of two curves, or an open end
};

struct ContourPolyline {
  bool closed = false;
  // In order along the line. A closed polyline does not repeat its first point at the end.
  // A point shared by two curves appears once, with the face and (u, v) of the curve that
  // reaches it first along the line.
  std::vector<PolylinePoint> points;
  std::vector<int> curves;  // indices into the curves it was chained from, in order
};

// Every curve is used by exactly one polyline. Closed polylines come first, then open ones;
// within each kind, in the order of their first curve.
std::vector<ContourPolyline> chainContourCurves(const std::vector<ContourCurve>& curves,
                                                const Camera& camera);

// How far the point is from the limit surface along the surface normal at its (face, u, v):
// 0 up to rounding for "exact" samples and edge points, the curve's departure from the surface
// for "pn" samples and for exact samples left on the chord. Visibility tests widen their
// tolerance by it (oracle/visibility.h).
double distanceFromSurface(const subdiv::LimitSurface& surface, const PolylinePoint& point);

// A maximal run of points with the same visibility: points [start, end] of a polyline.
struct PolylinePiece {
  int start = 0, end = 0;  // inclusive
  bool visible = true;
};

// Cuts a polyline into pieces by the visibility of its points (one flag per point). A closed
// polyline whose visibility changes is first rotated (its points and `visible`) so that point
// 0 starts a piece: no piece wraps around. The segment between the last point of one piece and
// the first of the next belongs to neither; drawings split it at its midpoint.
std::vector<PolylinePiece> splitPieces(ContourPolyline& polyline, std::vector<bool>& visible);

}  // namespace limn::render::silhouette
