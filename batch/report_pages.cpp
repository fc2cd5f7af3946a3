// summary.md, report.html and the plots (batch/report.h).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "batch/report.h"

namespace limn::batch {

namespace fs = std::filesystem;

namespace {

constexpr size_t kHardestRows = 10;

std::string fixed(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

std::string count(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f", value);
  return text;
}

// One paragraph saying what was run and what the numbers mean.
std::string scope(const std::vector<api::ResultRow>& rows) {
  std::set<std::string> meshes, views, methods;
  size_t failed = 0;
  int size = 0, supersample = 0;
  for (const api::ResultRow& r : rows) {
    meshes.insert(r.meshHash);
    views.insert(r.view);
    methods.insert(r.label);
    failed += r.error.has_value();
    size = r.size;
    supersample = r.supersample;
  }
  std::ostringstream out;
  out << rows.size() << " rows (" << failed << " failed): " << meshes.size() << " meshes x "
      << views.size() << " views x " << methods.size() << " methods at " << size << " x " << size
      << " px, metrics supersampled S = " << supersample << ".";
  return out.str();
}

const char* kExplanation =
    "Error: the outline Hausdorff distance between the method's outline and the exact limit "
    "surface's, in output pixels (`metrics.silhouette.outlineHausdorffPx`); p95 is the nearest "
    "rank. IoU: of the two coverage masks. Geometry: the largest distance to the limit surface "
    "relative to the bounding-box diagonal. ms: the method's own time, median: its approximation "
    "and the raster of the passes its metrics need (colour, mask, depth and normal, the mask at S "
    "times the size); the reference (built once per mesh and view) and the metrics are not in it.";

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

Table methodTable(const std::vector<api::ResultRow>& rows) {
  Table t{{"method", "rows", "failed", "median px", "p95 px", "worst px", "worst (mesh, view)",
           "median IoU", "median rel. geometry", "median triangles", "median ms"},
          {}};
  for (const MethodSummary& s : summarize(rows)) {
    t.rows.push_back({s.label, std::to_string(s.rows), std::to_string(s.failed),
                      fixed(s.medianError, 3), fixed(s.p95Error, 3), fixed(s.worstError, 3),
                      s.worstRow, fixed(s.medianIou, 5), fixed(s.medianRelGeometry, 6),
                      count(s.medianTriangles), fixed(s.medianMs, 1)});
  }
  return t;
}

// The largest errors of every method but the cage itself: where the methods struggle.
Table hardestRows(const std::vector<api::ResultRow>& rows) {
  std::vector<const api::ResultRow*> ranked;
  for (const api::ResultRow& r : rows) {
    if (!r.error && r.method != "coarse" && r.metrics.count("silhouette.outlineHausdorffPx")) {
      ranked.push_back(&r);
    }
  }
  std::sort(ranked.begin(), ranked.end(), [](const api::ResultRow* a, const api::ResultRow* b) {
    return a->metrics.at("silhouette.outlineHausdorffPx") >
           b->metrics.at("silhouette.outlineHausdorffPx");
  });
  Table t{{"mesh", "view", "method", "error px", "triangles"}, {}};
  for (size_t i = 0; i < std::min(kHardestRows, ranked.size()); ++i) {
    const api::ResultRow& r = *ranked[i];
    t.rows.push_back({r.mesh, r.view, r.label,
                      fixed(r.metrics.at("silhouette.outlineHausdorffPx"), 3), count(r.triangles)});
  }
  return t;
}

Table failedRows(const std::vector<api::ResultRow>& rows) {
  Table t{{"mesh", "view", "method", "status", "error"}, {}};
  for (const api::ResultRow& r : rows) {
    if (r.error) {
      t.rows.push_back({r.mesh, r.view, r.label, std::to_string(r.error->status),
                        r.error->code + ": " + r.error->message.substr(0, 160)});
    }
  }
  return t;
}

bool isNumber(const std::string& text) {
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  return !text.empty() && end == text.c_str() + text.size();
}

std::string markdown(const Table& t) {
  auto cell = [](std::string text) {
    for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2)) {
      text.replace(at, 1, "\\|");
    }
    return text;
  };
  std::string out = "|";
  for (const std::string& h : t.header) out += " " + h + " |";
  out += "\n|";
  // Numbers right-aligned, words left: judged by the first row.
  for (size_t i = 0; i < t.header.size(); ++i) {
    const bool numeric = !t.rows.empty() && isNumber(t.rows.front()[i]);
    out += numeric ? " ---: |" : " --- |";
  }
  out += "\n";
  for (const auto& row : t.rows) {
    out += "|";
    for (const std::string& c : row) out += " " + cell(c) + " |";
    out += "\n";
  }
  return out;
}

std::string escapeHtml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string html(const Table& t) {
  std::string out = "<table><thead><tr>";
  for (const std::string& h : t.header) out += "<th>" + escapeHtml(h) + "</th>";
  out += "</tr></thead><tbody>\n";
  for (const auto& row : t.rows) {
    out += "<tr>";
    for (const std::string& c : row) out += "<td>" + escapeHtml(c) + "</td>";
    out += "</tr>\n";
  }
  return out + "</tbody></table>\n";
}

std::string shellQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

const char* kPlotTitles[][2] = {
    {"error_vs_triangles", "Outline error against triangles, per method (Pareto front dashed)"},
    {"time_vs_triangles", "Method time (approximation + raster) against triangles"},
    {"error_by_shape",
     "Outline error per shape and method (median over the views, bars from "
     "the best to the worst view)"}};

}  // namespace

void writeSummary(const std::vector<api::ResultRow>& rows, const fs::path& file) {
  std::ofstream out(file);
  out << "# limn batch: summary\n\n" << scope(rows) << "\n\n" << kExplanation << "\n\n";
  out << markdown(methodTable(rows)) << "\n";
  Table hardest = hardestRows(rows);
  if (!hardest.rows.empty()) {
    out << "## Largest errors\n\nThe " << hardest.rows.size()
        << " rows with the largest outline error, the control cage (coarse) left out.\n\n"
        << markdown(hardest) << "\n";
  }
  Table failed = failedRows(rows);
  if (!failed.rows.empty()) out << "## Failed rows\n\n" << markdown(failed) << "\n";
  out << "## Plots\n\n";
  for (const auto& [name, title] : kPlotTitles) {
    out << "- [" << title << "](plots/" << name << ".svg) ([PNG](plots/" << name << ".png))\n";
  }
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

void writeHtml(const std::vector<api::ResultRow>& rows, const fs::path& dir, const std::string& css,
               const std::vector<std::string>& plots) {
  std::ofstream out(dir / "report.html");
  out << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
      << "<title>limn batch report</title>\n<style>\n"
      << css
      << "\nbody { display: block; padding: 16px 24px; max-width: 1400px; }\n"
         "table { border-collapse: collapse; font-variant-numeric: tabular-nums; margin: 8px 0 "
         "18px; }\nth, td { border-bottom: 1px solid var(--line); padding: 3px 10px; text-align: "
         "right; }\nth:first-child, td:first-child { text-align: left; }\n"
         "th { color: var(--muted); font-weight: 600; }\nfigure { margin: 12px 0 24px; }\n"
         "figure img { max-width: 100%; border: 1px solid var(--line); }\n</style></head>\n"
      << "<body>\n<h1>limn batch report<small>" << escapeHtml(scope(rows)) << "</small></h1>\n"
      << "<p class=\"hint\">" << escapeHtml(kExplanation) << "</p>\n"
      << html(methodTable(rows));
  Table hardest = hardestRows(rows);
  if (!hardest.rows.empty()) out << "<h2>Largest errors</h2>\n" << html(hardest);
  Table failed = failedRows(rows);
  if (!failed.rows.empty()) out << "<h2>Failed rows</h2>\n" << html(failed);
  for (const auto& [name, title] : kPlotTitles) {
    const std::string svg = std::string("plots/") + name + ".svg";
    if (std::find(plots.begin(), plots.end(), svg) == plots.end()) continue;
    out << "<figure><img src=\"" << svg << "\" alt=\"" << escapeHtml(title) << "\"><figcaption>"
        << escapeHtml(title) << " (<a href=\"plots/" << name
        << ".png\">PNG</a>)</figcaption></figure>\n";
  }
  out << "<p class=\"hint\">Data: <a href=\"results.csv\">results.csv</a>, "
         "<a href=\"summary.md\">summary.md</a>, results*.jsonl.</p>\n</body></html>\n";
  if (!out) throw std::runtime_error("cannot write " + (dir / "report.html").string());
}

std::vector<std::string> makePlots(const fs::path& dir, const std::string& script,
                                   std::string* why) {
  const char* python = std::getenv("LIMN_PYTHON");
  // Debian's matplotlib is seen by Debian's interpreter; the python3 first on PATH may not be it.
  std::string interpreter = python && *python                ? python
                            : fs::exists("/usr/bin/python3") ? "/usr/bin/python3"
                                                             : "python3";
  char scriptPath[] = "/tmp/limn-batch-plots-XXXXXX";
  const int fd = ::mkstemp(scriptPath);
  if (fd < 0) {
    if (why) *why = "cannot write the plot script to /tmp";
    return {};
  }
  if (::write(fd, script.data(), script.size()) != static_cast<ssize_t>(script.size())) {
    if (why) *why = "cannot write the plot script to /tmp";
  }
  ::close(fd);
  const std::string command = shellQuoted(interpreter) + " " + shellQuoted(scriptPath) + " " +
                              shellQuoted(dir.string()) + " 2>&1";
  std::vector<std::string> plots;
  std::string output;
  if (std::FILE* pipe = ::popen(command.c_str(), "r")) {
    char line[4096];
    while (std::fgets(line, sizeof line, pipe)) {
      std::string text(line);
      while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
      if (text.rfind("wrote ", 0) == 0) {
        plots.push_back(text.substr(6));
      } else {
        output += text + "\n";
      }
    }
    const int status = ::pclose(pipe);
    if (status != 0 && why) *why = output.empty() ? "the plot script failed" : output;
  } else if (why) {
    *why = "cannot run " + interpreter;
  }
  ::unlink(scriptPath);
  return plots;
}

}  // namespace limn::batch
