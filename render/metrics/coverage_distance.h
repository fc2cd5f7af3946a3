// Distances from image points to a rendering's coverage, measured on its triangles rather than
// on its samples.
//
// The silhouette metrics find outlines where the samples of a mask change (1/S output px apart).
// A feature narrower than that spacing — the last pixels of a spike tapering to a point — is
// covered by no sample, so it is missing from the mask while the geometry still reaches there.
// Where two renderings draw the same spike with widths a few hundredths of a pixel apart, their
// samples lose it at points pixels apart along its length, and the sampled distances call that
// a gap of pixels (3.4 px on a cube with infinitely sharp corners at 512^2, S = 4; the gap
// changes with S, which the geometry does not). Measuring from a point outside the other shape
// to that shape's triangles gives the distance the metric means: to the nearest point the
// other rendering covers. The same holds inside out: a slit or gap narrower than the spacing
// (two parts that nearly touch, seen at a grazing angle) has no sample in it, so from a point
// the other shape covers the distance is measured to the nearest point its triangles leave
// uncovered.
#pragma once

#include <functional>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/vec.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::metrics {

// Image-plane points in output pixels (as outline.h). On entry distances[k] is an upper bound
// for points[k] (the distance the samples gave); it is lowered, where that is smaller, to the
// distance from points[k] to the nearest covered point when points[k] is not covered, and to
// the nearest uncovered point (the coverage's edge) when it is. Uncovered points are searched
// for at most 8 px away and a thousandth of a pixel off the triangles' edges (narrower gaps are
// the rounding of float positions along seams), and not at all when some triangle reaches
// behind the near plane (left out, it could seem a gap). The query may run on several threads.
using CoverageDistanceQuery =
    std::function<void(const std::vector<Vec2>& points, std::vector<double>& distances)>;

// The query for `mesh` seen by `camera`, covering what rasterising or ray casting its triangles
// covers. Triangles reaching behind the eye or the near plane are left out (their projection is
// not a triangle), which can only leave a bound unlowered. `mesh`, `camera` and `cancel` must
// outlive the query; `cancel` is checked between batches of triangles.
CoverageDistanceQuery meshCoverageDistance(const tessellate::TriangleMesh& mesh,
                                           const Camera& camera, const CancelToken& cancel);

// Lowers every bound in `distances` with `query` where that can change the largest: the points
// go to the query largest bound first, in batches that double (256 first), until the largest
// bound left is no more than the largest distance measured so far; those left keep their bounds
// (which can only overstate a mean by what they would have been lowered). So a rendering far off
// everywhere (a coarse mesh, 100k outline points pixels away) costs a batch or two, not a search
// around every point.
void lowerLargestFirst(const CoverageDistanceQuery& query, const std::vector<Vec2>& points,
                       std::vector<double>& distances);

// Distance from `p` to the segment [a, b], and to the closed triangle (a, b, c) (0 inside).
double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b);
double pointTriangleDistance(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c);

}  // namespace limn::render::metrics
