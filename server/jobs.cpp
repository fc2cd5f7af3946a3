#include "server/jobs.h"

#include <iostream>

#include "api/batch_results.h"
#include "api/jobs_api.h"
#include "api/json_util.h"
#include "batch/report.h"
#include "server/access.h"
#include "server/tasks.h"

namespace limn::server {

using Clock = std::chrono::steady_clock;

// A group sent to the pool.
struct JobManager::InFlight {
  batch::ClaimedGroup group;
  std::shared_ptr<const api::BatchPlan> plan;
  api::RowGroup rows;
  WorkerPool::Abandon abandon;
};

// Its answer, waiting for the runner to store it.
struct JobManager::Finished {
  std::pair<std::string, size_t> key;
  api::Answer answer;
};

namespace {

api::Answer notFound(const std::string& id) {
  return api::errorAnswer({404, "not_found",
                           "no job " + api::json::quote(id) +
                               " (never created, forgotten, or finished longer ago than "
                               "jobRetentionSeconds)",
                           api::json::detailObject({{"id", id}})});
}

api::Answer storeUnavailable(const std::string& what) {
  api::Answer answer = api::errorAnswer(
      {503, "unavailable", "the job store cannot be reached: " + what + "; renders go on"});
  answer.headers.emplace_back("Retry-After", "5");
  return answer;
}

// An answer the group may get differently later: the server busy, timing out, shutting down.
bool transient(const api::Answer& answer) {
  return answer.status == 429 || answer.status == 503 || answer.status == 504 ||
         answer.status == 499 || answer.status == 0;
}

bool crashed(const api::Answer& answer) {
  return answer.status == 500 && answer.body.find("\"worker_crashed\"") != std::string::npos;
}

}  // namespace

JobManager::JobManager(WorkerPool& pool, const render::pipeline::JobLimits& limits,
                       JobOptions options, std::unique_ptr<batch::JobStore> store,
                       render::mesh::MeshCache* meshes)
    : pool_(pool), limits_(limits), options_(options), store_(std::move(store)), meshes_(meshes) {
  runner_ = std::thread([this] { runLoop(); });
}

JobManager::~JobManager() { stop(); }

std::string JobManager::storeProblem() const {
  std::lock_guard lock(mutex_);
  return problem_;
}

void JobManager::markUnhealthy(const batch::DatabaseError& e) {
  std::lock_guard lock(mutex_);
  if (problem_.empty()) std::cerr << "limn: job store: " << e.what() << "\n";
  problem_ = e.what();
}

JobManager::Counters JobManager::counters() const {
  std::lock_guard lock(mutex_);
  Counters c = counters_;
  c.inFlight = inFlight_.size();
  return c;
}

template <typename Fn>
api::Answer JobManager::withStore(Fn&& fn) {
  try {
    return fn();
  } catch (const batch::DatabaseError& e) {
    if (!e.lost) return api::errorAnswer({500, "internal", std::string("job store: ") + e.what()});
    markUnhealthy(e);
    return storeUnavailable(e.what());
  }
}

namespace {

// A job's record as the API shows it (without rows).
api::JobView viewFrom(const batch::JobRecord& job) {
  api::JobView view;
  view.id = job.id;
  view.state = job.state;
  view.done = job.rowsDone;
  view.total = job.totalRows;
  view.failed = job.rowsFailed;
  view.createdMs = job.createdMs;
  view.finishedMs = job.finishedMs;
  const int64_t end = job.finishedMs ? job.finishedMs
                                     : std::chrono::duration_cast<std::chrono::milliseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count();
  view.elapsedS = static_cast<double>(std::max<int64_t>(end - job.createdMs, 0)) / 1000.0;
  view.error = job.error;
  view.withRows = false;
  return view;
}

}  // namespace

api::Answer JobManager::viewOf(const batch::JobRecord& job, size_t offset, int status,
                               bool withRows) {
  api::JobView view = viewFrom(job);
  view.withRows = withRows;
  if (withRows) {
    view.offset = std::min(offset, job.rowsDone);
    for (batch::StoredRow& row : store_->rows(job.id, view.offset, options_.maxJobRows)) {
      view.rows.push_back(std::move(row.line));
    }
  }
  api::Answer answer;
  answer.status = status;
  answer.body = api::writeJob(view);
  return answer;
}

api::Answer JobManager::create(std::string_view body, const std::string& client,
                               const std::string& idempotencyKey) {
  return api::answerOrError("job", [&] {
    if (idempotencyKey.size() > 255) {
      api::json::fail("Idempotency-Key", "the Idempotency-Key header is longer than 255 bytes");
    }
    auto plan = std::make_shared<const api::BatchPlan>(
        api::parseJobSpec(body, limits_, options_.maxJobRows, meshes_));
    batch::NewJob job;
    job.client = client;
    job.idempotencyKey = idempotencyKey;
    job.requestHash = digestHex(body);
    job.spec = api::storedSpec(body, *plan);
    job.totalRows = plan->rows().size();
    for (api::RowGroup& group : plan->pendingGroups({}, {}, limits_.maxCompareRows)) {
      job.groups.push_back(std::move(group.rows));
    }
    return withStore([&] {
      batch::CreateOutcome outcome = store_->create(job, options_.maxJobs, options_.retention);
      using Kind = batch::CreateOutcome::Kind;
      if (outcome.kind == Kind::Full) {
        api::Answer busy =
            api::errorAnswer({429, "busy",
                              "the job store holds " + std::to_string(options_.maxJobs) +
                                  " unfinished jobs (limits.maxJobs); retry when one has finished",
                              api::json::detailObject({{"limit", "maxJobs"}})});
        busy.headers.emplace_back("Retry-After", "10");
        return busy;
      }
      if (outcome.kind == Kind::KeyReused) {
        return api::errorAnswer(
            {422, "invalid_request",
             "Idempotency-Key " + api::json::quote(idempotencyKey) + " was used for job " +
                 outcome.job.id + " with another body; use a new key for a new job",
             api::json::detailObject({{"field", "Idempotency-Key"}, {"id", outcome.job.id}})});
      }
      {
        std::lock_guard lock(mutex_);
        if (outcome.kind == Kind::Created) {
          plans_[outcome.job.id] = plan;
          workAdded_ = true;
        }
      }
      wake_.notify_all();
      api::Answer answer = viewOf(outcome.job, 0, outcome.kind == Kind::Created ? 202 : 200, true);
      answer.headers.emplace_back("Location", "/v1/jobs/" + outcome.job.id);
      return answer;
    });
  });
}

api::Answer JobManager::get(const std::string& id, size_t offset) {
  return withStore([&] {
    std::optional<batch::JobRecord> job = store_->find(id);
    return job ? viewOf(*job, offset, 200, true) : notFound(id);
  });
}

api::Answer JobManager::list(const std::string& client, const std::string& after, size_t limit) {
  return withStore([&] {
    batch::JobPage page = store_->list(client, after, limit);
    std::vector<api::JobView> views;
    for (const batch::JobRecord& job : page.jobs) views.push_back(viewFrom(job));
    api::Answer answer;
    answer.body = api::writeJobList(views, page.next, limit);
    return answer;
  });
}

api::Answer JobManager::cancel(const std::string& id) {
  return withStore([&] {
    std::optional<batch::JobRecord> job = store_->find(id);
    if (!job) return notFound(id);
    if (job->finished()) {
      store_->forget(id);
      return viewOf(*job, 0, 200, false);
    }
    job = store_->cancel(id);
    // This replica's comparisons of it stop now; the others' at their next heartbeat.
    std::vector<WorkerPool::Abandon> abandons;
    {
      std::lock_guard lock(mutex_);
      for (auto& [key, flight] : inFlight_) {
        if (key.first == id && flight->abandon) abandons.push_back(flight->abandon);
      }
    }
    for (auto& abandon : abandons) abandon();
    return job ? viewOf(*job, 0, 200, true) : notFound(id);
  });
}

api::Answer JobManager::results(const std::string& id, const std::string& format) {
  return withStore([&] {
    std::optional<batch::JobRecord> job = store_->find(id);
    if (!job) return notFound(id);
    api::Answer answer;
    const bool csv = format == "csv";
    answer.contentType = csv ? "text/csv; charset=utf-8" : "application/x-ndjson";
    answer.headers.emplace_back("Content-Disposition",
                                "attachment; filename=\"" + id + "-results." + format + "\"");
    if (csv) answer.body = batch::csvHeader();
    constexpr size_t kPage = 2000;
    for (size_t offset = 0;; offset += kPage) {
      std::vector<batch::StoredRow> rows = store_->rows(id, offset, kPage);
      for (const batch::StoredRow& row : rows) {
        if (!csv) {
          answer.body += row.line + "\n";
        } else if (std::optional<api::ResultRow> read = api::readResultLine(row.line)) {
          answer.body += batch::csvLine(*read);
        }
      }
      if (rows.size() < kPage) break;
    }
    return answer;
  });
}

void JobManager::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !runner_.joinable()) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (runner_.joinable()) runner_.join();
  // The comparisons still in flight are given up (their answers come back at once as 499),
  // and every answer is stored or its lease handed back.
  std::vector<WorkerPool::Abandon> abandons;
  {
    std::lock_guard lock(mutex_);
    for (auto& [key, flight] : inFlight_) {
      if (flight->abandon) abandons.push_back(flight->abandon);
    }
  }
  for (auto& abandon : abandons) abandon();
  std::deque<Finished> finished;
  {
    std::lock_guard lock(mutex_);
    finished.swap(finished_);
  }
  for (Finished& f : finished) settle(std::move(f));
  try {
    store_->releaseAll();
  } catch (const batch::DatabaseError& e) {
    std::cerr << "limn: job store: cannot hand back leases: " << e.what() << "\n";
  }
}

void JobManager::runLoop() {
  const Clock::duration beatEvery =
      std::max<Clock::duration>(store_->lease() / 3, std::chrono::milliseconds(50));
  Clock::time_point nextBeat = Clock::now();
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    while (!finished_.empty()) {
      Finished f = std::move(finished_.front());
      finished_.pop_front();
      lock.unlock();
      settle(std::move(f));
      lock.lock();
    }
    if (Clock::now() >= nextBeat) {
      lock.unlock();
      heartbeat();
      lock.lock();
      nextBeat = Clock::now() + beatEvery;
    }
    Claimed claimed = Claimed::Nothing;
    if (!stopping_ && problem_.empty()) {
      lock.unlock();
      claimed = claimWork();
      lock.lock();
    }
    // Every worker busy with this replica's groups: an answer wakes the runner. Nothing to
    // claim, or the workers busy with requests: it looks again after a poll.
    const Clock::time_point wakeAt = std::min(
        nextBeat,
        Clock::now() + (claimed == Claimed::Full ? beatEvery : Clock::duration(options_.poll)));
    wake_.wait_until(lock, wakeAt, [&] { return stopping_ || !finished_.empty() || workAdded_; });
    workAdded_ = false;
  }
}

JobManager::Claimed JobManager::claimWork() {
  for (;;) {
    // Requests first: a group is claimed only for a worker that batch work may use and that
    // nothing waits for (the pool's batch lane comes after the others anyway).
    const PoolSnapshot pool = pool_.snapshot();
    if (pool.stopping || pool.draining) return Claimed::Nothing;
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return Claimed::Nothing;
      if (static_cast<int>(inFlight_.size()) >= pool.readyWorkers) return Claimed::Full;
    }
    if (pool.freeForBatch <= 0) return Claimed::PoolBusy;
    try {
      std::optional<batch::ClaimedGroup> group = store_->claim();
      if (!group) return Claimed::Nothing;
      // A group that cannot start (its spec unreadable here) ends its job inside; a store lost
      // meanwhile leaves the group leased, to be claimed again when the lease runs out.
      startGroup(std::move(*group));
    } catch (const batch::DatabaseError& e) {
      markUnhealthy(e);
      return Claimed::Nothing;
    }
  }
}

std::shared_ptr<const api::BatchPlan> JobManager::planOf(const std::string& jobId) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = plans_.find(jobId); it != plans_.end()) return it->second;
  }
  std::optional<std::string> spec = store_->spec(jobId);
  if (!spec) return nullptr;
  // The stored spec has every mesh inline (api::storedSpec): no cache is needed to read it.
  auto plan = std::make_shared<const api::BatchPlan>(
      api::parseJobSpec(*spec, limits_, options_.maxJobRows, nullptr));
  std::lock_guard lock(mutex_);
  constexpr size_t kPlansKept = 4;
  if (plans_.size() >= kPlansKept) plans_.erase(plans_.begin());
  plans_[jobId] = plan;
  return plan;
}

void JobManager::startGroup(batch::ClaimedGroup group) {
  auto flight = std::make_shared<InFlight>();
  try {
    flight->plan = planOf(group.jobId);
  } catch (const api::ApiError& e) {
    // Another replica's spec that this one cannot read (a different limits section).
    store_->fail(group.jobId,
                 "replica " + store_->replica() + " cannot read the job's spec: " + e.message);
    return;
  }
  if (!flight->plan || group.rows.empty() || group.rows.back() >= flight->plan->rows().size()) {
    store_->fail(group.jobId, "the job's stored groups do not match its spec");
    return;
  }
  const api::BatchRow& first = flight->plan->rows()[group.rows.front()];
  flight->rows = {first.mesh, first.view, group.rows};
  flight->group = std::move(group);
  const std::pair<std::string, size_t> key{flight->group.jobId, flight->group.group};
  {
    std::lock_guard lock(mutex_);
    inFlight_[key] = flight;
  }
  // The pool may answer before submit returns (a refusal): the reply only queues the answer.
  WorkerPool::Abandon abandon =
      pool_.submit(Task{Endpoint::Compare, flight->plan->compareBody(flight->rows)},
                   [this, key](api::Answer answer) {
                     {
                       std::lock_guard lock(mutex_);
                       finished_.push_back({key, std::move(answer)});
                     }
                     wake_.notify_all();
                   });
  std::lock_guard lock(mutex_);
  flight->abandon = std::move(abandon);
}

void JobManager::count(size_t Counters::*counter) {
  std::lock_guard lock(mutex_);
  ++(counters_.*counter);
}

void JobManager::settle(Finished finished) {
  std::shared_ptr<InFlight> flight;
  bool stopping;
  {
    std::lock_guard lock(mutex_);
    auto it = inFlight_.find(finished.key);
    if (it == inFlight_.end()) return;
    flight = it->second;
    inFlight_.erase(it);
    stopping = stopping_;
  }
  const api::Answer& answer = finished.answer;
  const batch::ClaimedGroup& group = flight->group;
  try {
    const PoolSnapshot pool = pool_.snapshot();
    // Given up by this replica (a shutdown, a cancelled job): not the group's fault.
    if (answer.status == 499 ||
        (transient(answer) && (stopping || pool.draining || pool.stopping))) {
      store_->release(group, std::chrono::milliseconds(0), false);
      return;
    }
    const bool retry = crashed(answer) ? group.attempts < 2
                                       : transient(answer) && group.attempts < options_.maxAttempts;
    if (retry) {
      // 1 s, 2 s, 4 s, ...: a busy cluster gets time to drain.
      store_->release(group, std::chrono::milliseconds(1000 << std::min(group.attempts - 1, 5)),
                      true);
      count(&Counters::retried);
      return;
    }
    std::vector<std::string> lines = api::resultLines(*flight->plan, flight->rows, answer);
    std::vector<batch::StoredRow> rows;
    for (size_t i = 0; i < lines.size() && i < group.rows.size(); ++i) {
      std::optional<api::ResultRow> read = api::readResultLine(lines[i]);
      rows.push_back({group.rows[i], flight->plan->rows()[group.rows[i]].key,
                      api::withReplica(lines[i], store_->replica()), read && read->error});
    }
    store_->complete(group, rows);
    count(&Counters::stored);
  } catch (const batch::DatabaseError& e) {
    // The lease runs out and the group is claimed again; its rows are made once more.
    markUnhealthy(e);
  }
}

void JobManager::heartbeat() {
  try {
    bool wasHealthy;
    {
      std::lock_guard lock(mutex_);
      wasHealthy = problem_.empty();
    }
    if (!wasHealthy) store_->ping();
    std::vector<std::pair<std::string, size_t>> held;
    {
      std::lock_guard lock(mutex_);
      for (const auto& [key, flight] : inFlight_) held.push_back(key);
    }
    std::vector<std::string> stopped = store_->heartbeat(held);
    store_->expire(options_.retention);
    std::vector<WorkerPool::Abandon> abandons;
    {
      std::lock_guard lock(mutex_);
      if (!problem_.empty()) std::cerr << "limn: job store: reachable again\n";
      problem_.clear();
      for (auto& [key, flight] : inFlight_) {
        if (flight->abandon &&
            std::find(stopped.begin(), stopped.end(), key.first) != stopped.end())
          abandons.push_back(flight->abandon);
      }
    }
    for (auto& abandon : abandons) abandon();
  } catch (const batch::DatabaseError& e) {
    markUnhealthy(e);
  }
}

}  // namespace limn::server
