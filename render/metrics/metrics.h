// Error metrics of an approximation against the reference, exactly as DESIGN.md defines them.
#pragma once

#include <optional>
#include <vector>

#include "render/core/cancel.h"
#include "render/core/image.h"
#include "render/metrics/coverage_distance.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::metrics {

struct SilhouetteMetrics {
  double hausdorffPx = 0;  // output pixels
  double meanPx = 0;       // output pixels
  double iou = 1;          // at supersampled size
  long mismatchPx = 0;     // output pixels whose majority coverage differs
  // Distances between the two outlines as curves in the image plane, output pixels, not
  // quantised by the supersampling (outline.h); absent where no outline was located.
  std::optional<double> outlineHausdorffPx, outlineMeanPx;
  // Closed loops of either outline narrower than the reference resolves, not measured in those.
  long outlineUnresolvedLoops = 0;
};
struct ColorMetrics {
  double rmse = 0, psnr = 0;
  // The colour difference at the top of the diff heat map's ramp (when one was drawn).
  std::optional<double> diffScale;
};
struct DepthMetrics {
  double maxRel = 0, meanRel = 0;
};
struct NormalMetrics {
  double meanDeg = 0, maxDeg = 0;
};
struct GeometryMetrics {
  double maxDist = 0, meanDist = 0, relMaxDist = 0, relMeanDist = 0;
};

// Where the time of measuring one approximation against its reference went (milliseconds), for
// timings and benchmarks: the mask metrics (with their geometry distance queries), locating the
// approximation's outline and comparing it with the reference's, colour, depth and normal
// metrics, and the geometry metrics.
struct MetricsTimings {
  double silhouetteMs = 0, outlineMs = 0, imageMs = 0, geometryMs = 0;
};

struct Metrics {
  std::optional<SilhouetteMetrics> silhouette;
  std::optional<ColorMetrics> image;
  std::optional<DepthMetrics> depth;
  std::optional<NormalMetrics> normal;
  std::optional<GeometryMetrics> geometry;
};
// The worst of several views' metrics, member by member (a turntable's summary): the largest
// error, the smallest IoU and PSNR; a group is present when any view has it.
Metrics worstOf(const std::vector<Metrics>& views);

// Silhouette pixels of a mask: covered pixels with an uncovered 4-neighbour (outside the image
// counts as uncovered). Both masks are at `supersample` times the output size, covered where
// nonzero. When only one mask shows anything, hausdorffPx and meanPx are the image diagonal in
// output pixels; when neither does, both are 0 and iou is 1.
// Throws std::invalid_argument for masks of different sizes, not one byte per pixel, or a size
// that is not a multiple of `supersample`. `cancel` is checked every band of rows (32768^2 masks
// take seconds), throwing Cancelled.
//
// With `geometry`, a contour pixel of one mask more than a mask pixel from the other's contour
// and outside the other's geometry is measured to that geometry instead where it is nearer: a
// feature narrower than the samples is then not counted as missing from the mask that lost it
// (coverage_distance.h says why). hausdorffPx and meanPx are then no longer multiples of 1/S.
struct SilhouetteGeometry {
  const CoverageDistanceQuery* approximation = nullptr;  // of `mask`
  const CoverageDistanceQuery* reference = nullptr;      // of `referenceMask`
};
// How the contour distances are found: among the other contour's pixels in the rows around
// each pixel (exact, and taking the whole-image distance transform only where a pixel has none
// within 16 output pixels), or always with the transform (the original way, slower at 4096^2;
// kept for the tests, which hold both to the same numbers).
enum class ContourSearch { Nearby, FullTransform };
SilhouetteMetrics compareSilhouettes(const Mask& mask, const Mask& referenceMask, int supersample,
                                     const CancelToken& cancel = CancelToken{},
                                     const SilhouetteGeometry& geometry = {},
                                     ContourSearch search = ContourSearch::Nearby);
// Coverage comes from each set's "mask" pass, else the colour's alpha (> 0.5), else depth > 0.
// Missing or mismatched passes throw std::invalid_argument.
//
// RGB over pixels covered in either. psnr = 20 log10(1 / rmse), capped at 100 dB (identical
// images would otherwise be infinite, which JSON cannot carry).
ColorMetrics compareColor(const ImageSet& approx, const ImageSet& reference);
// The per-pixel colour difference as a heat map (image_metrics.cpp has the ramp): for each
// pixel covered in either rendering, d = the largest |approx - reference| of R, G, B, drawn as
// ramp(d / scale) with scale = the largest d (at least 1/255, one 8-bit step); pixels covered
// in neither are transparent. Same passes and coverage rules as compareColor.
struct DiffImage {
  Image image;  // RGBA
  double scale = 0;
};
DiffImage colorDifference(const ImageSet& approx, const ImageSet& reference);
// Over pixels covered in both; relative to `diagonal` (the mesh's bounding-box diagonal).
DepthMetrics compareDepth(const ImageSet& approx, const ImageSet& reference, double diagonal);
// Angle between the normalised normals where both are covered; pixels with a zero normal are
// left out.
NormalMetrics compareNormals(const ImageSet& approx, const ImageSet& reference);
// Triangle vertices, edge midpoints and centroid against the limit surface at the same
// (face, u, v); or, for meshes with limitPositions, every vertex against its own. Triangles on
// faces without a limit (holes) are skipped; triangles whose corners lie on different Bfr
// sub-faces are measured at their corners only. A mesh with neither kind of information throws
// std::invalid_argument.
GeometryMetrics measureGeometry(const tessellate::TriangleMesh& mesh,
                                const subdiv::LimitSurface& surface);

// Exact squared Euclidean distance transform (Felzenszwalb-Huttenlocher): for each pixel the
// squared distance to the nearest pixel where `isFeature` is true. Exposed for tests and the
// normal-map dilation of later work. Pixels with no feature anywhere get +infinity. The image
// may be at most 65535 pixels tall (std::invalid_argument otherwise).
std::vector<double> squaredDistanceTransform(const std::vector<bool>& isFeature, int width,
                                             int height);

}  // namespace limn::render::metrics
