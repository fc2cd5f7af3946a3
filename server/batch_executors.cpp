#include "server/batch_executors.h"

namespace limn::server {

PoolExecutor::PoolExecutor(WorkerPool& pool, int inFlight)
    : pool_(pool), inFlight_(inFlight > 0 ? inFlight : pool.snapshot().workers) {}

batch::Executor::Abandon PoolExecutor::submit(std::string body, Done done) {
  return pool_.submit(Task{Endpoint::Compare, std::move(body)}, std::move(done));
}

RemoteExecutor::RemoteExecutor(HttpClient client, int connections) : client_(std::move(client)) {
  for (int i = 0; i < std::max(connections, 1); ++i) threads_.emplace_back([this] { sendLoop(); });
}

RemoteExecutor::~RemoteExecutor() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  ready_.notify_all();
  for (std::thread& t : threads_) t.join();
}

// A request already sent cannot be taken back: the handle is empty, and the runner waits for
// its answer (at most the server's requestTimeoutMs).
batch::Executor::Abandon RemoteExecutor::submit(std::string body, Done done) {
  {
    std::lock_guard lock(mutex_);
    queue_.emplace_back(std::move(body), std::move(done));
  }
  ready_.notify_one();
  return {};
}

void RemoteExecutor::sendLoop() {
  for (;;) {
    std::pair<std::string, Done> next;
    {
      std::unique_lock lock(mutex_);
      ready_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;
      next = std::move(queue_.front());
      queue_.pop_front();
    }
    next.second(client_.post("/v1/compare", next.first));
  }
}

}  // namespace limn::server
