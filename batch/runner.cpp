#include "batch/runner.h"

#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>

#include "api/batch_results.h"

namespace limn::batch {

namespace {

using Clock = std::chrono::steady_clock;

// The comparisons' answers arrive on other threads; the runner's loop takes them from here.
struct Mailbox {
  std::mutex mutex;
  std::condition_variable arrived;
  std::deque<std::pair<size_t, api::Answer>> answers;  // group index, answer

  void post(size_t group, api::Answer answer) {
    std::lock_guard lock(mutex);
    answers.emplace_back(group, std::move(answer));
    arrived.notify_all();
  }
};

// A group waiting to be sent: now, or again after a refusal.
struct Pending {
  size_t group;
  Clock::time_point notBefore;
  int attempts = 0;
};

std::string errorMessage(const api::Answer& answer) {
  std::optional<std::string> message = api::errorMessageOf(answer.body);
  return message ? *message : answer.body.substr(0, 300);
}

class Run {
 public:
  Run(const api::BatchPlan& plan, const std::vector<api::RowGroup>& groups, Executor& executor,
      const RunCallbacks& callbacks, const std::atomic<bool>& stop, const RunOptions& options)
      : plan_(plan),
        groups_(groups),
        executor_(executor),
        callbacks_(callbacks),
        stop_(stop),
        options_(options),
        mailbox_(std::make_shared<Mailbox>()) {
    for (size_t g = 0; g < groups.size(); ++g) waiting_.push_back({g, Clock::now(), 0});
    for (const api::RowGroup& g : groups) total_ += g.rows.size();
    summary_.groups = groups.size();
  }

  RunSummary operator()() {
    while ((!waiting_.empty() && summary_.unavailable.empty()) || !inFlight_.empty()) {
      if (stop_) return giveUp();
      sendWhatIsDue();
      std::unique_lock lock(mailbox_->mutex);
      // Wake for an answer, a retry falling due, or (every 200 ms) to look at `stop`.
      mailbox_->arrived.wait_until(lock, nextWake(), [&] { return !mailbox_->answers.empty(); });
      std::deque<std::pair<size_t, api::Answer>> answers;
      answers.swap(mailbox_->answers);
      lock.unlock();
      for (auto& [group, answer] : answers) settle(group, std::move(answer));
    }
    return summary_;
  }

 private:
  Clock::time_point nextWake() const {
    Clock::time_point wake = Clock::now() + std::chrono::milliseconds(200);
    if (!waiting_.empty() && inFlight_.size() < capacity() && waiting_.front().notBefore < wake) {
      wake = waiting_.front().notBefore;
    }
    return wake;
  }

  size_t capacity() const { return static_cast<size_t>(std::max(executor_.parallelism(), 1)); }

  void sendWhatIsDue() {
    while (summary_.unavailable.empty() && !waiting_.empty() && inFlight_.size() < capacity() &&
           waiting_.front().notBefore <= Clock::now()) {
      Pending next = waiting_.front();
      waiting_.pop_front();
      attempts_[next.group] = next.attempts + 1;
      // The mailbox outlives this run, should an answer come after it gave up.
      std::shared_ptr<Mailbox> mailbox = mailbox_;
      inFlight_[next.group] = executor_.submit(
          plan_.compareBody(groups_[next.group]),
          [mailbox, group = next.group](api::Answer a) { mailbox->post(group, std::move(a)); });
    }
  }

  void settle(size_t group, api::Answer answer) {
    inFlight_.erase(group);
    const int attempts = attempts_[group];
    if (answer.status == 429 && !stop_) {
      // Busy is the pool protecting its queue, not a failure: wait and send it again.
      waiting_.push_front({group, Clock::now() + options_.busyPause, attempts});
      return;
    }
    if (answer.status == 0 && attempts < options_.transportAttempts && !stop_) {
      waiting_.push_back({group, Clock::now() + options_.busyPause * attempts, attempts});
      return;
    }
    if (answer.status == 499) return;  // given up by giveUp(): the rows stay pending
    if (answer.status == 503) {
      summary_.unavailable = errorMessage(answer);
      summary_.stopped = true;
      return;
    }
    const api::RowGroup& g = groups_[group];
    std::vector<std::string> lines = api::resultLines(plan_, g, answer);
    size_t failed = 0;
    for (const std::string& line : lines) {
      std::optional<api::ResultRow> row = api::readResultLine(line);
      failed += row && row->error;
    }
    summary_.rows += g.rows.size();
    summary_.failedRows += failed;
    if (callbacks_.rows) callbacks_.rows(g, lines);
    if (callbacks_.progress) callbacks_.progress(summary_.rows, total_, summary_.failedRows);
  }

  // Gives up the comparisons in flight and waits for their (499) answers, so that no callback
  // into this run's state is left pending when it returns.
  RunSummary giveUp() {
    for (auto& [group, abandon] : inFlight_) {
      if (abandon) abandon();
    }
    std::unique_lock lock(mailbox_->mutex);
    while (!inFlight_.empty()) {
      mailbox_->arrived.wait(lock, [&] { return !mailbox_->answers.empty(); });
      for (auto& answer : mailbox_->answers) inFlight_.erase(answer.first);
      mailbox_->answers.clear();
    }
    summary_.stopped = true;
    return summary_;
  }

  const api::BatchPlan& plan_;
  const std::vector<api::RowGroup>& groups_;
  Executor& executor_;
  const RunCallbacks& callbacks_;
  const std::atomic<bool>& stop_;
  RunOptions options_;
  std::shared_ptr<Mailbox> mailbox_;
  std::deque<Pending> waiting_;
  std::map<size_t, Executor::Abandon> inFlight_;
  std::map<size_t, int> attempts_;
  size_t total_ = 0;
  RunSummary summary_;
};

}  // namespace

RunSummary runGroups(const api::BatchPlan& plan, const std::vector<api::RowGroup>& groups,
                     Executor& executor, const RunCallbacks& callbacks,
                     const std::atomic<bool>& stop, const RunOptions& options) {
  return Run(plan, groups, executor, callbacks, stop, options)();
}

}  // namespace limn::batch
