#include "server/router.h"

#include <cstdio>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "api/compare_api.h"
#include "api/implicit_api.h"
#include "api/openapi.h"
#include "api/silhouette_api.h"
#include "server/web_assets.h"

#ifndef LIMN_VERSION
#define LIMN_VERSION "unknown"
#endif

namespace limn::server {

namespace {

struct Route {
  const char* path;
  const char* method;
};

// Every (path, method) limn answers; a known path with another method is a 405 listing these.
constexpr Route kRoutes[] = {
    {"/healthz", "GET"},         {"/readyz", "GET"},         {"/metrics", "GET"},
    {"/openapi.json", "GET"},    {"/v1/render", "POST"},     {"/v1/silhouette", "POST"},
    {"/v1/meshes", "POST"},      {"/v1/tessellate", "POST"}, {"/v1/implicit", "POST"},
    {"/v1/compare", "POST"},     {"/v1/jobs", "POST"},       {"/v1/jobs/{id}", "GET"},
    {"/v1/jobs/{id}", "DELETE"},
};

constexpr std::string_view kJobPrefix = "/v1/jobs/";

// The path as kRoutes names it: /v1/jobs/<id> is "/v1/jobs/{id}".
std::string_view routePath(std::string_view path) {
  if (path.size() > kJobPrefix.size() && path.substr(0, kJobPrefix.size()) == kJobPrefix &&
      path.find('/', kJobPrefix.size()) == std::string_view::npos) {
    return "/v1/jobs/{id}";
  }
  return path;
}

// "offset" of a query string ("?offset=20"), 0 when absent or not a number.
size_t offsetParameter(std::string_view target) {
  const size_t query = target.find('?');
  if (query == std::string_view::npos) return 0;
  std::string_view rest = target.substr(query + 1);
  const size_t at = rest.find("offset=");
  if (at == std::string_view::npos || (at > 0 && rest[at - 1] != '&')) return 0;
  size_t value = 0;
  for (char c : rest.substr(at + 7)) {
    if (c < '0' || c > '9') break;
    value = value * 10 + static_cast<size_t>(c - '0');
    if (value > (size_t{1} << 40)) break;
  }
  return value;
}

// The few JSON strings the service endpoints write (renderer names, error texts) go through
// this; the request and response documents themselves belong to api/.
std::string jsonString(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

api::Answer jsonAnswer(int status, std::string body) {
  api::Answer answer;
  answer.status = status;
  answer.body = std::move(body);
  return answer;
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
    if (auto preflight = access_.preflight(request.origin)) {
      reply(std::move(*preflight));
      return {};
    }
  }
  if (auto refusal = access_.refuse(path, request.authorization)) {
    reply(std::move(*refusal));
    return {};
  }
  return route(std::move(request), std::move(reply));
}

WorkerPool::Abandon Router::route(Request request, Reply reply) {
  const std::string target = request.target;
  std::string_view path = pathOf(target);
  std::vector<std::string> allowed;
  for (const Route& route : kRoutes) {
    if (routePath(path) == route.path) allowed.emplace_back(route.method);
  }
  const EmbeddedFile* asset = findWebAsset(path);
  if (asset) allowed.emplace_back("GET");
  if (allowed.empty()) {
    reply(api::errorAnswer({404, "not_found", "no such endpoint: " + std::string(path),
                            "{\"path\":" + jsonString(path) + "}"}));
    return {};
  }
  bool methodAllowed = false;
  for (const auto& m : allowed) methodAllowed = methodAllowed || m == request.method;
  if (!methodAllowed) {
    std::string allow;
    for (const auto& m : allowed) allow += (allow.empty() ? "" : ", ") + m;
    api::Answer answer = api::errorAnswer(
        {405, "method_not_allowed",
         request.method + " is not allowed on " + std::string(path) + "; use " + allow,
         "{\"allow\":" + jsonString(allow) + "}"});
    answer.headers.emplace_back("Allow", allow);
    reply(std::move(answer));
    return {};
  }

  std::optional<api::Answer> now;
  if (asset) now = webAsset(*asset);
  if (path == "/healthz") now = healthz();
  if (path == "/readyz") now = readyz();
  if (path == "/metrics") now = metricsAnswer();
  if (path == "/openapi.json") now = jsonAnswer(200, std::string(api::openApiDocument()));
  if (now) {
    reply(std::move(*now));
    return {};
  }
  if (path == "/v1/silhouette") {
    return silhouette(std::move(request.body), std::move(request.accept), std::move(reply));
  }
  if (path == "/v1/meshes") return uploadMesh(std::move(request.body), std::move(reply));
  if (path == "/v1/compare") return compare(std::move(request.body), std::move(reply));
  if (routePath(path) != path || path == "/v1/jobs") return jobs(request, std::move(reply));
  if (path == "/v1/tessellate") {
    return tessellate(std::move(request.body), std::move(request.accept), std::move(reply));
  }
  if (path == "/v1/implicit") {
    return implicit(std::move(request.body), std::move(request.accept), std::move(reply));
  }
  return render(std::move(request.body), std::move(reply));
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

// Parsing a large mesh takes a while: it runs on a worker like a render (same queue, limits and
// deadline), though it needs no GL context.
WorkerPool::Abandon Router::uploadMesh(std::string body, Reply reply) {
  if (!meshes_) {
    reply(api::errorAnswer(
        {404, "not_found", "this server keeps no uploaded meshes", "{\"path\":\"/v1/meshes\"}"}));
    return {};
  }
  return pool_.submit(
      [body = std::move(body), limits = limits_, meshes = meshes_](render::pipeline::RenderContext&,
                                                                   const render::CancelToken&) {
        return api::handleMeshUpload(body, limits, *meshes);
      },
      std::move(reply));
}

// The approximation's mesh for a client that draws it itself: the method's work without the
// raster, on the same workers.
WorkerPool::Abandon Router::tessellate(std::string body, std::string accept, Reply reply) {
  return pool_.submit(
      [body = std::move(body), accept = std::move(accept), limits = limits_, meshes = meshes_](
          render::pipeline::RenderContext&, const render::CancelToken& cancel) {
        return api::handleTessellate(body, accept, limits, cancel, meshes);
      },
      std::move(reply));
}

WorkerPool::Abandon Router::render(std::string body, Reply reply) {
  return pool_.submit(
      [body = std::move(body), limits = limits_, meshes = meshes_](
          render::pipeline::RenderContext& context, const render::CancelToken& cancel) {
        return api::handleRender(body, limits, context, cancel, meshes);
      },
      std::move(reply));
}

// Implicit scenes: polygonised, drawn and measured on the same workers as meshes.
WorkerPool::Abandon Router::implicit(std::string body, std::string accept, Reply reply) {
  return pool_.submit(
      [body = std::move(body), accept = std::move(accept), limits = limits_](
          render::pipeline::RenderContext& context, const render::CancelToken& cancel) {
        return api::handleImplicit(body, accept, limits, context, cancel);
      },
      std::move(reply));
}

// Several methods against one reference per camera: one job on one worker (the request's
// deadline covers all of its rows).
WorkerPool::Abandon Router::compare(std::string body, Reply reply) {
  return pool_.submit(
      [body = std::move(body), limits = limits_, meshes = meshes_](
          render::pipeline::RenderContext& context, const render::CancelToken& cancel) {
        return api::handleCompare(body, limits, context, cancel, meshes);
      },
      std::move(reply));
}

// A job's spec (its meshes) is read on a worker, like an upload; its state and cancellation are
// answered at once. The rows themselves go through the pool as comparisons (server/jobs.h).
WorkerPool::Abandon Router::jobs(const Request& request, Reply reply) {
  std::string_view path = pathOf(request.target);
  if (!jobs_) {
    reply(api::errorAnswer(
        {404, "not_found", "this server runs no jobs", "{\"path\":" + jsonString(path) + "}"}));
    return {};
  }
  if (path == "/v1/jobs") {
    return pool_.submit([jobs = jobs_, body = request.body](
                            render::pipeline::RenderContext&,
                            const render::CancelToken&) { return jobs->create(body); },
                        std::move(reply));
  }
  const std::string id(path.substr(kJobPrefix.size()));
  reply(request.method == "DELETE" ? jobs_->cancel(id)
                                   : jobs_->get(id, offsetParameter(request.target)));
  return {};
}

// Contours need no GL context, but share the render workers: one queue, one set of limits and
// deadlines for everything that computes.
WorkerPool::Abandon Router::silhouette(std::string body, std::string accept, Reply reply) {
  return pool_.submit(
      [body = std::move(body), accept = std::move(accept), limits = limits_, meshes = meshes_](
          render::pipeline::RenderContext&, const render::CancelToken& cancel) {
        return api::handleSilhouette(body, accept, limits, cancel, meshes);
      },
      std::move(reply));
}

api::Answer Router::healthz() const {
  PoolSnapshot pool = pool_.snapshot();
  const auto& workers = pool_.workerStatus();

  // Every worker runs the same driver; report the first one that has a context, and the
  // errors of those that do not.
  const render::raster::DeviceInfo* device = nullptr;
  std::string errors;
  for (const auto& w : workers) {
    if (w.ready && !device) device = &w.device;
    if (!w.ready) errors += (errors.empty() ? "" : ",") + jsonString(w.error);
  }
  bool ok = pool.readyWorkers == pool.workers && !pool.stopping;
  double uptime =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();

  std::ostringstream out;
  out << "{\"status\":" << jsonString(ok ? "ok" : "degraded")
      << ",\"version\":" << jsonString(LIMN_VERSION)
      << ",\"renderer\":" << jsonString(device ? device->renderer : "")
      << ",\"glVendor\":" << jsonString(device ? device->vendor : "")
      << ",\"glVersion\":" << jsonString(device ? device->version : "")
      << ",\"eglPlatform\":" << jsonString(device ? device->eglPlatform : "")
      << ",\"workers\":" << pool.workers << ",\"readyWorkers\":" << pool.readyWorkers
      << ",\"busyWorkers\":" << pool.busyWorkers << ",\"queueDepth\":" << pool.queued
      << ",\"queueCapacity\":" << pool.queueCapacity << ",\"uptimeS\":" << uptime << ",\"errors\":["
      << errors << "]}";
  return jsonAnswer(200, out.str());
}

api::Answer Router::readyz() const {
  PoolSnapshot pool = pool_.snapshot();
  std::string reason;
  if (pool.stopping) {
    reason = "shutting down";
  } else if (pool.readyWorkers == 0) {
    reason = "no render worker has an OpenGL context";
  } else if (pool.queued >= pool.queueCapacity) {
    reason = "render queue full";
  }
  if (reason.empty()) return jsonAnswer(200, "{\"ready\":true}");
  return jsonAnswer(503, "{\"ready\":false,\"reason\":" + jsonString(reason) + "}");
}

api::Answer Router::metricsAnswer() const {
  PoolSnapshot pool = pool_.snapshot();
  std::ostringstream out;
  out << metrics_.text();
  out << "# HELP limn_queue_depth Render jobs waiting for a worker.\n"
         "# TYPE limn_queue_depth gauge\n"
      << "limn_queue_depth " << pool.queued << "\n"
      << "# HELP limn_queue_capacity Render jobs that may wait before requests get 429.\n"
         "# TYPE limn_queue_capacity gauge\n"
      << "limn_queue_capacity " << pool.queueCapacity << "\n"
      << "# HELP limn_workers Render worker threads, by whether they hold a GL context.\n"
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
      << "limn_render_jobs_refused_total{reason=\"abandoned\"} " << pool.abandoned << "\n";
  if (const render::oracle::ReferenceSceneCache* cache = pool_.options().referenceCache) {
    render::oracle::ReferenceSceneCache::Counters c = cache->counters();
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

  api::Answer answer;
  answer.status = 200;
  answer.contentType = "text/plain; version=0.0.4; charset=utf-8";
  answer.body = out.str();
  return answer;
}

}  // namespace limn::server
