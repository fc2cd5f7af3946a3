#include "server/worker_pool.h"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <iostream>
#include <utility>

namespace limn::server {

using Clock = render::CancelToken::Clock;

struct WorkerPool::Job {
  Job(Work w, Reply r, Clock::time_point due)
      : work(std::move(w)), reply(std::move(r)), queued(Clock::now()), deadline(due), token(due) {}

  Work work;
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

}  // namespace

WorkerPool::WorkerPool(const PoolOptions& options) : options_(options) {
  int count = options_.workers;
  if (count <= 0) count = std::max(1u, std::thread::hardware_concurrency());
  options_.workers = count;
  status_.resize(count);

  // Workers report their GL context before taking jobs, so that the first request after the
  // server says "listening" does not pay for context creation and /healthz is right at once.
  int started = 0;
  std::condition_variable startedCv;
  for (int i = 0; i < count; ++i) {
    workers_.emplace_back([this, i, &started, &startedCv] {
      std::unique_ptr<render::raster::Rasterizer> rasterizer;
      try {
        rasterizer = std::make_unique<render::raster::Rasterizer>();
        status_[i].ready = true;
        status_[i].device = rasterizer->device();
      } catch (const std::exception& e) {
        status_[i].error = e.what();
      }
      {
        // Notified under the lock: the constructor's locals must outlive this notification.
        std::lock_guard lock(mutex_);
        if (rasterizer) ++readyWorkers_;
        ++started;
        startedCv.notify_all();
      }
      if (rasterizer) workerLoop(*rasterizer);
      std::lock_guard lock(mutex_);
      ++exitedWorkers_;
      jobSettled_.notify_all();
    });
  }
  {
    std::unique_lock lock(mutex_);
    startedCv.wait(lock, [&] { return started == count; });
  }
  watchdog_ = std::thread([this] { watchdogMain(); });
}

WorkerPool::~WorkerPool() {
  stop();
  join();
}

WorkerPool::Abandon WorkerPool::submit(Work work, Reply reply) {
  api::Answer refusal;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || draining_) {
      refusal = unavailableAnswer("the server is shutting down");
    } else if (readyWorkers_ == 0) {
      refusal = unavailableAnswer("no render worker has an OpenGL context: " +
                                  (status_.empty() ? std::string() : status_.front().error));
    } else if (queue_.size() >= options_.queueDepth) {
      ++rejectedBusy_;
      refusal = busyAnswer(options_.queueDepth, retryAfterSecondsLocked());
    } else {
      auto job =
          std::make_shared<Job>(std::move(work), std::move(reply), Clock::now() + options_.timeout);
      job->deadlineEntry = deadlines_.emplace(job->deadline, job);
      queue_.push_back(job);
      workAvailable_.notify_one();
      // Only an earlier deadline than the watchdog's next one needs to wake it.
      if (job->deadlineEntry == deadlines_.begin()) deadlinesChanged_.notify_one();
      // The pool outlives the connections (HttpServer stops them first); the handle holds the
      // job weakly so that an answered job is freed at once.
      return [this, weak = std::weak_ptr<Job>(job)] {
        if (auto j = weak.lock()) abandon(j);
      };
    }
  }
  reply(std::move(refusal));
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

// A large job (a reference at 1024^2 allocates about a gigabyte in passes, masks and
// tessellations, across the TBB threads' malloc arenas) leaves that memory freed but resident:
// glibc keeps it for reuse. Handing it back costs a few milliseconds, which is nothing after a
// job that long and too much after every small one.
void WorkerPool::returnFreedMemory() { malloc_trim(0); }

WorkerPool::Reply WorkerPool::claimLocked(Job& job) {
  if (job.settled) return {};
  job.settled = true;
  deadlines_.erase(job.deadlineEntry);
  Reply reply = std::move(job.reply);
  job.reply = nullptr;
  return reply;
}

void WorkerPool::workerLoop(render::raster::Rasterizer& rasterizer) {
  render::pipeline::RenderContext context;
  context.rasterizer = &rasterizer;
  context.referenceCache = options_.referenceCache;
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock lock(mutex_);
      workAvailable_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      running_.insert(job);
      ++busyWorkers_;
    }

    auto start = Clock::now();
    api::Answer answer;
    try {
      answer = job->work(context, job->token);
    } catch (const std::exception& e) {
      answer = api::errorAnswer({500, "internal", std::string("render failed: ") + e.what()});
    } catch (...) {
      answer = api::errorAnswer({500, "internal", "render failed"});
    }
    double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (options_.metrics) {
      options_.metrics->jobRan(std::chrono::duration<double>(start - job->queued).count(), seconds,
                               answer);
    }

    Reply reply;
    {
      std::lock_guard lock(mutex_);
      --busyWorkers_;
      running_.erase(job);
      renderSecondsSum_ += seconds;
      ++renderCount_;
      reply = claimLocked(*job);
      jobSettled_.notify_all();
    }
    job->work = nullptr;  // frees the request body now rather than when the last owner lets go
    if (reply) reply(std::move(answer));
    if (seconds > kTrimAfterSeconds) returnFreedMemory();
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
}

int WorkerPool::retryAfterSecondsLocked() const {
  // Roughly how long until a queue slot frees: the mean render time times the jobs ahead,
  // spread over the workers; at least one second, at most a minute.
  if (renderCount_ == 0 || readyWorkers_ == 0) return 1;
  double mean = renderSecondsSum_ / static_cast<double>(renderCount_);
  double wait = mean * static_cast<double>(queue_.size() + busyWorkers_) / readyWorkers_;
  return static_cast<int>(std::clamp(std::ceil(wait), 1.0, 60.0));
}

PoolSnapshot WorkerPool::snapshot() const {
  std::lock_guard lock(mutex_);
  PoolSnapshot s;
  s.workers = static_cast<int>(status_.size());
  s.readyWorkers = readyWorkers_;
  s.busyWorkers = busyWorkers_;
  s.queued = queue_.size();
  s.queueCapacity = options_.queueDepth;
  s.stopping = stopping_;
  s.renderCount = renderCount_;
  s.rejectedBusy = rejectedBusy_;
  s.timedOut = timedOut_;
  s.cancelled = cancelled_;
  s.abandoned = abandoned_;
  return s;
}

}  // namespace limn::server
