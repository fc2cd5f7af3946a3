// Outline: where a rendering's coverage changes, located as a curve in the image plane to a
// thousandth of a pixel, and the distance between two such curves.
//
// The mask metrics (compareSilhouettes) measure outlines as sets of supersampled pixels, so they
// read in steps of 1/S output pixels. This measures them as curves: the coverage of the
// supersampled mask shows which cells of the sample grid the outline crosses; on every edge of
// such a cell whose two samples differ, the crossing is found by bisection with a coverage
// query on the geometry itself (a ray cast, not the mask), the crossings of each cell are
// joined into segments as marching squares joins them, and where the polyline turns sharply the
// segments' middles are moved onto the outline the same way (so corners are not cut off). See
// docs/engine.md "Continuous outline distances" for the definition, the image border and one-sided
// outlines.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "render/core/cancel.h"
#include "render/core/mask.h"
#include "render/core/vec.h"
#include "render/metrics/coverage_distance.h"

namespace limn::render::metrics {

// Image-plane points in output pixels: x right, y down, pixel (i, j) spans [i, i+1] x [j, j+1].
// The query fills covered[k] (0 or 1) for points[k]; it may run on several threads and is given
// whole batches so it can.
using CoverageQuery =
    std::function<void(const std::vector<Vec2>& points, std::vector<char>& covered)>;

struct Outline {
  std::vector<Vec2> points;                   // located crossings, output pixels
  std::vector<std::pair<int, int>> segments;  // indices into points
  // The frame points are measured in: the rectangle of output pixel centres, [0.5, w - 0.5] x
  // [0.5, h - 0.5], which every supersampling's sample grid covers (a finer grid reaches closer
  // to the image border, and must not be counted as an outline the coarser one lacks).
  double frameWidth = 0, frameHeight = 0;  // w and h, output pixels
  bool empty() const { return points.empty(); }
};

// Bisection stops when the bracket is shorter than this (output pixels).
inline constexpr double kOutlineTolerancePx = 1e-3;

// The outline of a coverage mask at `supersample` times the output size (samples at the centres
// of its pixels, covered where nonzero), located with `query`. Samples outside the mask are not
// invented: the outline lies between sample centres, so the image frame is not part of it.
// `scan` (optional, one flag per output pixel) limits the search to the cells in and along the
// blocks of the flagged pixels: where the caller knows the mask can be mixed (the reference's
// refined pixels); otherwise every cell of the mask is looked at.
Outline locateOutline(const Mask& supersampledMask, int supersample, const CoverageQuery& query,
                      const CancelToken& cancel, const std::vector<char>* scan = nullptr,
                      double tolerancePx = kOutlineTolerancePx);

struct OutlineDistances {
  double hausdorffPx = 0;      // max over both directions of the distance from a point to the other
  double meanPx = 0;           // mean of those distances over the points of both
  size_t unresolvedLoops = 0;  // closed loops of either outline thinner than resolvablePx
};

// Distances between two outlines: every located point of one inside its frame is measured to the
// nearest segment (or lone point) of the other, wherever that lies. Empty outlines: nothing when
// both are empty is 0; when only one is, the answer is `farPx` (the image diagonal) for both
// numbers, as for the mask metrics.
// With the outlines' geometry (`geometryA` of a, `geometryB` of b), a point further than 0.1 px
// from the other outline and outside the other's geometry is measured to that geometry where it
// is nearer, as compareSilhouettes does (coverage_distance.h).
// A closed loop of either outline whose convex hull is thinner than `resolvablePx` (a pinhole
// or a sliver that one sample caught, narrower than the reference can resolve: twice its
// accuracyPx) is not measured, and counted in unresolvedLoops; it stays a target for the
// other outline's points (a feature next to it is not missing).
OutlineDistances compareOutlines(const Outline& a, const Outline& b, double farPx,
                                 const CoverageDistanceQuery* geometryA = nullptr,
                                 const CoverageDistanceQuery* geometryB = nullptr,
                                 double resolvablePx = 0);

}  // namespace limn::render::metrics
