// The contour search over the control edges (step 2 of the silhouette method).
//
// A point p of the limit surface with unit normal n lies on the contour when
//   g = dot(n, viewVector(p)) = 0      (viewVector: p - eye, or the view direction if orthographic)
// with g < 0 facing the camera. g is known at every vertex from its limit position and normal;
// along an edge, the edge's limit curve is evaluated in one of its faces. An edge whose ends
// differ in sign holds a crossing; an edge whose ends agree may still hold two (a "double
// crossing") when g turns back inside it. Such edges are found by a bound, then sampled:
//
//   The normal along an edge turns by about the angle between its end normals, a; the view
//   ray turns by the angle it subtends, b. If at both ends the view ray is further than
//   1.5 a + b + 1 degree from the tangent plane, g cannot reach 0 inside the edge and the edge
//   is skipped. Otherwise g is sampled at `edgeSamples` intervals; an interval whose ends agree
//   but whose end slopes point towards each other holds an extremum, found by bisection on the
//   slope, and if g there has the other sign the interval holds two crossings.
//
// Each crossing is bracketed, narrowed by `searchSteps` bisections and placed by linear
// interpolation in the last interval. Infinitely sharp interior edges carry two normals (one
// per face), and so do edges whose faces disagree on the normal at an end (infinitely sharp
// corners, darts, valence-2 vertices): they are searched once per face; every other edge
// once. Boundary edges and
// sharp edges whose faces disagree on facing are outline, and get points along their limit
// curve as well (see SearchOptions). The points of an edge
// are shared by all its faces, so the re-triangulated faces keep their shared edges identical.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/silhouette/face_domain.h"
#include "render/subdiv/limit_surface.h"

namespace limn::render::silhouette {

struct SearchOptions {
  int searchSteps = 5;  // bisection steps before the final linear interpolation
  int edgeSamples = 4;  // intervals sampled on an edge the bound cannot clear
  // Outline edges (boundaries, and infinitely sharp creases seen front on one side and back on
  // the other) are part of the outline: their limit curve is sampled about every
  // `pixelsPerSample` pixels of its length in the image (not of the chord between its ends,
  // which a short bulging edge far exceeds), at most `outlineSamples` per edge, and they get the
  // fewest uniform points whose chords stay within `outlineTolerancePx` of those samples in the
  // image (none on a straight edge).
  double pixelsPerSample = 2.0;
  int outlineSamples = 32;
  double outlineTolerancePx = 0.01;
  // True: g at the dyadic parameters the sampling and bisection reach (multiples of 1/128)
  // comes from the edge tables (edge_tables.h) on the edges they cover, rather than from Bfr;
  // the same values to rounding. Off by default: the search evaluates only about 4 such points
  // per sampled edge (most hold no crossing; the slope probes and face corners stay on Bfr), too
  // few to pay for gathering the edge's support, and it measured no faster
  // (bench/edge_table_results.md).
  bool edgeTables = false;
};

// A point on the limit curve of a base edge where g changes sign for at least one of the
// edge's faces.
struct EdgePoint {
  double t = 0;        // edge parameter: 0 at the edge's first vertex, 1 at its second
  Vec3 position;       // on the limit curve, evaluated once so every face uses the same bits
  uint32_t sides = 0;  // bit k: a crossing of g as seen from the edge's k-th face (0: a point
                       // that only shapes an outline edge)
};

struct SearchStats {
  size_t edgesTested = 0;          // edges with a face that has a limit surface
  size_t edgesWithSignChange = 0;  // ends of different sign (for some face)
  size_t edgesSampled = 0;         // searched inside because the bound could not clear them
  size_t doubleCrossings = 0;      // edges with ends of the same sign and crossings inside
  size_t outlineEdges = 0;         // boundary or sharp edges drawn along their limit curve
  size_t edgesOnTables = 0;        // sampled edges whose dyadic samples came from edge tables
  size_t contourPoints = 0;        // distinct edge points
  size_t interiorLoopFaces = 0;    // faces whose contour lies inside them (ContourSearch)
};

struct ContourSearch {
  // g and the unit limit normal at every face corner, in faceVertexIndices order. Corners of
  // a smooth vertex share one value; corners at sharp features keep their face's own.
  std::vector<double> cornerG;
  std::vector<Vec3> cornerNormals;
  std::vector<size_t> faceOffsets;  // start of each face's corners in the arrays above
  std::vector<std::vector<EdgePoint>> edgePoints;  // per base edge, sorted by t
  // Faces without a crossing on their edges in which g still changes sign: a contour loop lies
  // inside them (a small bump seen edge-on; an eye so close that all it sees is one face).
  // Found like double crossings: a face whose corners the bound cannot clear (the normal and
  // view-ray turn across the face against the corners' angles to the tangent plane) is
  // sampled on a fan of interior points. The silhouette mesh tessellates them finely.
  std::vector<int> loopFaces;
  SearchStats stats;
};

// g = dot(n, viewVector(p)) for the camera.
double contourFunction(const Camera& camera, const Vec3& position, const Vec3& normal);

ContourSearch searchContour(const FaceDomains& domains, const Camera& camera,
                            const SearchOptions& options, const CancelToken& cancel);

// The point `t` of base edge `edge` in face `face`'s domain (edge must be one of its edges).
Vec2 edgeUV(const FaceDomains& domains, int face, int edge, double t);

}  // namespace limn::render::silhouette
