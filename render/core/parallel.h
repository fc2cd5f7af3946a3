// parallelFor: split [0, count) into chunks run on all hardware threads. Small and dependency
// free; the calling thread takes part, so a pool worker calling it never deadlocks waiting on
// itself. Exceptions from `body` are rethrown on the caller after all threads stop.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace limn::render {

// The most threads parallelFor uses; 0 (the default): one per hardware thread. For tests and
// benchmarks that compare results or times on 1 and 2 threads.
inline std::atomic<unsigned>& parallelThreadLimit() {
  static std::atomic<unsigned> limit{0};
  return limit;
}

template <typename Body>  // Body: void(size_t begin, size_t end)
void parallelFor(size_t count, size_t grain, const Body& body) {
  if (count == 0) return;
  grain = std::max<size_t>(grain, 1);
  size_t chunks = (count + grain - 1) / grain;
  size_t threads = std::min<size_t>(std::max(1u, std::thread::hardware_concurrency()), chunks);
  if (const unsigned limit = parallelThreadLimit().load())
    threads = std::min<size_t>(threads, limit);
  if (threads <= 1) {
    body(0, count);
    return;
  }
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex errorMutex;
  auto work = [&] {
    for (;;) {
      size_t chunk = next.fetch_add(1);
      if (chunk >= chunks) return;
      try {
        body(chunk * grain, std::min(count, (chunk + 1) * grain));
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (!error) error = std::current_exception();
        next.store(chunks);
      }
    }
  };
  std::vector<std::thread> pool;
  for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace limn::render
