// CancelToken: a job's deadline and cancellation flag, checked between stages and inside long
// loops so that a timed-out request stops using its worker.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>

#include "render/core/error.h"

namespace limn::render {

class CancelToken {
 public:
  using Clock = std::chrono::steady_clock;

  CancelToken() = default;
  explicit CancelToken(Clock::time_point deadline) : deadline_(deadline), hasDeadline_(true) {}
  // A token that also expires with `parent` (which must outlive it): for work run beside the
  // parent's, which can be stopped alone when the work beside it fails.
  explicit CancelToken(const CancelToken* parent) : parent_(parent) {}

  void cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool expired() const {
    return cancelled_.load(std::memory_order_relaxed) ||
           (hasDeadline_ && Clock::now() > deadline_) || (parent_ && parent_->expired());
  }
  // Throws Cancelled when the job should stop.
  void check() const {
    if (expired()) throw Cancelled();
  }

 private:
  std::atomic<bool> cancelled_{false};
  Clock::time_point deadline_{};
  bool hasDeadline_ = false;
  const CancelToken* parent_ = nullptr;
};

}  // namespace limn::render
