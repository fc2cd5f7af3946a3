#include "render/pipeline/measure.h"

#include <cmath>
#include <optional>
#include <string>

#include "render/metrics/metrics.h"
#include "render/pipeline/job_checks.h"

namespace limn::render::pipeline {

metrics::Metrics measureImages(const tessellate::TriangleMesh& approx, ImageSet& images,
                               const Camera& camera, int S,
                               const oracle::ReferenceResult& reference, double diagonal, bool diff,
                               const CancelToken& cancel, metrics::MetricsTimings* timings) {
  metrics::MetricsTimings spent;
  Stopwatch clock;
  const ImageSet& refImages = reference.images;
  // Both geometries, so that features narrower than the samples count as what they are.
  const metrics::CoverageDistanceQuery approxGeometry =
      metrics::meshCoverageDistance(approx, camera, cancel);
  std::optional<metrics::CoverageDistanceQuery> referenceGeometry;
  if (reference.coverageMesh) {
    referenceGeometry = metrics::meshCoverageDistance(*reference.coverageMesh, camera, cancel);
  }
  const metrics::CoverageDistanceQuery* toReference =
      referenceGeometry ? &*referenceGeometry : nullptr;
  metrics::Metrics m;
  m.silhouette =
      metrics::compareSilhouettes(images.supersampledMask, refImages.supersampledMask, S, cancel,
                                  {.approximation = &approxGeometry, .reference = toReference});
  spent.silhouetteMs = clock.lapMs();
  // The reference was hinted with this mask: its refined pixels hold all of its outline.
  metrics::Outline outline = oracle::locateMeshOutline(approx, camera, images.supersampledMask, S,
                                                       cancel, &reference.refinedPixels);
  // A loop thinner than twice the reference's accuracy (its walls may each be that far off) is
  // a feature it cannot tell from none: not measured, and counted.
  metrics::OutlineDistances d = metrics::compareOutlines(
      outline, reference.outline, std::hypot(camera.width(), camera.height()), &approxGeometry,
      toReference, 2 * reference.stats.accuracyPx);
  m.silhouette->outlineHausdorffPx = d.hausdorffPx;
  m.silhouette->outlineMeanPx = d.meanPx;
  m.silhouette->outlineUnresolvedLoops = static_cast<long>(d.unresolvedLoops);
  spent.outlineMs = clock.lapMs();
  m.image = metrics::compareColor(images, refImages);
  // A surface without extent (every control point at one place: a valid mesh, drawn as a dot)
  // has no diagonal to measure depth against: its relative depth differences are 0, as
  // measureGeometry reports its relative distances. (Found by fuzz/engine: "reference": true on
  // such a mesh answered 500, compareDepth refusing the zero diagonal.)
  m.depth =
      diagonal == 0 ? metrics::DepthMetrics{} : metrics::compareDepth(images, refImages, diagonal);
  m.normal = metrics::compareNormals(images, refImages);
  if (diff) {
    metrics::DiffImage heat = metrics::colorDifference(images, refImages);
    m.image->diffScale = heat.scale;
    images.passes[pass::kDiff] = std::move(heat.image);
  }
  spent.imageMs = clock.lapMs();
  if (timings) *timings = spent;
  return m;
}

void measureAgainstReference(const tessellate::TriangleMesh& approx, const Camera& camera, int S,
                             const oracle::ReferenceResult& reference, double diagonal, bool diff,
                             const CancelToken& cancel, RenderResult& result) {
  metrics::Metrics m =
      measureImages(approx, result.images, camera, S, reference, diagonal, diff, cancel);
  result.metrics.silhouette = m.silhouette;
  result.metrics.image = m.image;
  result.metrics.depth = m.depth;
  result.metrics.normal = m.normal;
}

std::optional<std::string> referenceAccuracyNote(const metrics::Metrics& metrics,
                                                 const oracle::ReferenceStats& reference) {
  if (!metrics.silhouette || !metrics.silhouette->outlineHausdorffPx) return std::nullopt;
  const double distance = *metrics.silhouette->outlineHausdorffPx;
  if (distance > reference.accuracyPx) return std::nullopt;
  return "metrics: silhouette.outlineHausdorffPx (" + std::to_string(distance) +
         " px) is within the reference's own accuracy (" + std::to_string(reference.accuracyPx) +
         " px): the outline's error is at most that, not known more closely";
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
  if (!isReference) keep(outputs.patches, pass::kPatches);
  for (const char* colorLike :
       {pass::kColor, pass::kWireframe, pass::kContours, pass::kCage, pass::kPatches}) {
    auto it = selected.passes.find(colorLike);
    if (it != selected.passes.end()) applyBackground(it->second, outputs.background);
  }
  return selected;
}

}  // namespace limn::render::pipeline
