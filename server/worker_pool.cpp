#include "server/worker_pool.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <fstream>
#include <iostream>
#include <utility>

namespace limn::server {

using Clock = render::CancelToken::Clock;

struct WorkerPool::Job {
  Job(Task t, Work w, uint64_t id, Reply r, Clock::time_point due)
      : task(std::move(t)),
        work(std::move(w)),
        requestId(id),
        reply(std::move(r)),
        queued(Clock::now()),
        deadline(due),
        token(due) {}

  Task task;
  Work work;  // set: run in the server (submitInServer); else `task` is the engine's
  uint64_t requestId;
  Reply reply;
  Clock::time_point queued, deadline;
  render::CancelToken token;
  bool settled = false;
  Deadlines::iterator deadlineEntry;
};

namespace {

api::Answer busyAnswer(size_t capacity, int retryAfterS) {
  api::Answer answer = api::errorAnswer(
      {429, "busy",
       "the render queue is full (" + std::to_string(capacity) + " waiting); retry later"});
  answer.headers.emplace_back("Retry-After", std::to_string(retryAfterS));
  return answer;
}

api::Answer timeoutAnswer(std::chrono::milliseconds timeout) {
  return api::errorAnswer({504, "timeout",
                           "the render did not finish within requestTimeoutMs (" +
                               std::to_string(timeout.count()) + " ms)"});
}

api::Answer unavailableAnswer(const std::string& why) {
  api::Answer answer = api::errorAnswer({503, "unavailable", why});
  answer.headers.emplace_back("Retry-After", "1");
  return answer;
}

api::Answer crashAnswer(const WorkerProcess::Outcome& outcome, int pid, uint64_t requestId) {
  std::string detail = "{\"pid\":" + std::to_string(pid) +
                       ",\"requestId\":" + std::to_string(requestId) + ",\"signal\":\"" +
                       outcome.signal + "\"}";
  return api::errorAnswer({500, "worker_crashed",
                           "the render worker (pid " + std::to_string(pid) + ") running request " +
                               std::to_string(requestId) + " " + outcome.crash +
                               "; the request is not retried, the worker has been replaced",
                           detail});
}

// How long a slot waits before it tries again to start a worker that would not start.
constexpr std::chrono::seconds kRestartBackoff{1};

}  // namespace

PoolOptions poolOptions(const api::ServiceConfig& config) {
  PoolOptions options;
  options.workers = config.workers;
  options.queueDepth = static_cast<size_t>(config.queueDepth);
  options.timeout = std::chrono::milliseconds(config.requestTimeoutMs);
  options.isolation = config.workerIsolation == "thread" ? Isolation::Thread : Isolation::Process;
  options.limits = config.limits;
  options.referenceCacheBytes = config.referenceCacheBytes;
  return options;
}

namespace {

// The memory this process may use: the machine's, or less when a cgroup (v2: a container's
// memory limit) says so.
size_t availableMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGESIZE);
  size_t total = pages > 0 && pageSize > 0 ? size_t(pages) * size_t(pageSize) : 8ull << 30;
  std::ifstream cgroup("/sys/fs/cgroup/memory.max");
  size_t limit = 0;
  if (cgroup >> limit && limit > 0) total = std::min(total, limit);  // "max" reads as nothing
  return total;
}

}  // namespace

size_t defaultWorkerMemoryBytes(int workers) {
  const size_t total = availableMemoryBytes();
  // A quarter (at least 1 GiB) for the server, its caches and the system; the rest split.
  const size_t reserve = std::max<size_t>(total / 4, 1ull << 30);
  const size_t share = total > reserve ? (total - reserve) / std::max(workers, 1) : 0;
  return std::max<size_t>(share, 1ull << 30);
}

WorkerPool::WorkerPool(const PoolOptions& options) : options_(options) {
  int count = options_.workers;
  if (count <= 0) count = std::max(1u, std::thread::hardware_concurrency());
  options_.workers = count;
  if (options_.isolation == Isolation::Process && options_.limits.maxWorkerMemoryBytes == 0) {
    options_.limits.maxWorkerMemoryBytes = defaultWorkerMemoryBytes(count);
  }
  if (options_.isolation == Isolation::Thread) {
    sharedReferenceCache_ =
        std::make_unique<render::oracle::ReferenceSceneCache>(options_.referenceCacheBytes);
  }
  status_.resize(count);
  referenceCounters_.resize(count);

  // Workers report their GL context before taking jobs, so that the first request after the
  // server says "listening" does not pay for context creation and /healthz is right at once.
  for (int i = 0; i < count; ++i) {
    workers_.emplace_back([this, i] {
      if (options_.isolation == Isolation::Process) {
        processWorkerMain(static_cast<size_t>(i));
      } else {
        threadWorkerMain(static_cast<size_t>(i));
      }
      std::lock_guard lock(mutex_);
      ++exitedWorkers_;
      jobSettled_.notify_all();
    });
  }
  {
    std::unique_lock lock(mutex_);
    jobSettled_.wait(lock, [&] { return started_ == count; });
  }
  watchdog_ = std::thread([this] { watchdogMain(); });
  if (options_.isolation == Isolation::Process && glFailures_ < count) {
    spareThread_ = std::thread([this] { spareMain(); });
  }
}

WorkerPool::~WorkerPool() {
  stop();
  join();
}

void WorkerPool::reportStarted(size_t slot, WorkerStatus status) {
  std::lock_guard lock(mutex_);
  if (!status.ready) ++glFailures_;
  status_[slot] = std::move(status);
  ++started_;
  jobSettled_.notify_all();
}

void WorkerPool::threadWorkerMain(size_t slot) {
  WorkerStatus status;
  std::unique_ptr<render::raster::Rasterizer> rasterizer;
  try {
    rasterizer = std::make_unique<render::raster::Rasterizer>();
    status.ready = true;
    status.device = rasterizer->device();
  } catch (const std::exception& e) {
    status.error = e.what();
  }
  reportStarted(slot, std::move(status));
  if (!rasterizer) return;

  render::pipeline::RenderContext context;
  context.rasterizer = rasterizer.get();
  context.referenceCache = sharedReferenceCache_.get();
  while (std::shared_ptr<Job> job = nextJob(slot)) {
    const auto start = Clock::now();
    api::Answer answer = runHere(*job, context);
    finishJob(slot, job, std::move(answer), start);
  }
}

WorkerProcessOptions WorkerPool::workerProcessOptions() const {
  WorkerProcessOptions options;
  options.executable = options_.workerExecutable;
  options.config.limits = options_.limits;
  options.config.referenceCacheBytes =
      options_.referenceCacheBytes / static_cast<size_t>(options_.workers);
  options.maxMemoryBytes = options_.limits.maxWorkerMemoryBytes;
  options.abandonStart = &stopRequested_;
  return options;
}

void WorkerPool::adoptLocked(size_t slot, const WorkerProcess& worker) {
  WorkerStatus& status = status_[slot];
  status.ready = worker.ready().ok;
  status.error = worker.ready().error;
  status.device = worker.ready().device;
  status.pid = worker.pid();
  ++status.starts;
}

std::unique_ptr<WorkerProcess> WorkerPool::startWorkerProcess(size_t slot) {
  for (;;) {
    std::string error;
    try {
      auto worker = std::make_unique<WorkerProcess>(workerProcessOptions());
      std::lock_guard lock(mutex_);
      ++workerStarts_;
      adoptLocked(slot, *worker);
      return worker;
    } catch (const std::exception& e) {
      error = e.what();
    }
    std::cerr << "limn: " << error << "\n";
    std::unique_lock lock(mutex_);
    status_[slot].ready = false;
    status_[slot].pid = 0;
    status_[slot].error = error;
    if (started_ < options_.workers && status_[slot].starts == 0) return nullptr;
    if (workAvailable_.wait_for(lock, kRestartBackoff, [this] { return stopping_; })) {
      return nullptr;
    }
  }
}

void WorkerPool::spareMain() {
  std::unique_lock lock(mutex_);
  for (;;) {
    spareWanted_.wait(lock, [this] { return stopping_ || !spare_; });
    if (stopping_) break;
    lock.unlock();
    std::unique_ptr<WorkerProcess> worker;
    try {
      worker = std::make_unique<WorkerProcess>(workerProcessOptions());
    } catch (const std::exception& e) {
      if (!stopRequested_) std::cerr << "limn: spare render worker: " << e.what() << "\n";
    }
    lock.lock();
    if (worker && worker->ready().ok) {
      ++workerStarts_;
      spare_ = std::move(worker);
    } else if (spareWanted_.wait_for(lock, kRestartBackoff, [this] { return stopping_; })) {
      break;
    }
  }
  std::unique_ptr<WorkerProcess> last = std::move(spare_);
  lock.unlock();  // its destructor waits for the process
}

std::unique_ptr<WorkerProcess> WorkerPool::takeSpare(size_t slot) {
  std::unique_ptr<WorkerProcess> spare;
  {
    std::lock_guard lock(mutex_);
    spare = std::move(spare_);
    spareWanted_.notify_one();
  }
  // A spare that died waiting (the OOM killer, anyone's kill) is no use.
  if (!spare || spare->exitedWhileIdle()) return nullptr;
  std::lock_guard lock(mutex_);
  adoptLocked(slot, *spare);
  return spare;
}

void WorkerPool::processWorkerMain(size_t slot) {
  std::unique_ptr<WorkerProcess> worker = startWorkerProcess(slot);
  reportStarted(slot, workerStatus()[slot]);
  if (!worker || !worker->ready().ok) return;

  render::pipeline::RenderContext serverContext;  // for work run here: no GL context
  for (;;) {
    std::shared_ptr<Job> job = nextJob(slot, kIdleCheck);
    // A worker that died between jobs (killed from outside, the OOM killer) is replaced
    // before it is given one: no request is answered for it.
    if (std::optional<WorkerProcess::Outcome> gone = worker->exitedWhileIdle()) {
      std::cerr << "limn: idle render worker " << worker->pid() << " " << gone->crash << "\n";
      if (!(worker = replaceWorker(slot, std::move(worker), *gone))) {
        if (job)
          finishJob(slot, job, unavailableAnswer("no render worker could be started"), Clock::now(),
                    AfterJob::Restarts);
        return;
      }
    }
    if (!job) {
      if (stopping()) return;
      continue;  // the idle check's wake-up
    }
    const auto start = Clock::now();
    if (job->work) {
      api::Answer answer = runHere(*job, serverContext);
      finishJob(slot, job, std::move(answer), start);
      continue;
    }
    // The body moves into the message (the job keeps its endpoint for the log).
    wire::Run run{job->requestId,
                  {job->task.endpoint, std::move(job->task.body), std::move(job->task.accept)},
                  job->deadline,
                  nullptr};
    if (options_.meshes) {
      if (std::optional<std::string> id = referencedMeshId(run.task)) {
        run.mesh = options_.meshes->find(*id);
      }
    }
    WorkerProcess::Outcome outcome = worker->run(run, job->token);
    if (outcome.answer) {
      {
        std::lock_guard lock(mutex_);
        referenceCounters_[slot] = outcome.answer->referenceCache;
      }
      finishJob(slot, job, std::move(outcome.answer->answer), start);
      continue;
    }
    // The worker died on this job: the job alone is answered for it (never retried: it may be
    // what killed the worker), and the slot starts a new one before it takes another job.
    const int pid = worker->pid();
    std::cerr << "limn: render worker " << pid << " " << outcome.crash << " (request "
              << job->requestId << ", " << endpointPath(job->task.endpoint) << ")\n";
    finishJob(slot, job, crashAnswer(outcome, pid, job->requestId), start, AfterJob::Restarts);
    if (!(worker = replaceWorker(slot, std::move(worker), outcome))) return;
  }
}

std::unique_ptr<WorkerProcess> WorkerPool::replaceWorker(size_t slot,
                                                         std::unique_ptr<WorkerProcess> dead,
                                                         const WorkerProcess::Outcome& outcome) {
  dead.reset();
  {
    std::lock_guard lock(mutex_);
    ++crashes_[outcome.signal.empty() ? "exit" : outcome.signal];
    status_[slot].ready = false;
    status_[slot].pid = 0;
    // The lost cache's lookups stay counted (counters never go back), its entries do not.
    retiredReferenceLookups_.hits += referenceCounters_[slot].hits;
    retiredReferenceLookups_.misses += referenceCounters_[slot].misses;
    retiredReferenceLookups_.evictions += referenceCounters_[slot].evictions;
    referenceCounters_[slot] = {};
  }
  if (stopping()) return nullptr;  // shutting down: nothing more to run
  // The spare is ready at once; a new process takes its GL context's time (seconds under load).
  std::unique_ptr<WorkerProcess> worker = takeSpare(slot);
  if (!worker) worker = startWorkerProcess(slot);
  if (worker && !worker->ready().ok) {
    std::lock_guard lock(mutex_);
    ++glFailures_;
    return nullptr;
  }
  return worker;
}

bool WorkerPool::stopping() const {
  std::lock_guard lock(mutex_);
  return stopping_;
}

api::Answer WorkerPool::runHere(Job& job, render::pipeline::RenderContext& context) {
  try {
    if (job.work) return job.work(context, job.token);
    return runTask(job.task, options_.limits, context, job.token, options_.meshes);
  } catch (const std::exception& e) {
    return api::errorAnswer({500, "internal", std::string("render failed: ") + e.what()});
  } catch (...) {
    return api::errorAnswer({500, "internal", "render failed"});
  }
}

WorkerPool::Abandon WorkerPool::submit(Task task, Reply reply, uint64_t requestId) {
  return enqueue(std::make_shared<Job>(std::move(task), nullptr, requestId, std::move(reply),
                                       Clock::now() + options_.timeout));
}

WorkerPool::Abandon WorkerPool::submitInServer(Work work, Reply reply) {
  return enqueue(std::make_shared<Job>(Task{}, std::move(work), 0, std::move(reply),
                                       Clock::now() + options_.timeout));
}

WorkerPool::Abandon WorkerPool::enqueue(std::shared_ptr<Job> job) {
  api::Answer refusal;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || draining_) {
      refusal = unavailableAnswer("the server is shutting down");
    } else if (glFailures_ == options_.workers) {
      refusal = unavailableAnswer("no render worker has an OpenGL context: " +
                                  (status_.empty() ? std::string() : status_.front().error));
    } else if (queue_.size() >= options_.queueDepth) {
      ++rejectedBusy_;
      refusal = busyAnswer(options_.queueDepth, retryAfterSecondsLocked());
    } else {
      job->deadlineEntry = deadlines_.emplace(job->deadline, job);
      queue_.push_back(job);
      // Every idle slot checks whether it is the lowest-numbered one (nextJob).
      workAvailable_.notify_all();
      // Only an earlier deadline than the watchdog's next one needs to wake it.
      if (job->deadlineEntry == deadlines_.begin()) deadlinesChanged_.notify_one();
      // The pool outlives the connections (HttpServer stops them first); the handle holds the
      // job weakly so that an answered job is freed at once.
      return [this, weak = std::weak_ptr<Job>(job)] {
        if (auto j = weak.lock()) abandon(j);
      };
    }
  }
  job->reply(std::move(refusal));
  return {};
}

void WorkerPool::abandon(const std::shared_ptr<Job>& job) {
  Reply reply;
  {
    std::lock_guard lock(mutex_);
    reply = claimLocked(*job);
    if (!reply) return;  // answered already
    auto queued = std::find(queue_.begin(), queue_.end(), job);
    if (queued != queue_.end()) queue_.erase(queued);
    job->token.cancel();
    ++abandoned_;
    jobSettled_.notify_all();
  }
  reply(api::errorAnswer({499, "client_closed", "the client closed the connection"}));
}

WorkerPool::Reply WorkerPool::claimLocked(Job& job) {
  if (job.settled) return {};
  job.settled = true;
  deadlines_.erase(job.deadlineEntry);
  Reply reply = std::move(job.reply);
  job.reply = nullptr;
  return reply;
}

std::shared_ptr<WorkerPool::Job> WorkerPool::nextJob(size_t slot,
                                                     std::chrono::milliseconds wakeAfter) {
  std::unique_lock lock(mutex_);
  idle_.insert(slot);
  // The k-th lowest idle slot takes a job when at least k jobs wait: the lowest idle slot
  // always gets the front one.
  auto mine = [&] {
    const size_t rank = static_cast<size_t>(std::distance(idle_.begin(), idle_.find(slot)));
    return rank < queue_.size();
  };
  const bool woken =
      wakeAfter.count() > 0
          ? workAvailable_.wait_for(lock, wakeAfter, [&] { return stopping_ || mine(); })
          : (workAvailable_.wait(lock, [&] { return stopping_ || mine(); }), true);
  idle_.erase(slot);
  if (stopping_ || !woken) return nullptr;
  std::shared_ptr<Job> job = std::move(queue_.front());
  queue_.pop_front();
  running_.insert(job);
  ++busyWorkers_;
  status_[slot].busy = true;
  status_[slot].endpoint = job->work ? "" : endpointPath(job->task.endpoint);
  status_[slot].requestId = job->requestId;
  return job;
}

void WorkerPool::finishJob(size_t slot, const std::shared_ptr<Job>& job, api::Answer answer,
                           Clock::time_point started, AfterJob after) {
  const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
  if (options_.metrics) {
    options_.metrics->jobRan(std::chrono::duration<double>(started - job->queued).count(), seconds,
                             answer);
  }
  Reply reply;
  {
    std::lock_guard lock(mutex_);
    --busyWorkers_;
    status_[slot].busy = false;
    status_[slot].endpoint = "";
    status_[slot].requestId = 0;
    running_.erase(job);
    renderSecondsSum_ += seconds;
    ++renderCount_;
    reply = claimLocked(*job);
    if (after == AfterJob::TakesNext) idle_.insert(slot);
    jobSettled_.notify_all();
    // A slot that went idle may now be the lowest-numbered one for a waiting job.
    workAvailable_.notify_all();
  }
  job->work = nullptr;  // frees the request body now rather than when the last owner lets go
  job->task = {};
  if (reply) reply(std::move(answer));
  // A worker process trims its own memory.
  if (options_.isolation == Isolation::Thread) returnFreedMemoryAfter(seconds);
}

void WorkerPool::watchdogMain() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (deadlines_.empty()) {
      deadlinesChanged_.wait(lock);
      continue;
    }
    auto due = deadlines_.begin()->first;
    if (Clock::now() < due) {
      deadlinesChanged_.wait_until(lock, due);
      continue;
    }
    // The earliest job is due: settle it with 504 whether it waits or runs.
    std::shared_ptr<Job> job = deadlines_.begin()->second;
    Reply reply = claimLocked(*job);
    auto queued = std::find(queue_.begin(), queue_.end(), job);
    if (queued != queue_.end()) queue_.erase(queued);
    job->token.cancel();  // a running worker stops at its next check
    ++timedOut_;
    jobSettled_.notify_all();
    lock.unlock();
    if (reply) reply(timeoutAnswer(options_.timeout));
    lock.lock();
  }
}

bool WorkerPool::drain(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  draining_ = true;
  // A job the watchdog answered 504 may still be running (cancelled): it has been answered.
  auto answered = [this] {
    if (!queue_.empty()) return false;
    for (const auto& job : running_) {
      if (!job->settled) return false;
    }
    return true;
  };
  return jobSettled_.wait_until(lock, deadline, answered);
}

void WorkerPool::stop() {
  std::vector<Reply> replies;
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
    stopRequested_ = true;
    for (auto& job : queue_) {
      if (Reply reply = claimLocked(*job)) replies.push_back(std::move(reply));
    }
    queue_.clear();
    for (const auto& job : running_) {
      job->token.cancel();
      if (Reply reply = claimLocked(*job)) replies.push_back(std::move(reply));
    }
    cancelled_ += replies.size();
  }
  workAvailable_.notify_all();
  deadlinesChanged_.notify_all();
  spareWanted_.notify_all();
  for (auto& reply : replies) reply(unavailableAnswer("the server is shutting down"));
}

bool WorkerPool::joinFor(std::chrono::milliseconds timeout) {
  {
    std::unique_lock lock(mutex_);
    const int threads = static_cast<int>(workers_.size());
    if (!jobSettled_.wait_for(lock, timeout, [&] { return exitedWorkers_ == threads; })) {
      return false;
    }
  }
  join();
  return true;
}

void WorkerPool::join() {
  for (auto& worker : workers_) {
    if (worker.joinable()) worker.join();
  }
  if (watchdog_.joinable()) watchdog_.join();
  if (spareThread_.joinable()) spareThread_.join();
}

int WorkerPool::retryAfterSecondsLocked() const {
  // Roughly how long until a queue slot frees: the mean render time times the jobs ahead,
  // spread over the workers; at least one second, at most a minute.
  const int ready = options_.workers - glFailures_;
  if (renderCount_ == 0 || ready <= 0) return 1;
  double mean = renderSecondsSum_ / static_cast<double>(renderCount_);
  double wait = mean * static_cast<double>(queue_.size() + busyWorkers_) / ready;
  return static_cast<int>(std::clamp(std::ceil(wait), 1.0, 60.0));
}

std::vector<WorkerStatus> WorkerPool::workerStatus() const {
  std::lock_guard lock(mutex_);
  return status_;
}

PoolSnapshot WorkerPool::snapshot() const {
  std::lock_guard lock(mutex_);
  PoolSnapshot s;
  s.workers = static_cast<int>(status_.size());
  for (const WorkerStatus& w : status_) s.readyWorkers += w.ready;
  s.busyWorkers = busyWorkers_;
  s.queued = queue_.size();
  s.queueCapacity = options_.queueDepth;
  s.stopping = stopping_;
  s.draining = draining_;
  s.renderCount = renderCount_;
  s.rejectedBusy = rejectedBusy_;
  s.timedOut = timedOut_;
  s.cancelled = cancelled_;
  s.abandoned = abandoned_;
  s.workerStarts = workerStarts_;
  s.spareReady = spare_ != nullptr;
  s.crashes = crashes_;
  if (sharedReferenceCache_) {
    s.referenceCache = sharedReferenceCache_->counters();
  } else {
    s.referenceCache = retiredReferenceLookups_;
    for (const auto& c : referenceCounters_) {
      s.referenceCache.hits += c.hits;
      s.referenceCache.misses += c.misses;
      s.referenceCache.evictions += c.evictions;
      s.referenceCache.entries += c.entries;
      s.referenceCache.bytes += c.bytes;
      s.referenceCache.capacityBytes += c.capacityBytes;
    }
  }
  return s;
}

}  // namespace limn::server
