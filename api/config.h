// ServiceConfig: the settings of one limn server process (listen address, worker pool, queue,
// request limits), with built-in defaults so that no file is needed. loadConfig() reads a JSON
// file whose keys mirror the member names (limits nested under "limits"); configs/default.json
// holds the defaults. Unknown keys are an error, so a misspelt key is never silently ignored.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "render/pipeline/render_job.h"

namespace limn::api {

struct ServiceConfig {
  std::string host = "127.0.0.1";
  int port = 8080;      // 0: any free port (tests)
  int workers = 0;      // render workers; 0 = one per core
  int queueDepth = 16;  // jobs waiting for a worker before answering 429
  // Lanes (server/worker_pool.h): workers kept for interactive requests (heavy and batch work
  // takes the others), the estimated run time from which a request is heavy, the estimated heavy
  // work that may wait before heavy requests get 429, and the requests one client may have
  // waiting (0: once the queue is half full, an equal share among the clients waiting).
  int reservedInteractiveWorkers = 1;
  int heavyRequestMs = 250;
  int heavyQueueMs = 30000;
  int clientQueueDepth = 0;
  // The nice value (0-19) of the worker processes heavy and batch work may use, when workers
  // are reserved for interactive requests: they yield the CPU to those.
  int heavyWorkerNice = 10;
  int ioThreads = 1;  // threads running the HTTP connections
  // "process": each render worker is a child process (a crash costs one request); "thread":
  // threads of the server itself (for debugging).
  std::string workerIsolation = "process";
  size_t maxBodyBytes = 64u << 20;
  int requestTimeoutMs = 120000;
  // On SIGTERM: how long the requests already queued or running may take to finish before
  // they are answered 503 and cancelled.
  int shutdownDrainMs = 10000;
  // Reference tessellations + BVHs kept for further requests with the same mesh and camera.
  size_t referenceCacheBytes = 512u << 20;
  // Meshes uploaded with POST /v1/meshes and referred to by id (least recently used go first).
  size_t meshCacheBytes = 256u << 20;
  // Bearer token the /v1 routes require ("" = none); the environment variable LIMN_AUTH_TOKEN
  // sets it when the file does not (limn serve), so it need not be written to a file.
  std::string authToken;
  // Web origins whose pages may read limn's answers (CORS); "*" = any; empty = none.
  std::vector<std::string> corsOrigins;
  // The request log's level on stderr: "debug", "info", "warn", "error" or "off".
  std::string logLevel = "info";
  render::pipeline::JobLimits limits;
  // POST /v1/jobs: jobs held (queued, running or finished; in the file under "limits"), rows of
  // one job (also under "limits"), and how long a finished job's rows are kept.
  size_t maxJobs = 8;
  size_t maxJobRows = 20000;
  int jobRetentionSeconds = 3600;
  // Where jobs are kept: "sqlite:PATH" or a postgresql:// URI; "" = a SQLite file in the data
  // folder (LIMN_JOB_STORE and limn serve --job-store override it). A claimed row group's lease
  // lasts jobLeaseSeconds, renewed every third of it while its replica lives.
  std::string jobStore;
  int jobLeaseSeconds = 30;
};

// A configuration file that cannot be used; the message names the file and the key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Keys left out keep their defaults. Throws ConfigError.
ServiceConfig loadConfig(const std::string& path);
// The same from JSON text; `source` names it in messages.
ServiceConfig parseConfig(std::string_view json, const std::string& source = "config");

}  // namespace limn::api
