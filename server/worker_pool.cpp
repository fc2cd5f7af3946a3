#include "server/worker_pool.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <utility>

#include "server/tasks.h"

namespace limn::server {

using Clock = render::CancelToken::Clock;

struct WorkerPool::Job {
  Job(Task t, Work w, uint64_t id, Reply r, Clock::time_point due, JobClass c)
      : task(std::move(t)),
        work(std::move(w)),
        requestId(id),
        reply(std::move(r)),
        queued(Clock::now()),
        deadline(due),
        token(due),
        jobClass(std::move(c)) {}

  Task task;
  Work work;  // set: run in the server (submitInServer); else `task` is the engine's
  uint64_t requestId;
  Reply reply;
  Clock::time_point queued, deadline;
  render::CancelToken token;
  bool settled = false;
  Deadlines::iterator deadlineEntry;
  JobClass jobClass;
  Lane lane = Lane::Interactive;
  double estimateS = 0;  // jobClass.referenceSeconds corrected by the pool's speed factor
};

// One lane's waiting jobs: a FIFO per client; the client served longest ago goes next (a client
// that just arrived before one that was just served), so that no client's stream of requests
// delays another's by more than one job per client.
struct WorkerPool::LaneQueue {
  std::map<std::string, std::deque<std::shared_ptr<Job>>> byClient;
  std::map<std::string, uint64_t> lastServed;  // the serving tick of each client seen lately
  uint64_t tick = 0;
  size_t size = 0;
  double seconds = 0;  // their estimated work

  void push(std::shared_ptr<Job> job) {
    seconds += job->estimateS;
    byClient[job->jobClass.client].push_back(std::move(job));
    ++size;
  }
  std::shared_ptr<Job> pop() {
    auto next = byClient.begin();
    uint64_t nextServed = UINT64_MAX;
    for (auto it = byClient.begin(); it != byClient.end(); ++it) {
      auto served = lastServed.find(it->first);
      const uint64_t at = served == lastServed.end() ? 0 : served->second;
      if (at < nextServed) {
        next = it;
        nextServed = at;
      }
    }
    std::shared_ptr<Job> job = std::move(next->second.front());
    next->second.pop_front();
    lastServed[next->first] = ++tick;
    if (next->second.empty()) byClient.erase(next);
    // Forget the clients with nothing waiting once there are many (their turn restarts at 0).
    if (lastServed.size() > 4096) {
      std::erase_if(lastServed, [&](const auto& entry) { return !byClient.count(entry.first); });
    }
    forget(*job);
    return job;
  }
  bool remove(const std::shared_ptr<Job>& job) {
    auto it = byClient.find(job->jobClass.client);
    if (it == byClient.end()) return false;
    auto at = std::find(it->second.begin(), it->second.end(), job);
    if (at == it->second.end()) return false;
    it->second.erase(at);
    if (it->second.empty()) byClient.erase(it);
    forget(*job);
    return true;
  }
  // When the longest-waiting job came.
  Clock::time_point oldest() const {
    Clock::time_point first = Clock::time_point::max();
    for (const auto& [client, fifo] : byClient) first = std::min(first, fifo.front()->queued);
    return first;
  }
  template <typename Fn>
  void forEach(Fn&& fn) const {
    for (const auto& [client, fifo] : byClient) {
      for (const auto& job : fifo) fn(job);
    }
  }
  void clear() {
    byClient.clear();
    size = 0;
    seconds = 0;
  }

 private:
  void forget(const Job& job) {
    --size;
    seconds = std::max(0.0, seconds - job.estimateS);
  }
};

const char* laneName(Lane lane) {
  switch (lane) {
    case Lane::Interactive:
      return "interactive";
    case Lane::Heavy:
      return "heavy";
    case Lane::Batch:
      return "batch";
  }
  return "interactive";
}

namespace {

api::Answer busyAnswer(const std::string& message, const std::string& limit, int retryAfterS) {
  api::Answer answer = api::errorAnswer(
      {429, "busy", message,
       "{\"limit\":\"" + limit + "\",\"retryAfterS\":" + std::to_string(retryAfterS) + "}"});
  answer.headers.emplace_back("Retry-After", std::to_string(retryAfterS));
  return answer;
}

size_t laneIndex(Lane lane) { return static_cast<size_t>(lane); }

std::string milliseconds(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", seconds * 1000);
  return text;
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

// Raises the nice value of every thread of process `pid` (threads it starts later inherit it
// from theirs). Raising needs no privilege; nothing here ever lowers it again.
void lowerPriority(int pid, int nice) {
  std::error_code ec;
  for (const auto& task :
       std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    const int tid = std::atoi(task.path().filename().c_str());
    if (tid > 0) ::setpriority(PRIO_PROCESS, static_cast<id_t>(tid), nice);
  }
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
  options.reservedInteractive = config.reservedInteractiveWorkers;
  options.heavySeconds = config.heavyRequestMs / 1000.0;
  options.heavyQueueSeconds = config.heavyQueueMs / 1000.0;
  options.clientQueueDepth = static_cast<size_t>(config.clientQueueDepth);
  options.heavyNice = config.heavyWorkerNice;
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
    keepFreedMemoryForReuse();  // tasks run in this process (worker processes call it too)
  }
  status_.resize(count);
  assigned_.resize(count);
  referenceCounters_.resize(count);
  for (auto& lane : lanes_) lane = std::make_unique<LaneQueue>();

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
    rasterizer = startRasterizer();
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
      options_.referenceCacheBytes / std::max<size_t>(status_.size(), 1);
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
  // The workers heavy and batch jobs run on yield the CPU to the reserved interactive ones: a
  // small request's worker then runs at nearly its own speed beside heavy renders.
  const bool reserveExists = static_cast<int>(status_.size()) > generalSlots();
  if (reserveExists && static_cast<int>(slot) < generalSlots() && options_.heavyNice > 0) {
    lowerPriority(worker.pid(), options_.heavyNice);
  }
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
    if (started_ < static_cast<int>(status_.size()) && status_[slot].starts == 0) return nullptr;
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

WorkerPool::Abandon WorkerPool::submit(Task task, Reply reply, uint64_t requestId,
                                       JobClass jobClass) {
  return enqueue(std::make_shared<Job>(std::move(task), nullptr, requestId, std::move(reply),
                                       Clock::now() + options_.timeout, std::move(jobClass)));
}

WorkerPool::Abandon WorkerPool::submitInServer(Work work, Reply reply, std::string client) {
  JobClass jobClass;
  jobClass.client = std::move(client);
  return enqueue(std::make_shared<Job>(Task{}, std::move(work), 0, std::move(reply),
                                       Clock::now() + options_.timeout, std::move(jobClass)));
}

WorkerPool::Abandon WorkerPool::enqueue(std::shared_ptr<Job> job) {
  api::Answer refusal;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || draining_) {
      refusal = unavailableAnswer("the server is shutting down");
    } else if (glFailures_ == static_cast<int>(status_.size())) {
      refusal = unavailableAnswer("no render worker has an OpenGL context: " +
                                  (status_.empty() ? std::string() : status_.front().error));
    } else if (std::optional<api::Answer> refused = admitLocked(*job)) {
      refusal = std::move(*refused);
    } else {
      job->deadlineEntry = deadlines_.emplace(job->deadline, job);
      ++queuedByClient_[job->jobClass.client];
      ++admitted_[laneIndex(job->lane)];
      lanes_[laneIndex(job->lane)]->push(job);
      dispatchLocked();
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

std::optional<api::Answer> WorkerPool::admitLocked(Job& job) {
  job.estimateS = job.jobClass.referenceSeconds * std::exp(logSpeed_);
  job.lane = job.jobClass.batch                       ? Lane::Batch
             : job.estimateS >= options_.heavySeconds ? Lane::Heavy
                                                      : Lane::Interactive;
  const size_t queued = queuedLocked();
  if (queued >= options_.queueDepth) {
    ++rejectedBusy_;
    ++refusals_["busy"];
    return busyAnswer("the render queue is full (" + std::to_string(options_.queueDepth) +
                          " waiting); retry later",
                      "queueDepth", retryAfterSecondsLocked());
  }
  // A client's share: clientQueueDepth when set; else, once the queue is half full, an equal
  // share of it among the clients with requests waiting (a lone client may fill it all).
  auto mine = queuedByClient_.find(job.jobClass.client);
  const size_t held = mine == queuedByClient_.end() ? 0 : mine->second;
  const size_t clients = queuedByClient_.size() + (held == 0 ? 1 : 0);
  const size_t share = options_.clientQueueDepth
                           ? options_.clientQueueDepth
                           : std::max<size_t>(1, options_.queueDepth / clients);
  const bool contended = options_.clientQueueDepth || queued >= options_.queueDepth / 2;
  if (job.lane != Lane::Batch && contended && held >= share) {
    double seconds = 0;
    for (const auto& lane : lanes_) {
      lane->forEach([&](const std::shared_ptr<Job>& j) {
        if (j->jobClass.client == job.jobClass.client) seconds += j->estimateS;
      });
    }
    ++rejectedBusy_;
    ++refusals_["client"];
    return busyAnswer("you have " + std::to_string(held) + " requests waiting, your share of " +
                          "the queue while others wait (clientQueueDepth " + std::to_string(share) +
                          "); retry when yours are answered",
                      "clientQueueDepth", drainSeconds(seconds, static_cast<int>(status_.size())));
  }
  const LaneQueue& heavy = *lanes_[laneIndex(Lane::Heavy)];
  if (job.lane == Lane::Heavy && heavy.size > 0 &&
      heavy.seconds + job.estimateS > options_.heavyQueueSeconds) {
    ++rejectedBusy_;
    ++refusals_["heavy"];
    return busyAnswer("the heavy-request lane is full (about " +
                          std::to_string(static_cast<int>(std::ceil(heavy.seconds))) +
                          " s of heavy work waiting, heavyQueueMs " +
                          std::to_string(static_cast<int>(options_.heavyQueueSeconds * 1000)) +
                          "); small requests are still taken",
                      "heavyQueueMs",
                      drainSeconds(heavy.seconds + runningHeavySeconds_, generalSlots()));
  }
  return std::nullopt;
}

std::string WorkerPool::serverTiming(const Job& job, double waitedS, double ranS) {
  std::string timing = "queue;dur=" + milliseconds(waitedS) + ";desc=\"" + laneName(job.lane) +
                       "\", run;dur=" + milliseconds(ranS);
  if (job.estimateS > 0) timing += ", estimate;dur=" + milliseconds(job.estimateS);
  return timing;
}

int WorkerPool::drainSeconds(double seconds, int workers) {
  return static_cast<int>(std::clamp(std::ceil(seconds / std::max(workers, 1)), 1.0, 60.0));
}

int WorkerPool::generalSlots() const {
  const int slots = static_cast<int>(status_.size());
  return std::max(1, slots - std::max(0, options_.reservedInteractive));
}

size_t WorkerPool::queuedLocked() const {
  size_t queued = 0;
  for (const auto& lane : lanes_) queued += lane->size;
  return queued;
}

int WorkerPool::idleSlotForLocked(Lane lane) const {
  const int general = generalSlots();
  if (lane != Lane::Interactive) {
    auto slot = idle_.begin();
    return slot != idle_.end() && static_cast<int>(*slot) < general ? static_cast<int>(*slot) : -1;
  }
  // Interactive work takes a reserved worker first, keeping the others for heavy work; the
  // same one each time while it is free (its reference cache).
  auto reserved = idle_.lower_bound(static_cast<size_t>(general));
  if (reserved != idle_.end()) return static_cast<int>(*reserved);
  return idle_.empty() ? -1 : static_cast<int>(*idle_.begin());
}

void WorkerPool::dispatchLocked() {
  bool gave = false;
  for (;;) {
    const LaneQueue& heavy = *lanes_[laneIndex(Lane::Heavy)];
    const bool heavyAged = heavy.size > 0 && Clock::now() - heavy.oldest() >= kHeavyAging;
    const std::array<Lane, kLanes> order =
        heavyAged ? std::array{Lane::Heavy, Lane::Interactive, Lane::Batch}
                  : std::array{Lane::Interactive, Lane::Heavy, Lane::Batch};
    bool given = false;
    for (Lane lane : order) {
      LaneQueue& queue = *lanes_[laneIndex(lane)];
      if (queue.size == 0) continue;
      const int slot = idleSlotForLocked(lane);
      if (slot < 0) continue;
      std::shared_ptr<Job> job = queue.pop();
      if (auto mine = queuedByClient_.find(job->jobClass.client);
          mine != queuedByClient_.end() && --mine->second == 0) {
        queuedByClient_.erase(mine);
      }
      idle_.erase(static_cast<size_t>(slot));
      assigned_[static_cast<size_t>(slot)] = std::move(job);
      given = gave = true;
      break;
    }
    if (!given) break;
  }
  if (gave) workAvailable_.notify_all();
}

void WorkerPool::unqueueLocked(const std::shared_ptr<Job>& job) {
  // A job already given to a slot stays there: the slot sees it settled and skips it.
  if (lanes_[laneIndex(job->lane)]->remove(job)) {
    if (auto mine = queuedByClient_.find(job->jobClass.client);
        mine != queuedByClient_.end() && --mine->second == 0) {
      queuedByClient_.erase(mine);
    }
  }
}

void WorkerPool::abandon(const std::shared_ptr<Job>& job) {
  Reply reply;
  {
    std::lock_guard lock(mutex_);
    reply = claimLocked(*job);
    if (!reply) return;  // answered already
    unqueueLocked(job);
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
  const auto until = Clock::now() + wakeAfter;
  for (;;) {
    if (!assigned_[slot]) {
      idle_.insert(slot);
      dispatchLocked();
    }
    auto given = [&] { return stopping_ || assigned_[slot] != nullptr; };
    const bool woken = wakeAfter.count() > 0 ? workAvailable_.wait_until(lock, until, given)
                                             : (workAvailable_.wait(lock, given), true);
    if (stopping_ || !woken) {
      idle_.erase(slot);
      return nullptr;
    }
    std::shared_ptr<Job> job = std::move(assigned_[slot]);
    if (job->settled) continue;  // answered while it was on its way (abandoned, timed out)
    running_.insert(job);
    ++busyWorkers_;
    ++runningByLane_[laneIndex(job->lane)];
    if (job->lane == Lane::Heavy) runningHeavySeconds_ += job->estimateS;
    status_[slot].busy = true;
    status_[slot].endpoint = job->work ? "" : endpointPath(job->task.endpoint);
    status_[slot].requestId = job->requestId;
    return job;
  }
}

void WorkerPool::finishJob(size_t slot, const std::shared_ptr<Job>& job, api::Answer answer,
                           Clock::time_point started, AfterJob after) {
  const double seconds = std::chrono::duration<double>(Clock::now() - started).count();
  const double waited = std::chrono::duration<double>(started - job->queued).count();
  if (options_.metrics) {
    options_.metrics->jobRan(laneName(job->lane), waited, seconds, answer, job->estimateS);
  }
  answer.headers.emplace_back("Server-Timing", serverTiming(*job, waited, seconds));
  Reply reply;
  {
    std::lock_guard lock(mutex_);
    --busyWorkers_;
    --runningByLane_[laneIndex(job->lane)];
    if (job->lane == Lane::Heavy) {
      runningHeavySeconds_ = std::max(0.0, runningHeavySeconds_ - job->estimateS);
    }
    // The estimates learn this machine's speed from the engine's jobs that ran to their end.
    if (!job->work && job->jobClass.referenceSeconds > 0 && answer.status == 200) {
      const double ratio = std::clamp(seconds / job->jobClass.referenceSeconds, 1e-3, 1e3);
      logSpeed_ += 0.1 * (std::log(ratio) - logSpeed_);
    }
    status_[slot].busy = false;
    status_[slot].endpoint = "";
    status_[slot].requestId = 0;
    running_.erase(job);
    renderSecondsSum_ += seconds;
    ++renderCount_;
    reply = claimLocked(*job);
    if (after == AfterJob::TakesNext) {
      idle_.insert(slot);
      dispatchLocked();
    }
    jobSettled_.notify_all();
  }
  job->work = nullptr;  // frees the request body now rather than when the last owner lets go
  job->task = {};
  if (reply) reply(std::move(answer));
  // A worker process trims its own memory.
  if (options_.isolation == Isolation::Thread) {
    trimFreedMemoryAbove(keptWorkerMemoryBytes(options_.limits.maxWorkerMemoryBytes));
  }
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
    unqueueLocked(job);
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
    if (queuedLocked() > 0) return false;
    for (const auto& job : assigned_) {
      if (job && !job->settled) return false;
    }
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
    for (const auto& lane : lanes_) {
      lane->forEach([&](const std::shared_ptr<Job>& job) {
        if (Reply reply = claimLocked(*job)) replies.push_back(std::move(reply));
      });
      lane->clear();
    }
    queuedByClient_.clear();
    for (const auto& job : assigned_) {
      if (job) {
        if (Reply reply = claimLocked(*job)) replies.push_back(std::move(reply));
      }
    }
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
  const int ready = static_cast<int>(status_.size()) - glFailures_;
  if (renderCount_ == 0 || ready <= 0) return 1;
  double mean = renderSecondsSum_ / static_cast<double>(renderCount_);
  double wait = mean * static_cast<double>(queuedLocked() + busyWorkers_) / ready;
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
  s.queued = queuedLocked();
  for (size_t l = 0; l < kLanes; ++l) {
    s.queuedByLane[l] = lanes_[l]->size;
    s.runningByLane[l] = runningByLane_[l];
  }
  int idleGeneral = 0;
  for (size_t slot : idle_) idleGeneral += static_cast<int>(slot) < generalSlots();
  s.freeForBatch = std::max(0, idleGeneral - static_cast<int>(s.queued));
  s.speedFactor = std::exp(logSpeed_);
  s.refusals = refusals_;
  s.admitted = admitted_;
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
