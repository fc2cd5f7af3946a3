// WorkerPool: the fixed set of render workers behind POST /v1/render and the other computing
// endpoints.
//
// A worker is a slot with a thread in the server. By default (Isolation::Process) each slot's
// thread drives a child process of its own (server/worker_process.h: `limn worker`, with its
// own EGL context and reference cache) and sends it one Task at a time; a crash, a memory
// ceiling or a hang of that process costs only the request it held, which is answered 500
// worker_crashed (never retried: it may be the poison), and the slot starts a new process at
// once. With Isolation::Thread (debugging, unit tests) the slot's thread runs the task itself
// with its own Rasterizer, as limn did before it had worker processes.
//
// The pool owns every rule about a job's life that does not depend on HTTP framing:
//  - lanes: a job is interactive, heavy (its estimated run time, corrected by the times the
//    pool measures, is at least heavySeconds) or batch (a job's row group). Interactive jobs go
//    first and may use every worker; heavy and batch jobs share all but reservedInteractive of
//    them (so a small request never waits for a heavy one to finish), heavy before batch; a
//    heavy job that has waited kHeavyAging goes before interactive ones for the workers it may
//    use. Within a lane, clients take turns (one job each, round robin);
//  - admission: a full queue answers 429 busy at once; so does a heavy job when the heavy work
//    already waiting would take more than heavyQueueSeconds, and a client's job when that
//    client already holds its share of the queue (clientQueueDepth; by default, once the queue
//    is half full, an equal share among the clients waiting) — each with a Retry-After
//    computed from the estimated time for that work to drain. A stopped pool or one without a
//    single working GL context answers 503 unavailable;
//  - dispatch: a job goes to the lowest-numbered idle worker it may use, so that a client's
//    requests in turn meet the same worker's reference cache;
//  - deadline: each job gets a CancelToken with deadline now + timeout; a watchdog thread
//    answers 504 timeout the moment the deadline passes, whether the job is still queued
//    (it leaves the queue) or running (its token is cancelled and the worker drops its result;
//    a worker process that has not stopped within its grace is killed and replaced);
//  - shutdown: drain() refuses new jobs (503) and waits, up to a deadline, for the queued and
//    running ones to finish; stop() answers every job still queued or running 503 and cancels
//    the running ones; joinFor() waits a bounded time for the threads to end.
//  - abandonment: the handle submit() returns drops a queued job or cancels a running one when
//    the client that asked for it has gone away (a page that moved the camera again).
// Whatever happens, a job's reply is called exactly once, from whichever thread settled it
// (a worker, the watchdog, or the submitter for an immediate refusal).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

#include "api/config.h"
#include "api/render_api.h"
#include "render/core/cancel.h"
#include "render/mesh/mesh_cache.h"
#include "render/oracle/reference_scene.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "server/service_metrics.h"
#include "server/tasks.h"
#include "server/worker_process.h"

namespace limn::server {

enum class Isolation { Process, Thread };

enum class Lane { Interactive, Heavy, Batch };
inline constexpr size_t kLanes = 3;
const char* laneName(Lane lane);

// What the pool needs to know of a job before it queues it.
struct JobClass {
  bool batch = false;           // a job's row group (or a request that asked to be batch)
  std::string client;           // who asked: clients take turns; "" is one anonymous client
  double referenceSeconds = 0;  // api::referenceSeconds of its work (0: treated as small)
};

struct PoolOptions {
  int workers = 0;                            // 0 = one per core
  size_t queueDepth = 64;                     // jobs waiting, not counting running ones
  std::chrono::milliseconds timeout{60'000};  // per job, from submission
  Isolation isolation = Isolation::Thread;
  // What each task may consume; limits.maxWorkerMemoryBytes is each worker process' ceiling.
  render::pipeline::JobLimits limits;
  // Reference scenes kept for later requests with the same mesh and camera: one cache of this
  // size shared by the threads, or this size split between the worker processes.
  size_t referenceCacheBytes = 0;
  // Uploaded meshes that tasks may name by id (owned by the caller, outliving the pool).
  render::mesh::MeshCache* meshes = nullptr;
  // Isolation::Process: the limn executable the workers run.
  std::string workerExecutable = "/proc/self/exe";
  // Where each job's queue wait, run time and stage times are recorded; null: nowhere.
  ServiceMetrics* metrics = nullptr;
  // Lanes (see above). Workers heavy and batch jobs may not take, when there are more workers
  // than this; the corrected estimate from which a job is heavy; the estimated heavy work that
  // may wait; the jobs one client may have waiting (0: once the queue is half full, an equal
  // share of it among the clients waiting).
  int reservedInteractive = 1;
  double heavySeconds = 0.25;
  double heavyQueueSeconds = 30;
  size_t clientQueueDepth = 0;
  // Isolation::Process with reserved workers: the nice value of the worker processes heavy and
  // batch jobs may use (0: as the server's).
  int heavyNice = 0;
};

// What one worker reported when it tried to make its GL context, and how it is now.
struct WorkerStatus {
  bool ready = false;
  std::string error;  // why the Rasterizer could not be made, when !ready
  render::raster::DeviceInfo device;
  int pid = 0;                // the worker process (0 with Isolation::Thread)
  bool busy = false;          // running a job now
  const char* endpoint = "";  // the running job's path ("/v1/render"; "" for server work)
  uint64_t requestId = 0;     // the running job's request
  size_t starts = 0;          // processes started for this slot (1 + replacements)
};

// The pool a limn process runs with `config`: its workers, queue, timeout, isolation, limits
// and reference cache (the caller sets meshes and metrics).
PoolOptions poolOptions(const api::ServiceConfig& config);

// The default ceiling of each worker process' memory: the machine's memory, less a share kept
// for the server and the system, split between `workers`.
size_t defaultWorkerMemoryBytes(int workers);

// A snapshot of the pool's counters for /healthz, /readyz and /metrics.
struct PoolSnapshot {
  int workers = 0;       // threads started
  int readyWorkers = 0;  // threads holding a GL context
  int busyWorkers = 0;
  size_t queued = 0;
  size_t queueCapacity = 0;
  bool stopping = false;
  bool draining = false;  // shutting down: new work is refused 503
  std::array<size_t, kLanes> queuedByLane{}, runningByLane{};
  // Workers a batch job could start on now: idle ones heavy and batch work may use, less the
  // jobs already waiting for one.
  int freeForBatch = 0;
  // Measured run time over api::referenceSeconds, learned from the jobs run so far.
  double speedFactor = 1;
  // Jobs refused at admission, by reason: "busy" (queue full), "heavy" (heavy lane full),
  // "client" (the client's share full); and admitted, by lane.
  std::map<std::string, size_t> refusals;
  std::array<size_t, kLanes> admitted{};
  size_t renderCount = 0;  // jobs run to their end
  size_t rejectedBusy = 0, timedOut = 0, cancelled = 0;
  size_t abandoned = 0;     // jobs whose client went away before their answer
  size_t workerStarts = 0;  // worker processes started, first ones included
  bool spareReady = false;  // Isolation::Process: a started worker waits to replace a lost one
  std::map<std::string, size_t> crashes;  // worker processes lost, by signal ("SIGSEGV")
  render::oracle::ReferenceSceneCache::Counters referenceCache;  // summed over the workers
};

class WorkerPool {
 public:
  // Work that needs the server's own state (an upload into its mesh cache, a job into its
  // table): run on a worker's thread in the server, with that thread's RenderContext under
  // Isolation::Thread and an empty one (no rasterizer) under Isolation::Process.
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

  // Queues `task`; `reply` gets its answer, or the 429/503/504 the pool gives instead, or 500
  // worker_crashed naming `requestId` when its worker process dies. The returned handle
  // abandons the job (empty when the job was refused at once).
  Abandon submit(Task task, Reply reply, uint64_t requestId = 0, JobClass jobClass = {});
  // The same for work run in the server process (interactive). `work` must not throw (a throw
  // becomes 500 internal anyway).
  Abandon submitInServer(Work work, Reply reply, std::string client = {});

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
  std::vector<WorkerStatus> workerStatus() const;
  const PoolOptions& options() const { return options_; }

 private:
  struct Job;
  using Deadlines = std::multimap<render::CancelToken::Clock::time_point, std::shared_ptr<Job>>;

  Abandon enqueue(std::shared_ptr<Job> job);
  void threadWorkerMain(size_t slot);
  void processWorkerMain(size_t slot);
  // The slot's first worker has made its GL context or failed to: the constructor may return.
  void reportStarted(size_t slot, WorkerStatus status);
  // A new worker process for `slot` (retried while the pool runs), or null once it stops.
  std::unique_ptr<WorkerProcess> startWorkerProcess(size_t slot);
  WorkerProcessOptions workerProcessOptions() const;
  // Shows `worker` as the slot's in /healthz.
  void adoptLocked(size_t slot, const WorkerProcess& worker);
  // Keeps one started, idle worker process in reserve, so that a crashed worker is replaced at
  // once rather than after a GL context's start (a second or more on a loaded machine).
  void spareMain();
  // The spare for `slot`, or null when there is none (or it died waiting).
  std::unique_ptr<WorkerProcess> takeSpare(size_t slot);
  // The next job for `slot` (dispatchLocked gives it one), or null when the pool stops or,
  // with `wakeAfter`, when that passes first.
  std::shared_ptr<Job> nextJob(size_t slot, std::chrono::milliseconds wakeAfter = {});
  // Gives waiting jobs to idle slots, by the lanes' rules (above).
  void dispatchLocked();
  // The lowest idle slot that may run a job of `lane`, or -1.
  int idleSlotForLocked(Lane lane) const;
  // Takes a job that has not started out of its lane or its slot (abandoned, timed out).
  void unqueueLocked(const std::shared_ptr<Job>& job);
  // The lane a job joins, or the 429 it gets instead.
  std::optional<api::Answer> admitLocked(Job& job);
  size_t queuedLocked() const;
  int generalSlots() const;  // the slots heavy and batch jobs may use: 0 .. generalSlots()-1
  // Counts the dead worker's end and starts its successor (null: none could be started).
  std::unique_ptr<WorkerProcess> replaceWorker(size_t slot, std::unique_ptr<WorkerProcess> dead,
                                               const WorkerProcess::Outcome& outcome);
  bool stopping() const;
  // How often an idle worker process is checked for having died between jobs.
  static constexpr std::chrono::milliseconds kIdleCheck{200};
  // A heavy job waiting this long goes before interactive ones (it is not starved by them).
  static constexpr std::chrono::milliseconds kHeavyAging{2000};
  // Runs `job` on the slot's thread (work in the server, or a task under Isolation::Thread).
  api::Answer runHere(Job& job, render::pipeline::RenderContext& context);
  // What a slot does once its job is answered.
  enum class AfterJob { TakesNext, Restarts };
  // Records the job's end and gives it its answer (unless it was answered already). A slot that
  // takes the next job counts as idle before the answer leaves, so that a client's next request
  // finds the worker (and the reference cache) that answered its last one.
  void finishJob(size_t slot, const std::shared_ptr<Job>& job, api::Answer answer,
                 render::CancelToken::Clock::time_point started,
                 AfterJob after = AfterJob::TakesNext);
  void watchdogMain();
  // Marks a job settled under the lock and hands back its reply, or nothing when it was settled
  // already (the watchdog and a worker can race for the same job).
  Reply claimLocked(Job& job);
  void abandon(const std::shared_ptr<Job>& job);
  int retryAfterSecondsLocked() const;
  // The Server-Timing header of a job's answer: its lane and wait, its run, its estimate (ms).
  static std::string serverTiming(const Job& job, double waitedS, double ranS);
  // Seconds for `seconds` of estimated work to drain through `workers` workers, 1..60.
  static int drainSeconds(double seconds, int workers);

  PoolOptions options_;
  // Isolation::Thread: the one cache every thread shares.
  std::unique_ptr<render::oracle::ReferenceSceneCache> sharedReferenceCache_;
  std::vector<std::thread> workers_;
  std::thread watchdog_;
  std::thread spareThread_;
  std::unique_ptr<WorkerProcess> spare_;  // Isolation::Process: the next replacement
  std::condition_variable spareWanted_;
  std::atomic<bool> stopRequested_{false};  // stopping_, for worker starts to give up on

  mutable std::mutex mutex_;
  std::condition_variable workAvailable_;
  std::condition_variable deadlinesChanged_;
  std::condition_variable jobSettled_;  // drain() and joinFor() wait on it
  struct LaneQueue;
  std::array<std::unique_ptr<LaneQueue>, kLanes> lanes_;
  std::map<std::string, size_t> queuedByClient_;
  std::array<size_t, kLanes> runningByLane_{}, admitted_{};
  std::map<std::string, size_t> refusals_;
  double logSpeed_ = 0;             // log of the learned speed factor
  double runningHeavySeconds_ = 0;  // estimated work of the heavy jobs running
  std::unordered_set<std::shared_ptr<Job>> running_;
  std::vector<WorkerStatus> status_;            // by slot
  std::set<size_t> idle_;                       // slots waiting for a job, or about to (finishJob)
  std::vector<std::shared_ptr<Job>> assigned_;  // by slot: given by dispatchLocked, not taken
  // Each worker process' reference cache as it last reported, and the lookups of those lost.
  std::vector<render::oracle::ReferenceSceneCache::Counters> referenceCounters_;  // by slot
  render::oracle::ReferenceSceneCache::Counters retiredReferenceLookups_;
  int started_ = 0;     // slots whose first worker has reported
  int glFailures_ = 0;  // slots whose worker could not make a GL context
  Deadlines deadlines_;
  bool stopping_ = false;
  bool draining_ = false;
  int exitedWorkers_ = 0;
  int busyWorkers_ = 0;
  size_t workerStarts_ = 0;
  std::map<std::string, size_t> crashes_;
  double renderSecondsSum_ = 0;
  size_t renderCount_ = 0;
  size_t rejectedBusy_ = 0, timedOut_ = 0, cancelled_ = 0, abandoned_ = 0;
};

}  // namespace limn::server
