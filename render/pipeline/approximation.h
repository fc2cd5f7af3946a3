// approximate(): the first half of run() — surface = build(mesh); approx = method(surface,
// camera) — for clients that draw the approximation themselves (POST /v1/tessellate): the
// TriangleMesh a method would rasterise, with its per-vertex normals (limit normals where the
// method has them), and no image.
#pragma once

#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/pipeline/render_job.h"
#include "render/tessellate/triangle_mesh.h"

namespace limn::render::pipeline {

struct Approximation {
  tessellate::TriangleMesh mesh;
  Camera camera;  // as resolved (adaptive and silhouette depend on it)
  Stats stats;
  Timings timings;
  std::vector<std::string> warnings;
};

// Throws InputError as run() does, also for method "limit" (the reference is ray cast: it has
// no mesh to hand out), and Cancelled.
Approximation approximate(const RenderJob& job, const JobLimits& limits, const CancelToken& cancel);

}  // namespace limn::render::pipeline
