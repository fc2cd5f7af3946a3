// RequestStats: the HTTP counters behind GET /metrics — answers by route and status, and the
// time from a request's last header byte to its answer, by route. Thread-safe; the connection
// records every answer it writes, including the ones the HTTP layer makes itself (413, 400).
#pragma once

#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <utility>

namespace limn::server {

class RequestStats {
 public:
  struct Duration {
    double secondsSum = 0;
    size_t count = 0;
  };

  // `route` is a known path or "other" (the caller folds unknown paths so that a scanner
  // probing random URLs cannot grow the label set without bound).
  void record(const std::string& route, int status, double seconds);

  std::map<std::pair<std::string, int>, size_t> answers() const;
  std::map<std::string, Duration> durations() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, int>, size_t> answers_;
  std::map<std::string, Duration> durations_;
};

}  // namespace limn::server
