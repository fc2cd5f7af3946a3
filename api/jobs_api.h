// The wire format of POST /v1/jobs, GET /v1/jobs/{id} and DELETE /v1/jobs/{id}: a batch spec
// (api/batch_spec.h, meshes given inline or by id: a server never reads a file it is named) ->
// the job's plan; a job's state and rows -> JSON. The jobs themselves are server/jobs.h's.
#pragma once

#include <cstddef>
#include <cstdint>
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

// The spec a job is stored with: `body` with its meshes as the plan read them, every one inline
// and named ({"name", "mesh"}), so that any replica, now or after a restart, reads the same
// plan from it without the mesh cache of the one that took it.
std::string storedSpec(std::string_view body, const BatchPlan& plan);

// What GET /v1/jobs/{id} answers about a job.
struct JobView {
  std::string id;
  std::string state;                       // "queued", "running", "done", "cancelled", "failed"
  size_t done = 0, total = 0, failed = 0;  // rows
  int64_t createdMs = 0, finishedMs = 0;   // Unix time in ms; finishedMs 0 while unfinished
  double elapsedS = 0;                     // since it was created (to its end, once finished)
  std::string error;                       // why it failed ("" when it did not)
  size_t offset = 0;                       // the index of rows.front() among the job's rows
  std::vector<std::string> rows;           // result lines (api/batch_results.h), in row order
  bool withRows = true;                    // false: the job without "offset" and "rows" (lists)
};

// {"id", "state", "progress": {"done", "total", "failed"}, "createdAt", "finishedAt"?,
//  "elapsedS", "error"?, "links": {...}, "offset", "rows": [...]}
std::string writeJob(const JobView& job);
// GET /v1/jobs: {"jobs": [job without rows...], "next": "/v1/jobs?after=...&limit=N"?}
std::string writeJobList(const std::vector<JobView>& jobs, const std::string& nextCursor,
                         size_t limit);
// A row line with the replica that computed it as its first field ("replica").
std::string withReplica(const std::string& line, const std::string& replica);

}  // namespace limn::api
