// The rows of a batch as results.jsonl holds them (and GET /v1/jobs/{id} answers them): one
// JSON object per row, made from a /v1/compare answer and the row's place in the plan, and
// ResultRow, the same row read back as flat fields for resuming and for the report.
//
// A line: {"key", "mesh", "meshPath", "meshHash", "label", "method", "params", "shading",
// "view", "camera", "size", "supersample", "stats", "metrics", "timings", "reference",
// "warnings"} or, for a row that could not be made, "error": {"status", "code", "message"}
// instead of stats, metrics and timings. docs/batch.md lists every field.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/answer.h"
#include "api/batch_plan.h"

namespace limn::api {

// The lines of a group's rows from the /v1/compare answer to plan.compareBody(group). An
// answer other than 200 (a timeout, a refusal, a server out of reach: status 0) gives every row
// of the group its error.
std::vector<std::string> resultLines(const BatchPlan& plan, const RowGroup& group,
                                     const Answer& answer);

struct ResultError {
  int status = 0;  // HTTP status; 0: the server could not be reached
  std::string code, message;
};

struct ResultRow {
  std::string key, mesh, meshPath, meshHash, label, method, params, shading, view;
  int size = 0, supersample = 0;
  double triangles = 0, controlFaces = 0;
  // Every metric as "group.name" ("silhouette.outlineHausdorffPx"); the row's timings
  // ("approxMs", "rasterMs", "metricsMs", "totalMs") and its view's "referenceMs".
  std::map<std::string, double> metrics, timings;
  std::optional<ResultError> error;

  // A row worth computing again on the next run: the server was busy, timed out, went away
  // or failed (5xx, 429, 499, 0). A 4xx is the row's own and stays.
  bool retryable() const;
};

// The message of an error answer's body ({"error": {"message"}}), if it is one.
std::optional<std::string> errorMessageOf(std::string_view body);
// The "workers" of a /healthz answer, if it is one.
std::optional<int> workersOf(std::string_view healthBody);

// One line of results*.jsonl; nothing when it is not a row (a line cut short by a crash).
std::optional<ResultRow> readResultLine(std::string_view line);

}  // namespace limn::api
