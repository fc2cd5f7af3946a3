#include "server/jobs.h"

#include <atomic>
#include <cstdio>
#include <random>

#include "api/batch_plan.h"
#include "api/jobs_api.h"
#include "api/json_util.h"
#include "batch/runner.h"
#include "server/batch_executors.h"

namespace limn::server {

using Clock = std::chrono::steady_clock;

struct JobManager::Job {
  Job(std::string i, api::BatchPlan p) : id(std::move(i)), plan(std::move(p)) {}

  const std::string id;
  const api::BatchPlan plan;
  std::string state = "queued";
  std::vector<std::string> rows;
  size_t failed = 0;
  std::string error;
  std::atomic<bool> cancelled{false};
  Clock::time_point created = Clock::now(), finished{};

  bool done() const { return state == "done" || state == "cancelled" || state == "failed"; }
};

namespace {

// Ids nobody can guess: the id is all a client needs to read or cancel a job.
std::string newJobId() {
  static std::mutex mutex;
  static std::random_device device;
  std::lock_guard lock(mutex);
  char text[33];
  std::snprintf(text, sizeof text, "%08x%08x%08x%08x", device(), device(), device(), device());
  return text;
}

api::Answer notFound(const std::string& id) {
  return api::errorAnswer({404, "not_found",
                           "no job " + api::json::quote(id) +
                               " (never created, or finished longer ago than "
                               "jobRetentionSeconds)",
                           api::json::detailObject({{"id", id}})});
}

}  // namespace

JobManager::JobManager(WorkerPool& pool, const render::pipeline::JobLimits& limits,
                       JobOptions options, render::mesh::MeshCache* meshes)
    : pool_(pool), limits_(limits), options_(options), meshes_(meshes) {
  driver_ = std::thread([this] { driverLoop(); });
}

JobManager::~JobManager() { stop(); }

void JobManager::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (auto& [id, job] : jobs_) job->cancelled = true;
  }
  changed_.notify_all();
  if (driver_.joinable()) driver_.join();
}

api::Answer JobManager::create(std::string_view body) {
  return api::answerOrError("job", [&] {
    api::BatchPlan plan = api::parseJobSpec(body, limits_, options_.maxJobRows, meshes_);
    std::lock_guard lock(mutex_);
    if (stopping_) return api::errorAnswer({503, "unavailable", "the server is shutting down"});
    if (!makeRoomLocked()) {
      api::Answer busy =
          api::errorAnswer({429, "busy",
                            "the server holds " + std::to_string(options_.maxJobs) +
                                " unfinished jobs (limits.maxJobs); retry when one has finished",
                            api::json::detailObject({{"limit", "maxJobs"}})});
      busy.headers.emplace_back("Retry-After", "10");
      return busy;
    }
    auto job = std::make_shared<Job>(newJobId(), std::move(plan));
    jobs_[job->id] = job;
    queue_.push_back(job);
    changed_.notify_all();
    api::Answer answer = viewLocked(*job, 0, 202);
    answer.headers.emplace_back("Location", "/v1/jobs/" + job->id);
    return answer;
  });
}

api::Answer JobManager::get(const std::string& id, size_t offset) {
  std::lock_guard lock(mutex_);
  dropExpiredLocked();
  auto it = jobs_.find(id);
  return it == jobs_.end() ? notFound(id) : viewLocked(*it->second, offset, 200);
}

api::Answer JobManager::cancel(const std::string& id) {
  std::unique_lock lock(mutex_);
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return notFound(id);
  std::shared_ptr<Job> job = it->second;
  if (job->done()) {
    jobs_.erase(it);
    return viewLocked(*job, 0, 200);
  }
  job->cancelled = true;
  if (job->state == "queued") {
    job->state = "cancelled";
    job->finished = Clock::now();
    std::erase(queue_, job);
  }
  // A running job stops within a moment (its comparisons in flight are given up).
  changed_.wait_for(lock, std::chrono::seconds(10), [&] { return job->done(); });
  return viewLocked(*job, 0, 200);
}

void JobManager::dropExpiredLocked() {
  const Clock::time_point now = Clock::now();
  std::erase_if(jobs_, [&](const auto& entry) {
    return entry.second->done() && now - entry.second->finished > options_.retention;
  });
}

bool JobManager::makeRoomLocked() {
  dropExpiredLocked();
  while (jobs_.size() >= options_.maxJobs) {
    auto oldest = jobs_.end();
    for (auto it = jobs_.begin(); it != jobs_.end(); ++it) {
      if (it->second->done() &&
          (oldest == jobs_.end() || it->second->finished < oldest->second->finished)) {
        oldest = it;
      }
    }
    if (oldest == jobs_.end()) return false;
    jobs_.erase(oldest);
  }
  return true;
}

api::Answer JobManager::viewLocked(const Job& job, size_t offset, int status) const {
  api::JobView view;
  view.id = job.id;
  view.state = job.state;
  view.done = job.rows.size();
  view.total = job.plan.rows().size();
  view.failed = job.failed;
  view.elapsedS = std::chrono::duration<double>(Clock::now() - job.created).count();
  view.error = job.error;
  view.offset = std::min(offset, job.rows.size());
  view.rows.assign(job.rows.begin() + static_cast<std::ptrdiff_t>(view.offset), job.rows.end());
  api::Answer answer;
  answer.status = status;
  answer.body = api::writeJob(view);
  return answer;
}

void JobManager::driverLoop() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = queue_.front();
      queue_.pop_front();
      job->state = "running";
    }
    runJob(*job);
  }
}

void JobManager::runJob(Job& job) {
  const std::vector<api::RowGroup> groups = job.plan.pendingGroups({}, {}, limits_.maxCompareRows);
  PoolExecutor executor(pool_);
  batch::RunCallbacks callbacks;
  callbacks.rows = [&](const api::RowGroup&, const std::vector<std::string>& lines) {
    std::lock_guard lock(mutex_);
    job.rows.insert(job.rows.end(), lines.begin(), lines.end());
  };
  callbacks.progress = [&](size_t, size_t, size_t failed) {
    std::lock_guard lock(mutex_);
    job.failed = failed;
  };
  batch::RunSummary summary =
      batch::runGroups(job.plan, groups, executor, callbacks, job.cancelled);
  std::lock_guard lock(mutex_);
  if (!summary.unavailable.empty()) {
    job.state = "failed";
    job.error = summary.unavailable;
  } else {
    job.state = summary.stopped ? "cancelled" : "done";
  }
  job.finished = Clock::now();
  changed_.notify_all();
}

}  // namespace limn::server
