// ImplicitJob -> RenderResult: an implicit field's path through the engine, the same straight
// line as a control mesh's (render_job.h): field = build(spec); approx = polygonize(field);
// images = raster(approx, camera); reference = ray-cast isosurface; metrics = compare(images,
// reference) + the mesh's distance to the isosurface. The answer has RenderResult's shape, with
// stats.implicit for the polygoniser and metrics.geometry always present.
#pragma once

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/implicit/field.h"
#include "render/implicit/polygonize.h"
#include "render/pipeline/render_job.h"

namespace limn::render::pipeline {

struct ImplicitJob {
  implicit::FieldSpec field;
  implicit::PolygonizerOptions polygonizer;
  CameraSpec camera;
  Shading shading = Shading::Smooth;
  Outputs outputs;
  bool reference = false;
  int metricSupersample = 4;
};

// Throws InputError (a bad field, options out of range, a limit exceeded) and Cancelled.
RenderResult runImplicit(const ImplicitJob& job, const JobLimits& limits, RenderContext& context,
                         const CancelToken& cancel);

// Only the polygonisation (for a mesh download): the mesh, with stats.implicit, the triangle
// counts and timings.surfaceMs / approxMs filled.
struct ImplicitMesh {
  tessellate::TriangleMesh mesh;
  Stats stats;
  Timings timings;
};
ImplicitMesh polygonizeImplicit(const ImplicitJob& job, const JobLimits& limits,
                                const CancelToken& cancel);

}  // namespace limn::render::pipeline
