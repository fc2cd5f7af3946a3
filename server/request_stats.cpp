#include "server/request_stats.h"

namespace limn::server {

void RequestStats::record(const std::string& route, int status, double seconds) {
  std::lock_guard lock(mutex_);
  ++answers_[{route, status}];
  Duration& d = durations_[route];
  d.secondsSum += seconds;
  ++d.count;
}

std::map<std::pair<std::string, int>, size_t> RequestStats::answers() const {
  std::lock_guard lock(mutex_);
  return answers_;
}

std::map<std::string, RequestStats::Duration> RequestStats::durations() const {
  std::lock_guard lock(mutex_);
  return durations_;
}

}  // namespace limn::server
