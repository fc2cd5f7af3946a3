// The wire format of POST /v1/jobs, GET /v1/jobs/{id} and DELETE /v1/jobs/{id}: a batch spec
// (api/batch_spec.h, meshes given inline or by id: a server never reads a file it is named) ->
// the job's plan; a job's state and rows -> JSON. The jobs themselves are server/jobs.h's.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "api/batch_plan.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

// Throws ApiError: what parseBatchSpec refuses, a mesh entry that names a file (400 naming
// meshes[i]), a mesh /v1/render would refuse (422 / 404 unknown_mesh, naming meshes[i].mesh),
// more rows than `maxRows` (413 naming limits.maxJobRows).
BatchPlan parseJobSpec(std::string_view body, const render::pipeline::JobLimits& limits,
                       size_t maxRows, render::mesh::MeshCache* meshes = nullptr);

// What GET /v1/jobs/{id} answers about a job.
struct JobView {
  std::string id;
  std::string state;                       // "queued", "running", "done", "cancelled", "failed"
  size_t done = 0, total = 0, failed = 0;  // rows
  double elapsedS = 0;                     // since it was created
  std::string error;                       // why it failed ("" when it did not)
  size_t offset = 0;                       // the index of rows.front() among the job's rows
  std::vector<std::string> rows;           // result lines (api/batch_results.h), as they came
};

// {"id", "state", "progress": {"done", "total", "failed"}, "elapsedS", "error"?, "offset",
//  "rows": [...]}
std::string writeJob(const JobView& job);

}  // namespace limn::api
