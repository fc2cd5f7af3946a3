// limn: the command line. `limn serve` runs the HTTP service; `limn render` runs one request
// file through the same engine without HTTP and writes the answer and its images to a folder;
// `limn batch` (server/batch_command.h) runs a batch of comparisons.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "api/config.h"
#include "api/implicit_api.h"
#include "api/render_api.h"
#include "batch/job_store.h"
#include "render/core/error.h"
#include "render/image/encode.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "server/batch_command.h"
#include "server/http_server.h"
#include "server/jobs.h"
#include "server/router.h"
#include "server/tasks.h"
#include "server/worker_pool.h"
#include "server/worker_process.h"

#ifndef LIMN_VERSION
#define LIMN_VERSION "unknown"
#endif

namespace {

using namespace limn;

constexpr const char* kHelp =
    R"(limn )" LIMN_VERSION R"( - renders smooth (subdivision) surfaces over HTTP

Usage:
  limn serve [--listen HOST:PORT] [--config FILE] [--workers N] [--job-store STORE]
      Runs the HTTP service. Defaults: 127.0.0.1:8080, built-in configuration, one render
      worker per core. Port 0 picks a free port. Once it accepts connections it prints
        limn listening on http://HOST:PORT
      on stdout. SIGINT or SIGTERM shut it down cleanly (exit status 0).
      Endpoints: POST /v1/render (images and metrics), POST /v1/silhouette (the contour
      curves of the limit surface as JSON polylines or SVG, pieces marked visible or hidden),
      POST /v1/meshes (a mesh kept for later requests by id), POST /v1/tessellate (the
      approximation as glTF, PLY or OBJ), POST /v1/compare (several methods against one
      reference per camera), POST /v1/jobs, GET /v1/jobs, GET and DELETE /v1/jobs/{id},
      GET /v1/jobs/{id}/results.csv|jsonl (a batch spec run in the background), GET / (the
      web page: open it in a browser), /examples, /healthz, /readyz, /metrics, /openapi.json.
      Jobs are kept in STORE: sqlite:PATH or a postgresql:// URI shared by several replicas
      (else LIMN_JOB_STORE, else the configuration's jobStore, else
      sqlite:$LIMN_DATA_DIR/jobs.sqlite, LIMN_DATA_DIR defaulting to ~/.local/state/limn).

  limn render REQUEST.json --out DIR [--config FILE]
      Runs one /v1/render request body through the engine without HTTP and writes
        DIR/response.json         the JSON answer (images as base64, metrics, timings)
        DIR/<pass>.png|exr        each requested image (color, mask, depth, normal, wireframe)
        DIR/reference_<pass>.*    the reference's images, when the request asks for them
      A request the service would refuse exits with status 2 and its JSON error on stderr.

  limn batch SPEC.json --out DIR [--server URL] [--shard-count N [--shard-index K]]
  limn batch --meshes DIR_OR_GLOB[,...] --methods coarse,uniform:3,adaptive:1,silhouette
             --views N --size PX --out DIR
      Compares many meshes x methods x views with the exact surface, on local render workers
      (one per core) or through a running server (--server http://HOST:PORT, its
      /v1/compare). Resumable: rows already in DIR/results*.jsonl are skipped. Writes
        DIR/results.jsonl (sharded: DIR/results-shard-K.jsonl), and unsharded also
        DIR/results.csv, DIR/summary.md, DIR/plots/*.svg|png, DIR/report.html
      `limn batch --report DIR` writes the report of every results*.jsonl in DIR without
      rendering. `limn batch --help` lists every option; docs/batch.md the spec.
      Exit status: 0 every row computed, 4 some rows carry errors, 2 a spec or mesh refused,
      3 the run could not finish (run it again to resume).

  limn help | --help      this text
  limn --version          the version

Environment (for containers; a command-line option wins over its variable):
  LIMN_CONFIG=FILE        the configuration file when there is no --config
  LIMN_LISTEN=HOST:PORT   limn serve's address when there is no --listen (over the file's)
  LIMN_AUTH_TOKEN=TOKEN   the bearer token when the configuration file sets none

Exit status: 0 success, 1 usage or configuration error, 2 bad request, 3 render failure.
)";

int usageError(const std::string& message) {
  std::cerr << "limn: " << message << "\n(see limn --help)\n";
  return 1;
}

// Parses "HOST:PORT", "[V6]:PORT" or ":PORT" (all interfaces is then 0.0.0.0).
bool parseListen(const std::string& text, std::string& host, unsigned short& port) {
  auto colon = text.rfind(':');
  if (colon == std::string::npos) return false;
  std::string h = text.substr(0, colon), p = text.substr(colon + 1);
  if (h.size() >= 2 && h.front() == '[' && h.back() == ']') h = h.substr(1, h.size() - 2);
  if (h.empty()) h = "0.0.0.0";
  if (p.empty() || p.find_first_not_of("0123456789") != std::string::npos || p.size() > 5) {
    return false;
  }
  unsigned long value = std::stoul(p);
  if (value > 65535) return false;
  host = h;
  port = static_cast<unsigned short>(value);
  return true;
}

std::optional<std::string> readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Options shared by both commands; each parses its own positional arguments.
struct CommandLine {
  std::vector<std::string> positional;
  std::optional<std::string> listen, config, workers, out, jobStore;
};

std::optional<CommandLine> parseArguments(int argc, char** argv, int first, std::string& error) {
  CommandLine cl;
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    std::optional<std::string>* target = nullptr;
    if (arg == "--listen") target = &cl.listen;
    if (arg == "--config") target = &cl.config;
    if (arg == "--workers") target = &cl.workers;
    if (arg == "--out") target = &cl.out;
    if (arg == "--job-store") target = &cl.jobStore;
    if (target) {
      if (i + 1 >= argc) {
        error = arg + " needs a value";
        return std::nullopt;
      }
      *target = argv[++i];
    } else if (arg.size() > 1 && arg[0] == '-') {
      error = "unknown option " + arg;
      return std::nullopt;
    } else {
      cl.positional.push_back(arg);
    }
  }
  return cl;
}

// The value of an environment variable, or nothing when it is unset or empty.
std::optional<std::string> environment(const char* name) {
  const char* value = std::getenv(name);
  if (!value || !*value) return std::nullopt;
  return std::string(value);
}

// --config FILE, else LIMN_CONFIG (a container image sets the variable once and mounts the
// file, so that its command line need not be overridden), else the built-in defaults.
std::optional<api::ServiceConfig> loadConfiguration(const CommandLine& cl) {
  std::optional<std::string> path = cl.config ? cl.config : environment("LIMN_CONFIG");
  if (!path) return api::ServiceConfig{};
  try {
    return api::loadConfig(*path);
  } catch (const api::ApiError& e) {
    std::cerr << "limn: configuration " << *path << ": " << e.message << "\n";
  } catch (const std::exception& e) {
    std::cerr << "limn: configuration " << *path << ": " << e.what() << "\n";
  }
  return std::nullopt;
}

// --job-store, else LIMN_JOB_STORE, else the configuration's jobStore, else a SQLite file in
// the data folder: LIMN_DATA_DIR, else $XDG_STATE_HOME/limn, else ~/.local/state/limn.
std::string jobStoreLocation(const CommandLine& cl, const api::ServiceConfig& config) {
  if (cl.jobStore) return *cl.jobStore;
  if (auto store = environment("LIMN_JOB_STORE")) return *store;
  if (!config.jobStore.empty()) return config.jobStore;
  std::string folder;
  if (auto data = environment("LIMN_DATA_DIR")) {
    folder = *data;
  } else if (auto state = environment("XDG_STATE_HOME")) {
    folder = *state + "/limn";
  } else if (auto home = environment("HOME")) {
    folder = *home + "/.local/state/limn";
  } else {
    folder = "limn-data";
  }
  return "sqlite:" + folder + "/jobs.sqlite";
}

// The name this process's rows and leases carry: LIMN_REPLICA, else host name and pid (a
// restarted process is another replica: the leases of the one before simply run out).
std::string replicaName() {
  if (auto name = environment("LIMN_REPLICA")) return *name;
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "limn");
  return std::string(host) + "-" + std::to_string(::getpid());
}

int serve(const CommandLine& cl) {
  if (!cl.positional.empty()) return usageError("serve takes no argument " + cl.positional[0]);
  auto config = loadConfiguration(cl);
  if (!config) return 1;
  if (cl.out) return usageError("--out belongs to limn render");
  // --listen, else LIMN_LISTEN (a container listens on all interfaces, a developer's machine
  // on loopback: the image sets the variable, the file keeps its default), else the file's.
  const char* listenName = "--listen";
  std::optional<std::string> listen = cl.listen;
  if (!listen && (listen = environment("LIMN_LISTEN"))) listenName = "LIMN_LISTEN";
  if (listen) {
    std::string host;
    unsigned short port = 0;
    if (!parseListen(*listen, host, port)) {
      return usageError(std::string(listenName) + " wants HOST:PORT, got " + *listen);
    }
    config->host = host;
    config->port = port;
  }
  if (cl.workers) {
    try {
      config->workers = std::stoi(*cl.workers);
    } catch (const std::exception&) {
      return usageError("--workers wants a number, got " + *cl.workers);
    }
    if (config->workers < 0) return usageError("--workers must be 0 (one per core) or more");
  }

  render::mesh::MeshCache meshCache(config->meshCacheBytes);
  server::ServiceMetrics metrics;
  server::PoolOptions poolOptions = server::poolOptions(*config);
  poolOptions.meshes = &meshCache;
  poolOptions.metrics = &metrics;
  server::WorkerPool pool(poolOptions);
  const std::vector<server::WorkerStatus> workers = pool.workerStatus();
  for (size_t i = 0; i < workers.size(); ++i) {
    if (!workers[i].ready)
      std::cerr << "limn: worker " << i << " has no OpenGL context: " << workers[i].error << "\n";
  }
  if (!workers.empty() && workers.front().ready) {
    std::cerr << "limn: " << workers.size() << " render workers ("
              << (poolOptions.isolation == server::Isolation::Process ? "processes" : "threads")
              << ") on " << workers.front().device.renderer << " (EGL "
              << workers.front().device.eglPlatform << ")\n";
  }

  server::AccessOptions access{config->authToken, config->corsOrigins};
  if (access.authToken.empty()) {
    if (const char* token = std::getenv("LIMN_AUTH_TOKEN"); token && *token)
      access.authToken = token;
  }
  // A store that cannot be opened ends the start, naming it: a replica that silently ran
  // without its jobs would answer 404 for every job of the cluster.
  const std::string storeLocation = jobStoreLocation(cl, *config);
  std::unique_ptr<batch::JobStore> store;
  try {
    store = batch::JobStore::open(storeLocation, replicaName(),
                                  {std::chrono::seconds(config->jobLeaseSeconds)});
  } catch (const std::exception& e) {
    std::cerr << "limn: job store: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "limn: jobs in " << store->describe() << " (replica " << store->replica() << ")\n";
  server::JobOptions jobOptions;
  jobOptions.maxJobs = config->maxJobs;
  jobOptions.maxJobRows = config->maxJobRows;
  jobOptions.retention = std::chrono::seconds(config->jobRetentionSeconds);
  server::JobManager jobs(pool, config->limits, jobOptions, std::move(store), &meshCache);
  server::Router router(config->limits, pool, metrics, access, config->logLevel, &meshCache, &jobs);
  server::HttpOptions httpOptions;
  httpOptions.host = config->host;
  httpOptions.port = config->port;
  httpOptions.ioThreads = config->ioThreads;
  httpOptions.maxBodyBytes = config->maxBodyBytes;
  httpOptions.drainTimeout = std::chrono::milliseconds(config->shutdownDrainMs);
  std::optional<server::HttpServer> http;
  try {
    http.emplace(httpOptions, router, pool);
  } catch (const std::exception& e) {
    std::cerr << "limn: " << e.what() << "\n";
    return 1;
  }

  std::string host = http->host();
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  std::cout << "limn listening on http://" << host << ":" << http->port() << std::endl;
  http->run();
  jobs.stop();  // the pool has answered its last comparisons: the running job ends now
  // Every stage checks its cancel token well within a second; a worker that has not stopped
  // after this is stuck, and must not keep the process alive (nor may its thread be joined).
  constexpr std::chrono::milliseconds kStuckWorkerGrace{3'000};
  if (!pool.joinFor(kStuckWorkerGrace)) {
    std::cerr << "limn: a render worker did not stop within " << kStuckWorkerGrace.count()
              << " ms of its cancellation; exiting without it\n";
    std::_Exit(1);
  }
  std::cerr << "limn: stopped\n";
  return 0;
}

void writeFile(const std::filesystem::path& path, const void* data, size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

int fail(const api::ApiError& error, int status) {
  std::cerr << api::errorAnswer(error).body << "\n";
  return status;
}

int renderCommand(const CommandLine& cl) {
  if (cl.positional.size() != 1) return usageError("render wants one REQUEST.json");
  if (!cl.out) return usageError("render wants --out DIR");
  if (cl.listen || cl.workers || cl.jobStore)
    return usageError("--listen, --workers and --job-store belong to limn serve");
  auto config = loadConfiguration(cl);
  if (!config) return 1;
  auto text = readFile(cl.positional[0]);
  if (!text) return usageError("cannot read " + cl.positional[0]);

  // The same command takes /v1/render's body and /v1/implicit's (which has a "field"), and
  // runs it through the same handler as the server.
  const server::Task task{
      api::isImplicitRequest(*text) ? server::Endpoint::Implicit : server::Endpoint::Render,
      std::move(*text)};
  api::Answer answer;
  try {
    render::raster::Rasterizer rasterizer;
    render::pipeline::RenderContext context;
    context.rasterizer = &rasterizer;
    answer = server::runTask(task, config->limits, context, render::CancelToken{}, nullptr);
  } catch (const std::exception& e) {
    return fail({500, "internal", e.what()}, 3);
  }
  if (answer.status != 200) {
    std::cerr << answer.body << "\n";
    return answer.status < 500 ? 2 : 3;
  }
  try {
    std::filesystem::path dir(*cl.out);
    std::filesystem::create_directories(dir);
    writeFile(dir / "response.json", answer.body.data(), answer.body.size());
    std::cout << (dir / "response.json").string() << "\n";
    for (const api::DecodedImage& image : api::imagesOf(answer.body)) {
      const auto path = dir / image.fileName;
      writeFile(path, image.bytes.data(), image.bytes.size());
      std::cout << path.string() << "\n";
    }
  } catch (const std::exception& e) {
    return fail({500, "internal", e.what()}, 3);
  }
  return 0;
}

// limn worker --fd N: a render worker process, started by limn serve (server/worker_process.h);
// not for people to run.
int workerCommand(int argc, char** argv) {
  if (argc != 4 || std::string(argv[2]) != "--fd") return usageError("worker is started by serve");
  return server::workerMain(std::atoi(argv[3]));
}

}  // namespace

int main(int argc, char** argv) {
  // A client that hangs up mid-answer, or a parent that stops reading stdout, must not kill
  // the server: writes then fail with EPIPE instead.
  std::signal(SIGPIPE, SIG_IGN);

  if (argc < 2) {
    std::cerr << kHelp;
    return 1;
  }
  std::string command = argv[1];
  if (command == "--help" || command == "-h" || command == "help") {
    std::cout << kHelp;
    return 0;
  }
  if (command == "--version") {
    std::cout << "limn " << LIMN_VERSION << "\n";
    return 0;
  }
  if (command == "batch") return server::batchCommand(argc, argv);
  if (command == "worker") return workerCommand(argc, argv);
  if (command != "serve" && command != "render") return usageError("unknown command " + command);

  std::string error;
  auto cl = parseArguments(argc, argv, 2, error);
  if (!cl) return usageError(error);
  try {
    return command == "serve" ? serve(*cl) : renderCommand(*cl);
  } catch (const std::exception& e) {
    std::cerr << "limn: " << e.what() << "\n";
    return 3;
  }
}
