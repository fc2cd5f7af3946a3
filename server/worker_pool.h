// WorkerPool: the fixed set of render threads behind POST /v1/render.
//
// Each worker constructs its own raster::Rasterizer (an EGL context is bound to the thread that
// made it) when it starts, then takes jobs from one bounded queue. The pool owns every rule about
// a job's life that does not depend on HTTP framing:
//  - admission: a full queue answers 429 busy (with Retry-After) at once, a stopped pool or one
//    without a single working GL context answers 503 unavailable;
//  - deadline: each job gets a CancelToken with deadline now + timeout; a watchdog thread
//    answers 504 timeout the moment the deadline passes, whether the job is still queued
//    (it leaves the queue) or running (its token is cancelled and the worker drops its result);
//  - shutdown: drain() refuses new jobs (503) and waits, up to a deadline, for the queued and
//    running ones to finish; stop() answers every job still queued or running 503 and cancels
//    the running ones; joinFor() waits a bounded time for the threads to end.
//  - abandonment: the handle submit() returns drops a queued job or cancels a running one when
//    the client that asked for it has gone away (a page that moved the camera again).
// Whatever happens, a job's reply is called exactly once, from whichever thread settled it
// (a worker, the watchdog, or the submitter for an immediate refusal).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

#include "api/render_api.h"
#include "render/core/cancel.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "server/service_metrics.h"

namespace limn::server {

struct PoolOptions {
  int workers = 0;                            // 0 = one per core
  size_t queueDepth = 64;                     // jobs waiting, not counting running ones
  std::chrono::milliseconds timeout{60'000};  // per job, from submission
  // Shared by every worker's jobs (owned by the caller, outliving the pool); null: none.
  render::oracle::ReferenceSceneCache* referenceCache = nullptr;
  // Where each job's queue wait, run time and stage times are recorded; null: nowhere.
  ServiceMetrics* metrics = nullptr;
};

// What one worker thread reported when it tried to make its GL context.
struct WorkerStatus {
  bool ready = false;
  std::string error;  // why the Rasterizer could not be made, when !ready
  render::raster::DeviceInfo device;
};

// A snapshot of the pool's counters for /healthz, /readyz and /metrics.
struct PoolSnapshot {
  int workers = 0;       // threads started
  int readyWorkers = 0;  // threads holding a GL context
  int busyWorkers = 0;
  size_t queued = 0;
  size_t queueCapacity = 0;
  bool stopping = false;
  size_t renderCount = 0;  // jobs run to their end
  size_t rejectedBusy = 0, timedOut = 0, cancelled = 0;
  size_t abandoned = 0;  // jobs whose client went away before their answer
};

class WorkerPool {
 public:
  using Work =
      std::function<api::Answer(render::pipeline::RenderContext&, const render::CancelToken&)>;
  using Reply = std::function<void(api::Answer)>;

  // Starts the workers and returns once each has made its GL context or failed to.
  explicit WorkerPool(const PoolOptions& options);
  ~WorkerPool();  // stop() then join()
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Cancels one job, if it has not been answered yet: a queued job leaves the queue, a running
  // one has its token cancelled (the worker stops at its next check). Its reply then gets a
  // 499 nobody reads. Safe to call from any thread, any number of times, after the pool's end.
  using Abandon = std::function<void()>;

  // Queues `work`; `reply` gets its answer, or the 429/503/504 the pool gives instead.
  // `work` must not throw (a throw becomes 500 internal anyway). The returned handle abandons
  // the job (empty when the job was refused at once).
  Abandon submit(Work work, Reply reply);

  // Refuses new jobs (503) and waits until every queued and running job has been answered or
  // `deadline` passed; true when none is left.
  bool drain(std::chrono::steady_clock::time_point deadline);
  // Refuses new jobs, answers queued and running ones 503 and cancels the running ones.
  // Does not block; join() waits for the threads.
  void stop();
  void join();
  // join() for at most `timeout` after stop(): false when a worker is still inside a job that
  // has not noticed its cancellation (the threads are then left running, not joined).
  bool joinFor(std::chrono::milliseconds timeout);

  // ---- Introspection ----
  PoolSnapshot snapshot() const;
  const std::vector<WorkerStatus>& workerStatus() const { return status_; }
  const PoolOptions& options() const { return options_; }

 private:
  struct Job;
  using Deadlines = std::multimap<render::CancelToken::Clock::time_point, std::shared_ptr<Job>>;

  void workerLoop(render::raster::Rasterizer& rasterizer);
  void watchdogMain();
  // Marks a job settled under the lock and hands back its reply, or nothing when it was settled
  // already (the watchdog and a worker can race for the same job).
  Reply claimLocked(Job& job);
  void abandon(const std::shared_ptr<Job>& job);
  int retryAfterSecondsLocked() const;
  // Jobs that ran longer than this return the memory they freed to the system afterwards.
  static constexpr double kTrimAfterSeconds = 0.2;
  static void returnFreedMemory();

  PoolOptions options_;
  std::vector<WorkerStatus> status_;  // written before the constructor returns, then read-only
  std::vector<std::thread> workers_;
  std::thread watchdog_;

  mutable std::mutex mutex_;
  std::condition_variable workAvailable_;
  std::condition_variable deadlinesChanged_;
  std::condition_variable jobSettled_;  // drain() and joinFor() wait on it
  std::deque<std::shared_ptr<Job>> queue_;
  std::unordered_set<std::shared_ptr<Job>> running_;
  Deadlines deadlines_;
  bool stopping_ = false;
  bool draining_ = false;
  int exitedWorkers_ = 0;
  int readyWorkers_ = 0;
  int busyWorkers_ = 0;
  double renderSecondsSum_ = 0;
  size_t renderCount_ = 0;
  size_t rejectedBusy_ = 0, timedOut_ = 0, cancelled_ = 0, abandoned_ = 0;
};

}  // namespace limn::server
