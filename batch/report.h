// The report of a batch, made from its results files alone (no rendering): `limn batch` writes
// it at the end of an unsharded run, `limn batch --report DIR` after sharded ones.
//
//   results.csv   one line per row, every metric and timing as a column
//   summary.md    per method: rows, the outline error's median / p95 / worst, the median
//                 triangles and time; the hardest rows
//   plots/        error vs triangles (with the Pareto front), time vs triangles, error per shape,
//                 as SVG and PNG (scripts/batch_plots.py, matplotlib)
//   report.html   the table and the plots on one page, styled like limn's web page
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "api/batch_results.h"

namespace limn::batch {

// Every row of every results*.jsonl in `dir`, one per key: a later line replaces an earlier
// one, except that a row with an error never replaces one without. Lines that are not rows (cut
// short by a crash) are counted in *unreadable. Sorted by mesh, view and method.
std::vector<api::ResultRow> readResults(const std::filesystem::path& dir,
                                        size_t* unreadable = nullptr);

// The keys a run need not compute again: rows without an error, or with one of their own (4xx).
std::set<std::string> finishedKeys(const std::vector<api::ResultRow>& rows);

// The CSV columns: the row's place, then every metric, timing and error field.
std::vector<std::string> csvColumns();
void writeCsv(const std::vector<api::ResultRow>& rows, const std::filesystem::path& file);
// The same file a piece at a time (GET /v1/jobs/{id}/results.csv): the header, then a line per
// row, each ending in a newline.
std::string csvHeader();
std::string csvLine(const api::ResultRow& row);

// Per method label (the table of summary.md and report.html).
struct MethodSummary {
  std::string label, method;
  size_t rows = 0, failed = 0;
  double medianError = 0, p95Error = 0, worstError = 0;  // outline Hausdorff distance, px
  std::string worstRow;                                  // "mesh, view" of the worst
  double medianIou = 0, medianRelGeometry = 0;
  double medianTriangles = 0, medianMs = 0;  // ms: approximation + raster
};
std::vector<MethodSummary> summarize(const std::vector<api::ResultRow>& rows);

// The median and the p95 (nearest rank) of values; 0 for none.
double median(std::vector<double> values);
double percentile(std::vector<double> values, double p);

void writeSummary(const std::vector<api::ResultRow>& rows, const std::filesystem::path& file);
// `css`: the web page's style sheet, shared so the report looks like the page.
void writeHtml(const std::vector<api::ResultRow>& rows, const std::filesystem::path& dir,
               const std::string& css, const std::vector<std::string>& plots);

// Runs the plot script (its text) with /usr/bin/python3 (LIMN_PYTHON overrides) on `dir`;
// the plots written, or nothing with the reason in *why (matplotlib missing, say).
std::vector<std::string> makePlots(const std::filesystem::path& dir, const std::string& script,
                                   std::string* why);

}  // namespace limn::batch
