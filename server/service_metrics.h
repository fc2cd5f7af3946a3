// ServiceMetrics: everything GET /metrics reports about requests, in Prometheus' text format
// (version 0.0.4): answers by route and status, request durations, queue waits, per-stage
// render times and mesh sizes as cumulative-bucket histograms. Debian 12 has no prometheus-cpp,
// so the few families limn needs are kept here; tests/integration parses the output with
// Prometheus' own Python parser. Thread-safe: connections, workers and /metrics share one.
#pragma once

#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "api/answer.h"

namespace limn::server {

// One histogram's buckets (upper bounds, +Inf implied), counts, sum.
class Histogram {
 public:
  explicit Histogram(const std::vector<double>* upperBounds);
  void observe(double value);
  // `name{labels,le="..."} n` lines for every bucket, then _sum and _count. `labels` is
  // `k="v",...` or "".
  void write(std::string& out, const std::string& name, const std::string& labels) const;

 private:
  const std::vector<double>* bounds_;
  std::vector<size_t> counts_;  // per bucket, not cumulative; last = above every bound
  double sum_ = 0;
  size_t count_ = 0;
};

class ServiceMetrics {
 public:
  ServiceMetrics();

  // An answer the HTTP layer wrote. `route` is a known path or "other" (Router::routeLabel),
  // so a scanner probing random URLs cannot grow the label set.
  void answered(const std::string& route, int status, double seconds);
  // A job a render worker ran: its lane, how long it waited in the queue, how long it ran, what
  // the api layer reported of its stages and its mesh, and the run time it was estimated at
  // (0: none; the ratio is recorded for jobs answered 200).
  void jobRan(const std::string& lane, double queueWaitSeconds, double runSeconds,
              const api::Answer& answer, double estimatedSeconds = 0);

  // The families above as exposition text (HELP, TYPE, samples).
  std::string text() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, int>, size_t> answers_;
  std::map<std::pair<std::string, int>, Histogram> durations_;
  Histogram queueWait_, jobRun_, meshFaces_, estimateRatio_;
  std::map<std::string, Histogram> laneWaits_, laneRuns_;
  std::map<std::string, Histogram> stages_;
};

// Prometheus label values escape backslash, quote and newline.
std::string labelValue(std::string_view text);

}  // namespace limn::server
