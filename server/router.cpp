#include "server/router.h"

#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <cstdio>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "api/json_util.h"
#include "api/openapi.h"
#include "api/work_estimate.h"
#include "server/web_assets.h"

#ifndef LIMN_VERSION
#define LIMN_VERSION "unknown"
#endif

namespace limn::server {

// One entry of the route table: a request with this method and path goes to `handler`; a known
// path with another method is a 405 listing the methods it has.
struct Router::Route {
  std::string_view method;
  std::string_view path;  // "{id}" stands for one path segment
  Handler handler;
  Endpoint endpoint = Endpoint::Render;  // for Router::compute
};

const Router::Route Router::kRoutes[] = {
    {"GET", "/healthz", &Router::healthz},
    {"GET", "/readyz", &Router::readyz},
    {"GET", "/metrics", &Router::metricsText},
    {"GET", "/openapi.json", &Router::openApi},
    {"POST", "/v1/render", &Router::compute, Endpoint::Render},
    {"POST", "/v1/silhouette", &Router::compute, Endpoint::Silhouette},
    {"POST", "/v1/tessellate", &Router::compute, Endpoint::Tessellate},
    {"POST", "/v1/implicit", &Router::compute, Endpoint::Implicit},
    {"POST", "/v1/compare", &Router::compute, Endpoint::Compare},
    {"POST", "/v1/meshes", &Router::uploadMesh, Endpoint::ImportMesh},
    {"POST", "/v1/jobs", &Router::createJob},
    {"GET", "/v1/jobs", &Router::listJobs},
    {"GET", "/v1/jobs/{id}", &Router::getJob},
    {"DELETE", "/v1/jobs/{id}", &Router::cancelJob},
    {"GET", "/v1/jobs/{id}/results.csv", &Router::jobResults},
    {"GET", "/v1/jobs/{id}/results.jsonl", &Router::jobResults},
};

namespace {

constexpr std::string_view kJobPrefix = "/v1/jobs/";

// The path as the route table names it: /v1/jobs/<id> is "/v1/jobs/{id}", and
// /v1/jobs/<id>/results.csv is "/v1/jobs/{id}/results.csv".
std::string_view routePath(std::string_view path) {
  if (path.size() <= kJobPrefix.size() || path.substr(0, kJobPrefix.size()) != kJobPrefix) {
    return path;
  }
  const size_t slash = path.find('/', kJobPrefix.size());
  if (slash == std::string_view::npos) return "/v1/jobs/{id}";
  const std::string_view rest = path.substr(slash);
  if (rest == "/results.csv") return "/v1/jobs/{id}/results.csv";
  if (rest == "/results.jsonl") return "/v1/jobs/{id}/results.jsonl";
  return path;
}

// A query parameter's value ("" when absent).
std::string queryParameter(std::string_view target, std::string_view name) {
  const size_t query = target.find('?');
  if (query == std::string_view::npos) return "";
  std::string_view rest = target.substr(query + 1);
  while (!rest.empty()) {
    const std::string_view pair = rest.substr(0, rest.find('&'));
    if (pair.size() > name.size() && pair.substr(0, name.size()) == name &&
        pair[name.size()] == '=') {
      return std::string(pair.substr(name.size() + 1));
    }
    if (pair.size() == rest.size()) break;
    rest.remove_prefix(pair.size() + 1);
  }
  return "";
}

// A whole-number query parameter, `fallback` when absent or not a number, at most `most`.
size_t numberParameter(std::string_view target, std::string_view name, size_t fallback,
                       size_t most) {
  const std::string text = queryParameter(target, name);
  if (text.empty()) return fallback;
  size_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return fallback;
    value = std::min(value * 10 + static_cast<size_t>(c - '0'), most);
  }
  return value;
}

api::Answer jsonAnswer(int status, std::string body) {
  api::Answer answer;
  answer.status = status;
  answer.body = std::move(body);
  return answer;
}

// Answers at once; the handlers that do have no job to abandon.
WorkerPool::Abandon answerNow(Router::Reply& reply, api::Answer answer) {
  reply(std::move(answer));
  return {};
}

// The answer of the /v1/jobs routes on a server made without a job manager (tests).
api::Answer noJobs(const Request& request) {
  const std::string path(pathOf(request.target));
  return api::errorAnswer(
      {404, "not_found", "this server runs no jobs", api::json::detailObject({{"path", path}})});
}

std::string jobId(const Request& request) {
  std::string_view rest = pathOf(request.target).substr(kJobPrefix.size());
  return std::string(rest.substr(0, rest.find('/')));
}

}  // namespace

std::string_view pathOf(std::string_view target) {
  return target.substr(0, target.find_first_of("?#"));
}

std::string Router::routeLabel(std::string_view target) {
  std::string_view path = routePath(pathOf(target));
  for (const Route& route : kRoutes) {
    if (path == route.path) return std::string(path);
  }
  if (findWebAsset(path)) return std::string(path);  // a fixed set: the files built in
  return "other";
}

Router::Router(const render::pipeline::JobLimits& limits, WorkerPool& pool, ServiceMetrics& metrics,
               AccessOptions access, const std::string& logLevel, render::mesh::MeshCache* meshes,
               JobManager* jobs)
    : limits_(limits),
      pool_(pool),
      metrics_(metrics),
      meshes_(meshes),
      jobs_(jobs),
      access_(std::move(access)),
      log_(logLevel),
      started_(std::chrono::steady_clock::now()) {}

WorkerPool::Abandon Router::handle(Request request, Reply reply) {
  if (access_.originAllowed(request.origin)) {
    // Every answer to this origin, now or from a worker later, carries the CORS headers.
    reply = [origin = request.origin, reply = std::move(reply)](api::Answer answer) {
      addCorsHeaders(origin, answer);
      reply(std::move(answer));
    };
  }
  std::string_view path = pathOf(request.target);
  if (request.method == "OPTIONS" && routeLabel(path) != "other") {
    if (auto preflight = access_.preflight(request.origin)) return answerNow(reply, *preflight);
  }
  if (auto refusal = access_.refuse(path, request.authorization)) {
    return answerNow(reply, std::move(*refusal));
  }
  return route(std::move(request), std::move(reply));
}

WorkerPool::Abandon Router::route(Request request, Reply reply) {
  const std::string_view path = pathOf(request.target);
  const std::string_view routed = routePath(path);
  std::string allow;
  for (const Route& route : kRoutes) {
    if (route.path != routed) continue;
    if (route.method == request.method) return (this->*route.handler)(route, request, reply);
    allow += (allow.empty() ? "" : ", ") + std::string(route.method);
  }
  const EmbeddedFile* asset = findWebAsset(path);
  if (asset && request.method == "GET") return answerNow(reply, webAsset(*asset));
  if (asset) allow = "GET";
  if (allow.empty()) {
    return answerNow(reply,
                     api::errorAnswer({404, "not_found", "no such endpoint: " + std::string(path),
                                       api::json::detailObject({{"path", std::string(path)}})}));
  }
  api::Answer answer = api::errorAnswer(
      {405, "method_not_allowed",
       request.method + " is not allowed on " + std::string(path) + "; use " + allow,
       api::json::detailObject({{"allow", allow}})});
  answer.headers.emplace_back("Allow", allow);
  return answerNow(reply, std::move(answer));
}

// The page and the examples: small and built in, answered on the IO thread. no-cache makes a
// browser ask again on each load, so a rebuilt server's page is never mixed with an old one.
api::Answer Router::webAsset(const EmbeddedFile& file) const {
  api::Answer answer;
  answer.contentType = file.contentType;
  answer.body = std::string(file.body());
  answer.headers.emplace_back("Cache-Control", "no-cache");
  return answer;
}

// RFC 9218's urgency: 6 and 7 are background work ("u=7", as limn batch --server sends).
bool backgroundPriority(std::string_view priority) {
  const size_t at = priority.find("u=");
  return at != std::string_view::npos && at + 2 < priority.size() &&
         (priority[at + 2] == '6' || priority[at + 2] == '7');
}

JobClass Router::classify(const Route& route, const Request& request) const {
  JobClass jobClass;
  jobClass.client = clientOf(request.authorization, request.peer);
  jobClass.batch = backgroundPriority(request.priority);
  const api::WorkSize work = api::estimateWork(
      endpointPath(route.endpoint), request.body,
      [this](const std::string& id) { return meshes_ ? meshes_->facesOf(id) : -1; });
  jobClass.referenceSeconds = api::referenceSeconds(work);
  return jobClass;
}

WorkerPool::Abandon Router::compute(const Route& route, Request& request, Reply& reply) {
  JobClass jobClass = classify(route, request);
  return pool_.submit(Task{route.endpoint, std::move(request.body), std::move(request.accept)},
                      std::move(reply), request.id, std::move(jobClass));
}

// A mesh is read like a render's: in a worker process (Assimp's importers above all must not
// take the server down), with the same queue, limits and deadline. The worker answers the mesh in
// limn's JSON form; the server reads that back with its own reader and keeps it in its cache.
WorkerPool::Abandon Router::uploadMesh(const Route& route, Request& request, Reply& reply) {
  if (!meshes_) {
    return answerNow(reply,
                     api::errorAnswer({404, "not_found", "this server keeps no uploaded meshes",
                                       api::json::detailObject({{"path", "/v1/meshes"}})}));
  }
  std::string body;
  try {
    body = api::meshUploadBody(
        request.contentType,
        {queryParameter(request.target, "format"), queryParameter(request.target, "scheme"),
         queryParameter(request.target, "name")},
        std::move(request.body));
  } catch (const api::ApiError& error) {
    return answerNow(reply, api::errorAnswer(error));
  }
  request.body = std::move(body);
  JobClass jobClass = classify(route, request);
  return pool_.submit(
      Task{Endpoint::ImportMesh, std::move(request.body)},
      [reply = std::move(reply), limits = limits_, meshes = meshes_](api::Answer imported) {
        reply(api::storeImportedMesh(imported, limits, *meshes));
      },
      request.id, std::move(jobClass));
}

// A job's spec (its meshes) is read on a worker's thread, like an upload; its state and
// cancellation are answered at once. The rows themselves go through the pool as comparisons
// (server/jobs.h).
WorkerPool::Abandon Router::createJob(const Route&, Request& request, Reply& reply) {
  if (!jobs_) return answerNow(reply, noJobs(request));
  return pool_.submitInServer(
      [jobs = jobs_, body = std::move(request.body),
       client = clientOf(request.authorization, request.peer),
       key = std::move(request.idempotencyKey)](render::pipeline::RenderContext&,
                                                const render::CancelToken&) {
        return jobs->create(body, client, key);
      },
      std::move(reply));
}

WorkerPool::Abandon Router::getJob(const Route&, Request& request, Reply& reply) {
  if (!jobs_) return answerNow(reply, noJobs(request));
  return answerNow(reply, jobs_->get(jobId(request), numberParameter(request.target, "offset", 0,
                                                                     size_t{1} << 40)));
}

WorkerPool::Abandon Router::listJobs(const Route&, Request& request, Reply& reply) {
  if (!jobs_) return answerNow(reply, noJobs(request));
  constexpr size_t kDefaultPage = 50, kLargestPage = 500;
  return answerNow(
      reply, jobs_->list(clientOf(request.authorization, request.peer),
                         queryParameter(request.target, "after"),
                         std::max<size_t>(1, numberParameter(request.target, "limit", kDefaultPage,
                                                             kLargestPage))));
}

WorkerPool::Abandon Router::cancelJob(const Route&, Request& request, Reply& reply) {
  if (!jobs_) return answerNow(reply, noJobs(request));
  return answerNow(reply, jobs_->cancel(jobId(request)));
}

WorkerPool::Abandon Router::jobResults(const Route& route, Request& request, Reply& reply) {
  if (!jobs_) return answerNow(reply, noJobs(request));
  const bool csv = route.path.substr(route.path.size() - 4) == ".csv";
  return answerNow(reply, jobs_->results(jobId(request), csv ? "csv" : "jsonl"));
}

WorkerPool::Abandon Router::openApi(const Route&, Request&, Reply& reply) {
  return answerNow(reply, jsonAnswer(200, std::string(api::openApiDocument())));
}

WorkerPool::Abandon Router::healthz(const Route&, Request&, Reply& reply) {
  PoolSnapshot pool = pool_.snapshot();
  const std::vector<WorkerStatus> workers = pool_.workerStatus();

  // Every worker runs the same driver; report the first one that has a context, and the
  // errors of those that do not.
  const render::raster::DeviceInfo* device = nullptr;
  for (const auto& w : workers) {
    if (w.ready && !device) device = &w.device;
  }
  const bool ok = pool.readyWorkers == pool.workers && !pool.stopping;
  const double uptime =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  size_t crashes = 0;
  for (const auto& [signal, count] : pool.crashes) crashes += count;

  rapidjson::StringBuffer buffer;
  api::json::Writer out(buffer);
  auto string = [&](const char* key, std::string_view value) {
    out.Key(key);
    out.String(value.data(), static_cast<rapidjson::SizeType>(value.size()));
  };
  auto integer = [&](const char* key, int64_t value) {
    out.Key(key);
    out.Int64(value);
  };
  out.StartObject();
  string("status", ok ? "ok" : "degraded");
  string("version", LIMN_VERSION);
  string("renderer", device ? device->renderer : "");
  string("glVendor", device ? device->vendor : "");
  string("glVersion", device ? device->version : "");
  string("eglPlatform", device ? device->eglPlatform : "");
  string("workerIsolation", pool_.options().isolation == Isolation::Process ? "process" : "thread");
  integer("workers", pool.workers);
  integer("readyWorkers", pool.readyWorkers);
  integer("busyWorkers", pool.busyWorkers);
  integer("queueDepth", static_cast<int64_t>(pool.queued));
  integer("queueCapacity", static_cast<int64_t>(pool.queueCapacity));
  integer("workerStarts", static_cast<int64_t>(pool.workerStarts));
  integer("workerCrashes", static_cast<int64_t>(crashes));
  out.Key("spareWorkerReady");
  out.Bool(pool.spareReady);
  out.Key("uptimeS");
  out.Double(uptime);
  out.Key("workerStates");
  out.StartArray();
  for (const auto& w : workers) {
    out.StartObject();
    integer("pid", w.pid);
    // "starting": a replacement on its way; "failed": no GL context, or it would not start.
    string("state", w.ready ? (w.busy ? "busy" : "idle") : w.error.empty() ? "starting" : "failed");
    integer("starts", static_cast<int64_t>(w.starts));
    if (w.busy) {
      string("endpoint", w.endpoint);
      integer("requestId", static_cast<int64_t>(w.requestId));
    }
    out.EndObject();
  }
  out.EndArray();
  out.Key("errors");
  out.StartArray();
  for (const auto& w : workers) {
    if (!w.ready && !w.error.empty()) out.String(w.error.c_str());
  }
  out.EndArray();
  out.EndObject();
  return answerNow(reply, jsonAnswer(200, buffer.GetString()));
}

WorkerPool::Abandon Router::readyz(const Route&, Request&, Reply& reply) {
  PoolSnapshot pool = pool_.snapshot();
  std::string reason;
  if (pool.stopping) {
    reason = "shutting down";
  } else if (pool.readyWorkers == 0) {
    reason = "no render worker has an OpenGL context";
  } else if (pool.queued >= pool.queueCapacity) {
    reason = "render queue full";
  } else if (std::string problem = jobs_ ? jobs_->storeProblem() : ""; !problem.empty()) {
    reason = "the job store cannot be reached: " + problem;
  }
  if (reason.empty()) return answerNow(reply, jsonAnswer(200, "{\"ready\":true}"));
  return answerNow(reply, jsonAnswer(503, "{\"ready\":false,\"reason\":" +
                                              api::json::quote(reason, reason.size()) + "}"));
}

WorkerPool::Abandon Router::metricsText(const Route&, Request&, Reply& reply) {
  PoolSnapshot pool = pool_.snapshot();
  std::ostringstream out;
  out << metrics_.text();
  out << "# HELP limn_queue_depth Render jobs waiting for a worker.\n"
         "# TYPE limn_queue_depth gauge\n"
      << "limn_queue_depth " << pool.queued << "\n"
      << "# HELP limn_queue_capacity Render jobs that may wait before requests get 429.\n"
         "# TYPE limn_queue_capacity gauge\n"
      << "limn_queue_capacity " << pool.queueCapacity << "\n";
  // One sample per lane of a family.
  auto perLane = [&out](const char* name, const char* type, const char* help,
                        const std::array<size_t, kLanes>& values) {
    out << "# HELP " << name << " " << help << "\n# TYPE " << name << " " << type << "\n";
    for (size_t l = 0; l < kLanes; ++l) {
      out << name << "{lane=\"" << laneName(static_cast<Lane>(l)) << "\"} " << values[l] << "\n";
    }
  };
  perLane("limn_lane_queue_depth", "gauge", "Jobs waiting for a worker, by lane.",
          pool.queuedByLane);
  perLane("limn_lane_running", "gauge", "Jobs running on a worker, by lane.", pool.runningByLane);
  perLane("limn_admissions_total", "counter", "Jobs admitted to a lane.", pool.admitted);
  out << "# HELP limn_admission_refusals_total Jobs refused 429 at admission, by reason (busy: "
         "the queue, heavy: the heavy lane's budget, client: the client's share).\n"
         "# TYPE limn_admission_refusals_total counter\n";
  for (const char* reason : {"busy", "heavy", "client"}) {
    auto it = pool.refusals.find(reason);
    out << "limn_admission_refusals_total{reason=\"" << reason << "\"} "
        << (it == pool.refusals.end() ? 0 : it->second) << "\n";
  }
  out << "# HELP limn_cost_speed_factor This machine's run time over the reference estimate, "
         "learned from the jobs run so far.\n"
         "# TYPE limn_cost_speed_factor gauge\n"
      << "limn_cost_speed_factor " << pool.speedFactor << "\n"
      << "# HELP limn_workers Render workers, by whether they hold a GL context.\n"
         "# TYPE limn_workers gauge\n"
      << "limn_workers{state=\"ready\"} " << pool.readyWorkers << "\n"
      << "limn_workers{state=\"failed\"} " << pool.workers - pool.readyWorkers << "\n"
      << "# HELP limn_workers_busy Render workers running a job now.\n"
         "# TYPE limn_workers_busy gauge\n"
      << "limn_workers_busy " << pool.busyWorkers << "\n"
      << "# HELP limn_render_jobs_refused_total Render jobs not run to completion, by reason.\n"
         "# TYPE limn_render_jobs_refused_total counter\n"
      << "limn_render_jobs_refused_total{reason=\"busy\"} " << pool.rejectedBusy << "\n"
      << "limn_render_jobs_refused_total{reason=\"timeout\"} " << pool.timedOut << "\n"
      << "limn_render_jobs_refused_total{reason=\"shutdown\"} " << pool.cancelled << "\n"
      << "limn_render_jobs_refused_total{reason=\"abandoned\"} " << pool.abandoned << "\n"
      << "# HELP limn_worker_starts_total Render worker processes started (the first ones and "
         "their replacements).\n"
         "# TYPE limn_worker_starts_total counter\n"
      << "limn_worker_starts_total " << pool.workerStarts << "\n"
      << "# HELP limn_worker_crashes_total Render worker processes lost while running a request, "
         "by the signal that ended them (\"exit\": none), each replaced at once.\n"
         "# TYPE limn_worker_crashes_total counter\n";
  for (const auto& [signal, count] : pool.crashes) {
    out << "limn_worker_crashes_total{signal=\"" << signal << "\"} " << count << "\n";
  }
  {
    const render::oracle::ReferenceSceneCache::Counters& c = pool.referenceCache;
    out << "# HELP limn_reference_cache_lookups_total Reference scene lookups, by result.\n"
           "# TYPE limn_reference_cache_lookups_total counter\n"
        << "limn_reference_cache_lookups_total{result=\"hit\"} " << c.hits << "\n"
        << "limn_reference_cache_lookups_total{result=\"miss\"} " << c.misses << "\n"
        << "# HELP limn_reference_cache_evictions_total Reference scenes evicted to stay in "
           "bounds.\n"
           "# TYPE limn_reference_cache_evictions_total counter\n"
        << "limn_reference_cache_evictions_total " << c.evictions << "\n"
        << "# HELP limn_reference_cache_entries Reference scenes held.\n"
           "# TYPE limn_reference_cache_entries gauge\n"
        << "limn_reference_cache_entries " << c.entries << "\n"
        << "# HELP limn_reference_cache_bytes Estimated memory of the reference scenes held.\n"
           "# TYPE limn_reference_cache_bytes gauge\n"
        << "limn_reference_cache_bytes " << c.bytes << "\n"
        << "# HELP limn_reference_cache_capacity_bytes Bound on limn_reference_cache_bytes.\n"
           "# TYPE limn_reference_cache_capacity_bytes gauge\n"
        << "limn_reference_cache_capacity_bytes " << c.capacityBytes << "\n";
  }
  if (jobs_) {
    const JobManager::Counters c = jobs_->counters();
    out << "# HELP limn_job_store_up Whether the job store answered its last round trip.\n"
           "# TYPE limn_job_store_up gauge\n"
        << "limn_job_store_up " << (jobs_->storeProblem().empty() ? 1 : 0) << "\n"
        << "# HELP limn_job_groups_in_flight Job row groups this replica is computing now.\n"
           "# TYPE limn_job_groups_in_flight gauge\n"
        << "limn_job_groups_in_flight " << c.inFlight << "\n"
        << "# HELP limn_job_groups_total Job row groups this replica finished, by outcome.\n"
           "# TYPE limn_job_groups_total counter\n"
        << "limn_job_groups_total{result=\"stored\"} " << c.stored << "\n"
        << "limn_job_groups_total{result=\"retried\"} " << c.retried << "\n"
        << "limn_job_groups_total{result=\"released\"} " << c.released << "\n";
  }

  api::Answer answer;
  answer.status = 200;
  answer.contentType = "text/plain; version=0.0.4; charset=utf-8";
  answer.body = out.str();
  return answerNow(reply, std::move(answer));
}

}  // namespace limn::server
