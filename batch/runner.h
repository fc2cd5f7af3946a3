// runGroups: computes a batch's pending row groups through an Executor — the local worker
// pool of `limn batch`, a server's /v1/compare with --server, or the server's own pool for
// POST /v1/jobs — keeping as many comparisons in flight as it has workers, and hands each
// group's result lines to the caller as they come. The same loop serves all three, so a row
// is the same row whichever way it was computed.
//
// A comparison refused because the workers are busy (429) is sent again after a pause; one
// that could not reach the server (status 0) is tried three times; a 503 (the server is
// shutting down, or has no working GL context) ends the run, leaving the rest for a later one;
// every other answer, error or not, becomes the group's lines (api/batch_results.h), so the run
// goes on past a failing mesh and a later run retries what was transient (ResultRow::retryable).
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "api/answer.h"
#include "api/batch_plan.h"

namespace limn::batch {

// Where comparisons run.
class Executor {
 public:
  using Done = std::function<void(api::Answer)>;
  using Abandon = std::function<void()>;
  virtual ~Executor() = default;
  // Sends one /v1/compare body. `done` gets its answer exactly once, from any thread, possibly
  // before submit returns. The handle (may be empty) gives the comparison up.
  virtual Abandon submit(std::string body, Done done) = 0;
  // How many comparisons to keep in flight.
  virtual int parallelism() const = 0;
};

struct RunCallbacks {
  // A group is done: its lines, in its rows' order. Called on the runner's thread.
  std::function<void(const api::RowGroup& group, const std::vector<std::string>& lines)> rows;
  // After each group: rows done in this run (ok or not), of `total` pending at its start.
  std::function<void(size_t done, size_t total, size_t failed)> progress;
};

struct RunSummary {
  size_t rows = 0, failedRows = 0, groups = 0;
  bool stopped = false;     // `stop` was set before every group was done
  std::string unavailable;  // the message of a 503 that ended the run early
};

struct RunOptions {
  std::chrono::milliseconds busyPause{500};  // before sending a comparison refused with 429
  int transportAttempts = 3;                 // for a server that cannot be reached
};

// Returns when every group is done, or soon after `stop` is set (the comparisons in flight are
// given up and their rows left for a later run).
RunSummary runGroups(const api::BatchPlan& plan, const std::vector<api::RowGroup>& groups,
                     Executor& executor, const RunCallbacks& callbacks,
                     const std::atomic<bool>& stop, const RunOptions& options = {});

}  // namespace limn::batch
