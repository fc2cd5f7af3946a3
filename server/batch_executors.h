// Where the rows of a batch are computed (batch::Executor): PoolExecutor sends each comparison
// to a WorkerPool as a /v1/compare Task — the pool `limn batch` starts for itself, or the
// server's own pool for POST /v1/jobs, with its queue, limits and deadline — and
// RemoteExecutor sends it to a running server's POST /v1/compare.
#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "batch/runner.h"
#include "render/pipeline/render_job.h"
#include "server/http_client.h"
#include "server/worker_pool.h"

namespace limn::server {

class PoolExecutor : public batch::Executor {
 public:
  // `inFlight`: comparisons kept queued or running (0: one per worker).
  explicit PoolExecutor(WorkerPool& pool, int inFlight = 0);
  Abandon submit(std::string body, Done done) override;
  int parallelism() const override { return inFlight_; }

 private:
  WorkerPool& pool_;
  int inFlight_;
};

// `connections` threads, each sending one comparison at a time.
class RemoteExecutor : public batch::Executor {
 public:
  RemoteExecutor(HttpClient client, int connections);
  ~RemoteExecutor() override;  // waits for the requests under way
  Abandon submit(std::string body, Done done) override;
  int parallelism() const override { return static_cast<int>(threads_.size()); }

 private:
  void sendLoop();

  HttpClient client_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::pair<std::string, Done>> queue_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace limn::server
