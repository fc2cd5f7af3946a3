// readResults, finishedKeys, the CSV and the per-method statistics (batch/report.h).
#include "batch/report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>

namespace limn::batch {

namespace fs = std::filesystem;

namespace {

const char* const kMetricColumns[] = {"silhouette.outlineHausdorffPx",
                                      "silhouette.outlineMeanPx",
                                      "silhouette.hausdorffPx",
                                      "silhouette.meanPx",
                                      "silhouette.iou",
                                      "silhouette.mismatchPx",
                                      "image.rmse",
                                      "image.psnr",
                                      "depth.maxRel",
                                      "depth.meanRel",
                                      "normal.meanDeg",
                                      "normal.maxDeg",
                                      "geometry.maxDist",
                                      "geometry.meanDist",
                                      "geometry.relMaxDist"};
const char* const kTimingColumns[] = {"approxMs", "rasterMs", "metricsMs", "totalMs",
                                      "referenceMs"};

// The error the summary and the plots rank methods by: the continuous outline distance.
constexpr const char* kError = "silhouette.outlineHausdorffPx";

bool isResultsFile(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.rfind("results", 0) == 0 && p.extension() == ".jsonl";
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string numberText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

std::string optionalNumber(const std::map<std::string, double>& values, const char* key) {
  auto it = values.find(key);
  return it == values.end() ? "" : numberText(it->second);
}

double valueOr(const std::map<std::string, double>& values, const char* key, double otherwise) {
  auto it = values.find(key);
  return it == values.end() ? otherwise : it->second;
}

// Methods in the order people read them: the cheapest family first, then by triangles.
int familyRank(const std::string& method) {
  static const char* const kOrder[] = {"coarse", "uniform", "adaptive", "patches", "silhouette"};
  for (int i = 0; i < 5; ++i) {
    if (method == kOrder[i]) return i;
  }
  return 5;
}

}  // namespace

std::vector<api::ResultRow> readResults(const fs::path& dir, size_t* unreadable) {
  std::vector<fs::path> files;
  if (fs::is_directory(dir)) {
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.is_regular_file() && isResultsFile(entry.path())) files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::map<std::string, api::ResultRow> byKey;
  size_t bad = 0;
  for (const fs::path& file : files) {
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);) {
      if (line.empty()) continue;
      std::optional<api::ResultRow> row = api::readResultLine(line);
      if (!row) {
        ++bad;
        continue;
      }
      auto it = byKey.find(row->key);
      if (it == byKey.end()) {
        byKey.emplace(row->key, std::move(*row));
      } else if (!row->error || it->second.error) {
        it->second = std::move(*row);
      }
    }
  }
  if (unreadable) *unreadable = bad;
  std::vector<api::ResultRow> rows;
  for (auto& [key, row] : byKey) rows.push_back(std::move(row));
  std::stable_sort(rows.begin(), rows.end(), [](const api::ResultRow& a, const api::ResultRow& b) {
    return std::tie(a.mesh, a.view, a.label) < std::tie(b.mesh, b.view, b.label);
  });
  return rows;
}

std::set<std::string> finishedKeys(const std::vector<api::ResultRow>& rows) {
  std::set<std::string> keys;
  for (const api::ResultRow& row : rows) {
    if (!row.retryable()) keys.insert(row.key);
  }
  return keys;
}

std::vector<std::string> csvColumns() {
  std::vector<std::string> columns = {
      "key",     "mesh", "meshPath", "meshHash",    "label",     "method",      "params",
      "shading", "view", "size",     "supersample", "triangles", "controlFaces"};
  for (const char* c : kMetricColumns) columns.emplace_back(c);
  for (const char* c : kTimingColumns) columns.emplace_back(c);
  for (const char* c : {"errorStatus", "errorCode", "errorMessage"}) columns.emplace_back(c);
  return columns;
}

std::string csvHeader() {
  std::string line;
  for (const std::string& column : csvColumns()) line += (line.empty() ? "" : ",") + column;
  return line + "\n";
}

std::string csvLine(const api::ResultRow& r) {
  std::vector<std::string> fields = {r.key,
                                     r.mesh,
                                     r.meshPath,
                                     r.meshHash,
                                     r.label,
                                     r.method,
                                     r.params,
                                     r.shading,
                                     r.view,
                                     std::to_string(r.size),
                                     std::to_string(r.supersample)};
  fields.push_back(r.error ? "" : numberText(r.triangles));
  fields.push_back(r.error ? "" : numberText(r.controlFaces));
  for (const char* c : kMetricColumns) fields.push_back(optionalNumber(r.metrics, c));
  for (const char* c : kTimingColumns) fields.push_back(optionalNumber(r.timings, c));
  fields.push_back(r.error ? std::to_string(r.error->status) : "");
  fields.push_back(r.error ? r.error->code : "");
  fields.push_back(r.error ? r.error->message : "");
  std::string line;
  for (size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + csvField(fields[i]);
  return line + "\n";
}

void writeCsv(const std::vector<api::ResultRow>& rows, const fs::path& file) {
  std::ofstream out(file);
  out << csvHeader();
  for (const api::ResultRow& r : rows) out << csvLine(r);
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

double median(std::vector<double> values) { return percentile(std::move(values), 50); }

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  // Nearest rank: the smallest value with at least p% of the values at or below it.
  const size_t rank =
      static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size())));
  return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

std::vector<MethodSummary> summarize(const std::vector<api::ResultRow>& rows) {
  std::map<std::string, std::vector<const api::ResultRow*>> byLabel;
  for (const api::ResultRow& r : rows) byLabel[r.label].push_back(&r);
  std::vector<MethodSummary> out;
  for (const auto& [label, group] : byLabel) {
    MethodSummary s;
    s.label = label;
    s.method = group.front()->method;
    std::vector<double> errors, ious, geometry, triangles, ms;
    for (const api::ResultRow* r : group) {
      ++s.rows;
      if (r->error) {
        ++s.failed;
        continue;
      }
      const double error = valueOr(r->metrics, kError, NAN);
      if (std::isfinite(error)) {
        errors.push_back(error);
        if (error >= s.worstError) {
          s.worstError = error;
          s.worstRow = r->mesh + ", " + r->view;
        }
      }
      ious.push_back(valueOr(r->metrics, "silhouette.iou", 0));
      geometry.push_back(valueOr(r->metrics, "geometry.relMaxDist", 0));
      triangles.push_back(r->triangles);
      ms.push_back(valueOr(r->timings, "approxMs", 0) + valueOr(r->timings, "rasterMs", 0));
    }
    s.medianError = median(errors);
    s.p95Error = percentile(errors, 95);
    s.medianIou = median(ious);
    s.medianRelGeometry = median(geometry);
    s.medianTriangles = median(triangles);
    s.medianMs = median(ms);
    out.push_back(s);
  }
  std::sort(out.begin(), out.end(), [](const MethodSummary& a, const MethodSummary& b) {
    return std::make_tuple(familyRank(a.method), a.medianTriangles, a.label) <
           std::make_tuple(familyRank(b.method), b.medianTriangles, b.label);
  });
  return out;
}

}  // namespace limn::batch
