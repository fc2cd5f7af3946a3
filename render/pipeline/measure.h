// The steps every kind of job (a control mesh or an implicit field) ends with: an approximation's
// images measured against its reference, and the answer's passes picked from what was rendered.
#pragma once

#include <optional>
#include <string>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/metrics/metrics.h"
#include "render/oracle/reference.h"
#include "render/pipeline/render_job.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::pipeline {

// `images` (the approximation's passes at supersample S) against `reference` (cast with the
// approximation's mask as its hint, alone or merged with others': oracle::maskBlocks):
// silhouette metrics with the continuous outline distances, colour, depth (relative to
// `diagonal`) and normal metrics; with `diff`, the heat map goes into `images`. `timings`
// (optional) gets the time of each group.
metrics::Metrics measureImages(const tessellate::TriangleMesh& approx, ImageSet& images,
                               const Camera& camera, int S,
                               const oracle::ReferenceResult& reference, double diagonal, bool diff,
                               const CancelToken& cancel,
                               metrics::MetricsTimings* timings = nullptr);

// The same into result.metrics, for result.images.
void measureAgainstReference(const tessellate::TriangleMesh& approx, const Camera& camera, int S,
                             const oracle::ReferenceResult& reference, double diagonal, bool diff,
                             const CancelToken& cancel, RenderResult& result);

// A warning when the continuous outline distance is within the reference's own accuracy (the
// difference cannot be told from the reference's error), or nothing.
std::optional<std::string> referenceAccuracyNote(const metrics::Metrics& metrics,
                                                 const oracle::ReferenceStats& reference);

// Keeps only the passes the client asked for; the wireframe of the reference is its colour
// (the exact surface has no edges to draw).
ImageSet selectOutputs(ImageSet images, const Outputs& outputs, bool isReference);

}  // namespace limn::render::pipeline
