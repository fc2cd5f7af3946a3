#include "render/pipeline/measure.h"

#include <cmath>

#include "render/metrics/metrics.h"

namespace limn::render::pipeline {

void measureAgainstReference(const tessellate::TriangleMesh& approx, const Camera& camera, int S,
                             const oracle::ReferenceResult& reference, double diagonal, bool diff,
                             const CancelToken& cancel, RenderResult& result) {
  const ImageSet& approxImages = result.images;
  const ImageSet& refImages = reference.images;
  result.metrics.silhouette = metrics::compareSilhouettes(approxImages.supersampledMask,
                                                          refImages.supersampledMask, S, cancel);
  // The reference was hinted with this mask: its refined pixels hold all of its outline.
  metrics::Outline outline = oracle::locateMeshOutline(
      approx, camera, approxImages.supersampledMask, S, cancel, &reference.refinedPixels);
  metrics::OutlineDistances d = metrics::compareOutlines(
      outline, reference.outline, std::hypot(camera.width(), camera.height()));
  result.metrics.silhouette->outlineHausdorffPx = d.hausdorffPx;
  result.metrics.silhouette->outlineMeanPx = d.meanPx;
  result.metrics.image = metrics::compareColor(approxImages, refImages);
  result.metrics.depth = metrics::compareDepth(approxImages, refImages, diagonal);
  result.metrics.normal = metrics::compareNormals(approxImages, refImages);
  if (diff) {
    metrics::DiffImage heat = metrics::colorDifference(approxImages, refImages);
    result.metrics.image->diffScale = heat.scale;
    result.images.passes[pass::kDiff] = std::move(heat.image);
  }
}

ImageSet selectOutputs(ImageSet images, const Outputs& outputs, bool isReference) {
  ImageSet selected;
  auto keep = [&](bool wanted, const char* name) {
    if (!wanted) return;
    auto it = images.passes.find(name);
    if (it != images.passes.end()) selected.passes[name] = std::move(it->second);
  };
  if (isReference && outputs.wireframe && images.passes.count(pass::kColor)) {
    selected.passes[pass::kWireframe] = images.passes[pass::kColor];
  }
  keep(outputs.color, pass::kColor);
  keep(outputs.mask, pass::kMask);
  keep(outputs.depth, pass::kDepth);
  keep(outputs.normal, pass::kNormal);
  if (!isReference) keep(outputs.wireframe, pass::kWireframe);
  if (!isReference) keep(outputs.contours, pass::kContours);
  if (!isReference) keep(outputs.cage, pass::kCage);
  if (!isReference) keep(outputs.diff, pass::kDiff);
  return selected;
}

}  // namespace limn::render::pipeline
