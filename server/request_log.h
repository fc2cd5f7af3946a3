// RequestLog: one JSON line per answered request on stderr, through spdlog, so that a log
// shipper can parse limn's log without patterns:
//
//   {"ts":"2026-12-01T19:41:44.123Z","level":"info","id":17,"method":"POST","route":"/v1/render",
//    "status":200,"ms":12.3,"in":512,"out":20060,"stages":{"surfaceMs":0.4,...}}
//
// `id` numbers the requests of this process and is also sent back as X-Request-Id, so a client
// can quote it; `stages` is the engine's stage times (ms) for renders and contour searches. Answers
// of 500 and over are logged at level error, the rest at info; `logLevel` in the configuration
// ("debug", "info", "warn", "error", "off") filters them. Thread-safe.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "api/answer.h"

namespace spdlog {
class logger;
namespace sinks {
class sink;
}
}  // namespace spdlog

namespace limn::server {

struct AnsweredRequest {
  uint64_t id = 0;
  std::string_view method, route;
  int status = 0;
  double seconds = 0;
  size_t bytesIn = 0, bytesOut = 0;
  const std::vector<api::StageTime>* stages = nullptr;  // the engine's, for jobs; or none
};

class RequestLog {
 public:
  // Throws std::invalid_argument for an unknown level. `sink` (tests): where lines go instead
  // of stderr.
  explicit RequestLog(const std::string& level,
                      std::shared_ptr<spdlog::sinks::sink> sink = nullptr);
  ~RequestLog();

  uint64_t nextId() { return nextId_.fetch_add(1, std::memory_order_relaxed) + 1; }
  void answered(const AnsweredRequest& request);

 private:
  std::shared_ptr<spdlog::logger> logger_;
  std::atomic<uint64_t> nextId_{0};
};

}  // namespace limn::server
