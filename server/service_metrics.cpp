#include "server/service_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace limn::server {

namespace {

// Seconds: from a small /healthz (sub-millisecond) to a request at its 120 s deadline.
const std::vector<double> kSecondsBuckets = {0.001, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
                                             1,     2.5,   5,    10,    30,   60,  120};
// Control-mesh faces: the corpus spans 1 to a few thousand; limits allow far more.
const std::vector<double> kFaceBuckets = {10, 100, 1000, 10000, 100000, 1000000};
// Measured over estimated run time: within a factor 1.25, 2, 4, 8 either way.
const std::vector<double> kRatioBuckets = {0.125, 0.25, 0.5, 0.8, 1.25, 2, 4, 8};

// The shortest text that reads back as `value` (bucket bounds like 0.005, not 0.005000000001).
std::string number(double value) {
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  char text[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

void header(std::string& out, const char* name, const char* type, const char* help) {
  out += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
}

std::string routeLabels(const std::pair<std::string, int>& key) {
  return "path=\"" + labelValue(key.first) + "\",status=\"" + std::to_string(key.second) + "\"";
}

}  // namespace

std::string labelValue(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    if (c == '\\' || c == '"') out += '\\';
    out += c;
  }
  return out;
}

Histogram::Histogram(const std::vector<double>* upperBounds)
    : bounds_(upperBounds), counts_(upperBounds->size() + 1, 0) {}

void Histogram::observe(double value) {
  if (!std::isfinite(value)) return;
  // Prometheus buckets are "less than or equal": the first bound >= value.
  const size_t bucket =
      std::lower_bound(bounds_->begin(), bounds_->end(), value) - bounds_->begin();
  ++counts_[bucket];
  sum_ += value;
  ++count_;
}

void Histogram::write(std::string& out, const std::string& name, const std::string& labels) const {
  const std::string prefix = labels.empty() ? "" : labels + ",";
  size_t cumulative = 0;
  for (size_t i = 0; i <= bounds_->size(); ++i) {
    cumulative += counts_[i];
    const double bound = i < bounds_->size() ? (*bounds_)[i] : INFINITY;
    out += name + "_bucket{" + prefix + "le=\"" + number(bound) + "\"} " +
           std::to_string(cumulative) + "\n";
  }
  const std::string braces = labels.empty() ? "" : "{" + labels + "}";
  out += name + "_sum" + braces + " " + number(sum_) + "\n";
  out += name + "_count" + braces + " " + std::to_string(count_) + "\n";
}

ServiceMetrics::ServiceMetrics()
    : queueWait_(&kSecondsBuckets),
      jobRun_(&kSecondsBuckets),
      meshFaces_(&kFaceBuckets),
      estimateRatio_(&kRatioBuckets) {}

void ServiceMetrics::answered(const std::string& route, int status, double seconds) {
  std::lock_guard lock(mutex_);
  const std::pair<std::string, int> key{route, status};
  ++answers_[key];
  durations_.try_emplace(key, &kSecondsBuckets).first->second.observe(seconds);
}

void ServiceMetrics::jobRan(const std::string& lane, double queueWaitSeconds, double runSeconds,
                            const api::Answer& answer, double estimatedSeconds) {
  std::lock_guard lock(mutex_);
  queueWait_.observe(queueWaitSeconds);
  jobRun_.observe(runSeconds);
  laneWaits_.try_emplace(lane, &kSecondsBuckets).first->second.observe(queueWaitSeconds);
  laneRuns_.try_emplace(lane, &kSecondsBuckets).first->second.observe(runSeconds);
  if (estimatedSeconds > 0 && answer.status == 200) {
    estimateRatio_.observe(runSeconds / estimatedSeconds);
  }
  if (answer.meshFaces > 0) meshFaces_.observe(static_cast<double>(answer.meshFaces));
  for (const api::StageTime& stage : answer.stages) {
    stages_.try_emplace(stage.name, &kSecondsBuckets).first->second.observe(stage.ms / 1000);
  }
}

std::string ServiceMetrics::text() const {
  std::lock_guard lock(mutex_);
  std::string out;
  header(out, "limn_requests_total", "counter", "HTTP requests answered, by route and status.");
  for (const auto& [key, count] : answers_) {
    out += "limn_requests_total{" + routeLabels(key) + "} " + std::to_string(count) + "\n";
  }
  header(out, "limn_request_duration_seconds", "histogram",
         "Time from a request's last header byte to its answer, by route and status.");
  for (const auto& [key, histogram] : durations_) {
    histogram.write(out, "limn_request_duration_seconds", routeLabels(key));
  }
  header(out, "limn_queue_wait_seconds", "histogram",
         "Time render and contour jobs waited for a worker.");
  queueWait_.write(out, "limn_queue_wait_seconds", "");
  header(out, "limn_render_seconds", "histogram", "Time workers spent running a job.");
  jobRun_.write(out, "limn_render_seconds", "");
  header(out, "limn_lane_queue_wait_seconds", "histogram",
         "Time jobs waited for a worker, by lane (interactive, heavy, batch).");
  for (const auto& [lane, histogram] : laneWaits_) {
    histogram.write(out, "limn_lane_queue_wait_seconds", "lane=\"" + labelValue(lane) + "\"");
  }
  header(out, "limn_lane_run_seconds", "histogram", "Time workers spent on jobs, by lane.");
  for (const auto& [lane, histogram] : laneRuns_) {
    histogram.write(out, "limn_lane_run_seconds", "lane=\"" + labelValue(lane) + "\"");
  }
  header(out, "limn_cost_estimate_ratio", "histogram",
         "Measured run time over the estimate the job was admitted with (1: exact).");
  estimateRatio_.write(out, "limn_cost_estimate_ratio", "");
  header(out, "limn_render_stage_seconds", "histogram",
         "Time the engine spent in each stage of a job (surface, approx, raster, reference, ...).");
  for (const auto& [stage, histogram] : stages_) {
    histogram.write(out, "limn_render_stage_seconds", "stage=\"" + labelValue(stage) + "\"");
  }
  header(out, "limn_mesh_faces", "histogram", "Control-mesh faces of the jobs that read a mesh.");
  meshFaces_.write(out, "limn_mesh_faces", "");
  return out;
}

}  // namespace limn::server
