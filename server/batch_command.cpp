#include "server/batch_command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "api/batch_plan.h"
#include "api/batch_results.h"
#include "api/batch_spec.h"
#include "api/config.h"
#include "batch/mesh_files.h"
#include "batch/progress.h"
#include "batch/report.h"
#include "batch/runner.h"
#include "render/oracle/reference_scene.h"
#include "server/batch_executors.h"
#include "server/http_client.h"
#include "server/web_assets.h"
#include "server/worker_pool.h"

namespace limn::server {

// The plot script, built into the executable (server/CMakeLists.txt) so that a copied binary
// or a container image makes the same plots.
namespace batch_files {
extern const EmbeddedFile kEmbeddedFiles[];
extern const std::size_t kEmbeddedFileCount;
}  // namespace batch_files

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string spec, meshes, methods, out, server, token, config, report;
  int views = 3, size = 512, supersample = 4, workers = 0, connections = 0;
  uint64_t seed = 1;
  std::optional<int> shardIndex, shardCount;
  bool quiet = false, noPlots = false;
};

// A failure with its exit status and message.
struct Failure {
  int status;
  std::string message;
};

void say(const std::string& line) { std::cerr << "limn batch: " << line << "\n"; }

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Failure{1, "cannot read " + path.string()};
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  size_t start = 0;
  while (start <= text.size()) {
    size_t comma = text.find(',', start);
    if (comma == std::string::npos) comma = text.size();
    if (comma > start) items.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return items;
}

// The spec (from the file, or from the flags), and the folder its relative paths start from.
std::pair<api::BatchSpec, fs::path> readSpec(const Options& o, const CLI::App& app,
                                             const render::pipeline::JobLimits& limits) {
  api::BatchSpec spec;
  fs::path base = fs::current_path();
  try {
    if (!o.spec.empty()) {
      spec = api::parseBatchSpec(readFile(o.spec), limits);
      base = fs::absolute(o.spec).parent_path();
    } else {
      for (const std::string& pattern : splitList(o.meshes))
        spec.meshes.push_back({pattern, {}, "", ""});
      spec.methods = api::parseMethodList(o.methods, limits);
      spec.views = api::seededViews(o.views, o.seed);
    }
  } catch (const api::ApiError& e) {
    throw Failure{2, (o.spec.empty() ? "" : o.spec + ": ") + e.message};
  }
  if (o.spec.empty() || app.count("--size")) spec.size = o.size;
  if (o.spec.empty() || app.count("--supersample")) spec.supersample = o.supersample;
  if (spec.size < 1 || spec.size > limits.maxImageSide) {
    throw Failure{1, "--size must be in 1.." + std::to_string(limits.maxImageSide)};
  }
  if (spec.supersample < 1 || spec.supersample > limits.maxSupersample) {
    throw Failure{1, "--supersample must be in 1.." + std::to_string(limits.maxSupersample)};
  }
  return {spec, base};
}

// --shard-index, else JOB_COMPLETION_INDEX (a Kubernetes Indexed Job sets it) with --shard-count.
api::Shard readShard(const Options& o) {
  api::Shard shard;
  if (!o.shardCount) {
    if (o.shardIndex) throw Failure{1, "--shard-index needs --shard-count"};
    return shard;
  }
  shard.count = *o.shardCount;
  if (o.shardIndex) {
    shard.index = *o.shardIndex;
  } else if (const char* index = std::getenv("JOB_COMPLETION_INDEX"); index && *index) {
    try {
      shard.index = std::stoi(index);
    } catch (const std::exception&) {
      throw Failure{1, std::string("JOB_COMPLETION_INDEX is not a number: ") + index};
    }
  } else {
    throw Failure{1, "--shard-count needs --shard-index or JOB_COMPLETION_INDEX"};
  }
  if (shard.count < 1 || shard.index < 0 || shard.index >= shard.count) {
    throw Failure{1, "the shard index must be in 0.." + std::to_string(shard.count - 1)};
  }
  return shard;
}

fs::path resultsFile(const fs::path& dir, const api::Shard& shard, bool sharded) {
  return dir / (sharded ? "results-shard-" + std::to_string(shard.index) + ".jsonl"
                        : std::string("results.jsonl"));
}

// A line cut short (the process was killed while writing) is dropped, so appends start clean.
void dropPartialLine(const fs::path& file) {
  if (!fs::exists(file) || fs::file_size(file) == 0) return;
  std::string text = readFile(file);
  if (text.back() == '\n') return;
  const size_t lastEnd = text.rfind('\n');
  fs::resize_file(file, lastEnd == std::string::npos ? 0 : lastEnd + 1);
}

std::string styleSheet() {
  const EmbeddedFile* css = findWebAsset("/style.css");
  return css ? std::string(css->body()) : std::string();
}

std::string plotScript() {
  for (size_t i = 0; i < batch_files::kEmbeddedFileCount; ++i) {
    if (std::string_view(batch_files::kEmbeddedFiles[i].url) == "/batch_plots.py") {
      return std::string(batch_files::kEmbeddedFiles[i].body());
    }
  }
  return {};
}

// results.csv, summary.md, the plots and report.html from every results*.jsonl in `dir`.
int writeReport(const fs::path& dir, bool plots) {
  size_t unreadable = 0;
  std::vector<api::ResultRow> rows = batch::readResults(dir, &unreadable);
  if (rows.empty()) throw Failure{1, "no results*.jsonl rows in " + dir.string()};
  if (unreadable) say(std::to_string(unreadable) + " lines that are not rows were left out");
  batch::writeCsv(rows, dir / "results.csv");
  batch::writeSummary(rows, dir / "summary.md");
  std::vector<std::string> written;
  if (plots) {
    std::string why;
    written = batch::makePlots(dir, plotScript(), &why);
    if (written.empty()) say("no plots: " + why);
  }
  batch::writeHtml(rows, dir, styleSheet(), written);
  say("report of " + std::to_string(rows.size()) + " rows: " + (dir / "summary.md").string() +
      ", " + (dir / "report.html").string());
  return 0;
}

std::unique_ptr<batch::Executor> remoteExecutor(const Options& o,
                                                const api::ServiceConfig& config) {
  std::string why;
  std::optional<ServerUrl> url = parseServerUrl(o.server, &why);
  if (!url) throw Failure{1, "--server: " + why};
  std::string token = o.token;
  if (const char* env = std::getenv("LIMN_AUTH_TOKEN"); token.empty() && env) token = env;
  // A row group waits for the server's own deadline, and a little more.
  HttpClient client(*url, token, std::chrono::seconds(config.requestTimeoutMs / 1000 + 30));
  int connections = o.connections;
  if (connections <= 0) {
    api::Answer health = client.get("/healthz");
    if (health.status != 200) {
      throw Failure{3, o.server + "/healthz: " +
                           api::errorMessageOf(health.body).value_or(health.body.substr(0, 200))};
    }
    connections = api::workersOf(health.body).value_or(1);
  }
  return std::make_unique<RemoteExecutor>(std::move(client), connections);
}

// The render workers of limn serve's configuration: worker processes by default, so that a
// mesh that crashes one costs its own rows only.
std::unique_ptr<WorkerPool> localPool(const api::ServiceConfig& config, int workers) {
  PoolOptions options = poolOptions(config);
  if (workers > 0) options.workers = workers;
  options.queueDepth = 64;
  auto pool = std::make_unique<WorkerPool>(options);
  if (pool->snapshot().readyWorkers == 0) {
    throw Failure{3,
                  "no render worker has an OpenGL context: " + pool->workerStatus().front().error};
  }
  return pool;
}

// --config FILE, else LIMN_CONFIG (what limn serve reads too: a container sets it once).
api::ServiceConfig readConfig(const Options& o) {
  std::string path = o.config;
  if (const char* env = std::getenv("LIMN_CONFIG"); path.empty() && env && *env) path = env;
  if (path.empty()) return {};
  try {
    return api::loadConfig(path);
  } catch (const std::exception& e) {
    throw Failure{1, e.what()};
  }
}

int runBatch(const Options& o, const CLI::App& app) {
  const api::ServiceConfig config = readConfig(o);
  auto [spec, base] = readSpec(o, app, config.limits);
  const api::Shard shard = readShard(o);
  const bool sharded = o.shardCount.has_value();
  std::vector<std::string> warnings;
  std::vector<api::BatchMesh> meshes;
  try {
    meshes = batch::loadMeshes(spec.meshes, base, config.limits, warnings);
  } catch (const batch::MeshFileError& e) {
    throw Failure{2, e.what()};
  }
  for (const std::string& w : warnings) say(w);
  const api::BatchPlan plan(std::move(spec), std::move(meshes));

  const fs::path dir(o.out);
  fs::create_directories(dir);
  const fs::path file = resultsFile(dir, shard, sharded);
  dropPartialLine(file);
  const std::set<std::string> done = batch::finishedKeys(batch::readResults(dir));
  const std::vector<api::RowGroup> groups =
      plan.pendingGroups(shard, done, config.limits.maxCompareRows);
  size_t pending = 0, mine = 0;
  for (const api::RowGroup& g : groups) pending += g.rows.size();
  for (const api::BatchRow& r : plan.rows()) mine += r.index % shard.count == size_t(shard.index);
  say(std::to_string(plan.rows().size()) + " rows (" + std::to_string(plan.meshes().size()) +
      " meshes x " + std::to_string(plan.spec().views.size()) + " views x " +
      std::to_string(plan.spec().methods.size()) + " methods, " + std::to_string(plan.spec().size) +
      " px)" +
      (sharded ? "; shard " + std::to_string(shard.index) + " of " + std::to_string(shard.count) +
                     ": " + std::to_string(mine) + " rows"
               : "") +
      "; " + std::to_string(mine - pending) + " done already (skipped), " +
      std::to_string(pending) + " to compute");

  const Clock::time_point start = Clock::now();
  batch::RunSummary summary;
  if (pending > 0) {
    std::unique_ptr<WorkerPool> local;
    std::unique_ptr<batch::Executor> executor;
    if (!o.server.empty()) {
      executor = remoteExecutor(o, config);
    } else {
      local = localPool(config, o.workers);
      executor = std::make_unique<PoolExecutor>(*local);
    }
    std::ofstream results(file, std::ios::app | std::ios::binary);
    if (!results) throw Failure{1, "cannot write " + file.string()};
    batch::Progress progress(stderr, batch::Progress::modeFor(stderr, o.quiet), pending);
    batch::RunCallbacks callbacks;
    callbacks.rows = [&](const api::RowGroup&, const std::vector<std::string>& lines) {
      for (const std::string& line : lines) results << line << "\n";
      results.flush();  // a row written is a row a later run skips
    };
    callbacks.progress = [&](size_t n, size_t, size_t failed) { progress.update(n, failed); };
    std::atomic<bool> stop{false};
    summary = batch::runGroups(plan, groups, *executor, callbacks, stop);
    progress.finish(summary.rows, summary.failedRows);
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  say("computed " + std::to_string(summary.rows) + " rows (" + std::to_string(summary.failedRows) +
      " with errors) in " + batch::Progress::duration(seconds) + "; skipped " +
      std::to_string(mine - pending) + "; results in " + file.string());
  if (!summary.unavailable.empty()) {
    throw Failure{3, "stopped: " + summary.unavailable + " (run again to resume)"};
  }
  if (!sharded) writeReport(dir, !o.noPlots);
  return summary.failedRows > 0 ? 4 : 0;
}

}  // namespace

int batchCommand(int argc, char** argv) {
  CLI::App app{"limn batch: many meshes x methods x views, compared with the exact surface",
               "limn batch"};
  Options o;
  app.add_option("spec", o.spec, "a batch spec (JSON, docs/batch.md)");
  auto* meshes = app.add_option("--meshes", o.meshes, "files, folders or globs, comma-separated");
  auto* methods = app.add_option(
      "--methods", o.methods, "e.g. coarse,uniform:3,adaptive:1,silhouette (level, dicing rate)");
  app.add_option("--views", o.views, "seeded orbit views (with --meshes)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--seed", o.seed, "seed of the --views directions");
  app.add_option("--size", o.size, "image width and height, pixels");
  app.add_option("--supersample", o.supersample, "metricSupersample of every row");
  app.add_option("--out", o.out, "the folder for results.jsonl and the report");
  app.add_option("--server", o.server, "compute through a running limn: http://HOST:PORT");
  app.add_option("--token", o.token, "bearer token for --server (else LIMN_AUTH_TOKEN)");
  app.add_option("--connections", o.connections,
                 "requests in flight with --server (else its workers)");
  app.add_option("--workers", o.workers, "local render workers (default: one per core)");
  app.add_option("--config", o.config,
                 "a limn configuration file (limits, timeout, cache; else LIMN_CONFIG)");
  app.add_option("--shard-index", o.shardIndex, "this process's shard (else JOB_COMPLETION_INDEX)");
  app.add_option("--shard-count", o.shardCount, "shards in all: rows with index % N == K");
  app.add_option("--report", o.report, "only write the report of the results in this folder");
  app.add_flag("--quiet", o.quiet, "no progress output");
  app.add_flag("--no-plots", o.noPlots, "leave out the plots (no matplotlib)");
  meshes->excludes("spec");
  methods->excludes("spec");
  try {
    app.parse(argc - 1, argv + 1);
    if (!o.report.empty()) return writeReport(o.report, !o.noPlots);
    if (o.out.empty()) throw Failure{1, "--out DIR is required"};
    if (o.spec.empty() && (o.meshes.empty() || o.methods.empty())) {
      throw Failure{1, "give a SPEC file, or --meshes and --methods"};
    }
    if (!o.spec.empty() && app.count("--views"))
      throw Failure{1, "--views goes with --meshes, not a SPEC"};
    return runBatch(o, app);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  } catch (const Failure& f) {
    say(f.message);
    return f.status;
  } catch (const std::exception& e) {
    say(e.what());
    return 3;
  }
}

}  // namespace limn::server
