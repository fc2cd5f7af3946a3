// JobManager: the HTTP side of batch jobs over a batch::JobStore (SQLite or PostgreSQL) —
// POST /v1/jobs (with Idempotency-Key), GET /v1/jobs (the caller's jobs), GET and DELETE
// /v1/jobs/{id}, GET /v1/jobs/{id}/results.csv and results.jsonl — and this replica's share of
// computing them.
//
// Every replica on the same store answers for every job, and each one's runner thread claims
// row groups from the store while the render pool has a free worker and no request waiting for
// one (interactive requests come first), sends each as a /v1/compare task to the pool, and
// stores its rows. Leases are renewed every lease/3; a replica that dies leaves its groups to be
// claimed again when their leases run out. A group that comes back busy, timed out or refused
// (429, 503, 504) is given back with a growing pause, up to maxAttempts claims; one that
// crashed its worker twice is stored as error rows naming the crash. On shutdown the runner
// gives its leases back, uncounted, for the next replica or restart.
//
// A store that cannot be reached makes /v1/jobs answer 503 (Retry-After) and /readyz name its
// error (storeProblem()); renders go on, and the runner keeps trying it. Thread-safe.
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
#include "api/batch_plan.h"
#include "batch/job_store.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"
#include "server/worker_pool.h"

namespace limn::server {

struct JobOptions {
  size_t maxJobs = 8;                    // jobs held in the store: queued, running and finished
  size_t maxJobRows = 20000;             // rows of one job
  std::chrono::seconds retention{3600};  // a finished job is kept this long
  int maxAttempts = 4;                   // claims of one group before its rows are errors
  std::chrono::milliseconds poll{500};   // an idle runner asks the store for work this often
};

class JobManager {
 public:
  // `pool`, `meshes` (may be null) must outlive the manager; stop() before the pool stops.
  JobManager(WorkerPool& pool, const render::pipeline::JobLimits& limits, JobOptions options,
             std::unique_ptr<batch::JobStore> store, render::mesh::MeshCache* meshes = nullptr);
  ~JobManager();  // stop()
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  // 202 with the job (200 with the same job for a repeated Idempotency-Key), the spec's 4xx,
  // 422 for a key reused with another body, 429 when maxJobs unfinished jobs are held. Parses
  // the spec's meshes: call it on a worker (the router does), not an IO thread.
  api::Answer create(std::string_view body, const std::string& client,
                     const std::string& idempotencyKey);
  // 200 with the job and its rows from `offset` on, or 404 not_found.
  api::Answer get(const std::string& id, size_t offset);
  // 200 with the client's jobs, newest first, `limit` a page from the cursor `after`.
  api::Answer list(const std::string& client, const std::string& after, size_t limit);
  // Cancels a queued or running job (200, state "cancelled", its rows kept until the retention
  // ends), or forgets a finished one (200 with its last state); 404 for an unknown id.
  api::Answer cancel(const std::string& id);
  // The job's rows as results.jsonl ("jsonl") or results.csv ("csv"), in row order.
  api::Answer results(const std::string& id, const std::string& format);

  // Whether the store answered its last round trip.
  // Empty while the store answers; else why it does not (its last error).
  std::string storeProblem() const;
  // For /metrics: this replica's row groups by what became of them, and those in flight.
  struct Counters {
    size_t stored = 0;    // rows stored (with or without errors)
    size_t retried = 0;   // given back to be claimed again (busy, timeout, a crash)
    size_t released = 0;  // given back uncounted (a shutdown, a cancelled job)
    size_t inFlight = 0;
  };
  Counters counters() const;
  const std::string& replica() const { return store_->replica(); }

  // Stops claiming, gives up the comparisons in flight, hands their leases back, and waits
  // for the runner thread.
  void stop();

 private:
  struct InFlight;
  struct Finished;
  void runLoop();
  // Claims groups while the pool has a worker free for them; why it stopped.
  enum class Claimed { Nothing, Full, PoolBusy };
  Claimed claimWork();
  void startGroup(batch::ClaimedGroup group);
  void settle(Finished finished);
  void count(size_t Counters::*counter);
  void heartbeat();
  std::shared_ptr<const api::BatchPlan> planOf(const std::string& jobId);
  // Logs the store's error once and keeps it for /readyz until a heartbeat gets through.
  void markUnhealthy(const batch::DatabaseError& e);
  // Runs a store call; a lost store is 503, and marks the store unhealthy until a ping works.
  template <typename Fn>
  api::Answer withStore(Fn&& fn);
  api::Answer viewOf(const batch::JobRecord& job, size_t offset, int status, bool withRows);

  WorkerPool& pool_;
  render::pipeline::JobLimits limits_;
  JobOptions options_;
  std::unique_ptr<batch::JobStore> store_;
  render::mesh::MeshCache* meshes_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::string problem_;     // the store's last error while it fails; empty when it answers
  bool workAdded_ = false;  // a job was created here: claim at once rather than at the next poll
  std::map<std::pair<std::string, size_t>, std::shared_ptr<InFlight>> inFlight_;
  std::deque<Finished> finished_;
  std::map<std::string, std::shared_ptr<const api::BatchPlan>> plans_;  // a few recent jobs
  Counters counters_;
  std::thread runner_;
};

}  // namespace limn::server
