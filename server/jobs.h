// JobManager: POST /v1/jobs — a batch spec run in the background — GET /v1/jobs/{id} (state,
// progress, the rows so far) and DELETE /v1/jobs/{id} (cancel; a finished job is forgotten).
//
// Jobs run one at a time, in the order they came, on one driver thread that sends their row
// groups to the server's own WorkerPool through batch::runGroups (as many in flight as there are
// workers): a job's comparisons wait in the same queue, under the same limits and deadline, as
// any /v1/compare, and an interactive request waits behind at most one group per worker. The
// table holds at most `maxJobs` jobs; a new one evicts the oldest finished job when the table is
// full, and is refused 429 when every held job is still queued or running. Finished jobs are
// kept `retention` for their client to read, then dropped. Thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "api/answer.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"
#include "server/worker_pool.h"

namespace limn::server {

struct JobOptions {
  size_t maxJobs = 8;                    // jobs held: queued, running and finished
  size_t maxJobRows = 20000;             // rows of one job (each is about 1.5 kB held)
  std::chrono::seconds retention{3600};  // a finished job is kept this long
};

class JobManager {
 public:
  // `pool` and `meshes` (may be null) must outlive the manager; stop() before the pool stops.
  JobManager(WorkerPool& pool, const render::pipeline::JobLimits& limits, JobOptions options,
             render::mesh::MeshCache* meshes = nullptr);
  ~JobManager();  // stop()
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  // 202 with the job, or the spec's 4xx, or 429 when the table is full of unfinished jobs.
  // Parses the spec's meshes: call it on a worker (the router does), not an IO thread.
  api::Answer create(std::string_view body);
  // 200 with the job and its rows from `offset` on, or 404 not_found.
  api::Answer get(const std::string& id, size_t offset);
  // Cancels a queued or running job (200, state "cancelled", its rows so far kept until the
  // retention ends), or forgets a finished one (200 with its last state); 404 for an unknown id.
  api::Answer cancel(const std::string& id);

  // Cancels every job and waits for the driver thread.
  void stop();

 private:
  struct Job;
  void driverLoop();
  void runJob(Job& job);
  // Drops the finished jobs past their retention.
  void dropExpiredLocked();
  // For a new job: dropExpiredLocked(), then, while the table is full, the oldest finished
  // job; false when it stays full (every job unfinished).
  bool makeRoomLocked();
  api::Answer viewLocked(const Job& job, size_t offset, int status) const;

  WorkerPool& pool_;
  render::pipeline::JobLimits limits_;
  JobOptions options_;
  render::mesh::MeshCache* meshes_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, std::shared_ptr<Job>> jobs_;
  std::deque<std::shared_ptr<Job>> queue_;
  bool stopping_ = false;
  std::thread driver_;
};

}  // namespace limn::server
