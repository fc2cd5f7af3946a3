// Error metrics of an approximation against the reference, exactly as DESIGN.md defines them.
#pragma once

#include <optional>

#include "render/core/image.h"
#include "render/subdiv/limit_surface.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::metrics {

struct SilhouetteMetrics {
  double hausdorffPx = 0;  // output pixels
  double meanPx = 0;       // output pixels
  double iou = 1;          // at supersampled size
  long mismatchPx = 0;     // output pixels whose majority coverage differs
};
struct ColorMetrics {
  double rmse = 0, psnr = 0;
};
struct DepthMetrics {
  double maxRel = 0, meanRel = 0;
};
struct NormalMetrics {
  double meanDeg = 0, maxDeg = 0;
};
struct GeometryMetrics {
  double maxDist = 0, meanDist = 0, relMaxDist = 0;
};

struct Metrics {
  std::optional<SilhouetteMetrics> silhouette;
  std::optional<ColorMetrics> image;
  std::optional<DepthMetrics> depth;
  std::optional<NormalMetrics> normal;
  std::optional<GeometryMetrics> geometry;
};

// Silhouette pixels of a mask: covered pixels with an uncovered 4-neighbour (outside the image
// counts as uncovered). Both masks are at `supersample` times the output size.
SilhouetteMetrics compareSilhouettes(const Image& mask, const Image& referenceMask,
                                     int supersample);
// Over pixels covered in either image's mask pass.
ColorMetrics compareColor(const ImageSet& approx, const ImageSet& reference);
// Over pixels covered in both; relative to `diagonal` (the mesh's bounding-box diagonal).
DepthMetrics compareDepth(const ImageSet& approx, const ImageSet& reference, double diagonal);
NormalMetrics compareNormals(const ImageSet& approx, const ImageSet& reference);
// Triangle vertices, edge midpoints and centroid against the limit surface at the same
// (face, u, v); or, for meshes with limitPositions, every vertex against its own.
GeometryMetrics measureGeometry(const tessellate::TriangleMesh& mesh,
                                const subdiv::LimitSurface& surface);

// Exact squared Euclidean distance transform (Felzenszwalb-Huttenlocher): for each pixel the
// squared distance to the nearest pixel where `isFeature` is true. Exposed for tests and the
// normal-map dilation of later work.
std::vector<double> squaredDistanceTransform(const std::vector<bool>& isFeature, int width,
                                             int height);

}  // namespace limn::render::metrics
