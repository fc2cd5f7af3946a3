// Router: what limn does with one HTTP request, with no socket in sight.
//
// The HTTP layer hands it (method, target, body) and a reply callback; the router finds the
// request's entry in one route table (router.cpp: {method, path, handler}), answers the service
// endpoints at once (/healthz, /readyz, /metrics, /openapi.json), sends the computing ones to
// the WorkerPool as Tasks (server/tasks.h), and answers 404/405 JSON for everything else;
// access.h's rules (bearer token, CORS) come first. Tests call it directly.
//
//   GET  /healthz       liveness, what the workers run on, each worker's state
//   GET  /readyz        200 when a render would be accepted now and the job store answers, else 503
//   GET  /metrics       Prometheus text format
//   GET  /openapi.json  the API description
//   POST /v1/render, /v1/silhouette, /v1/tessellate, /v1/implicit, /v1/compare
//                       a Task on a render worker (one queue, one set of limits and deadlines)
//   POST /v1/meshes     api::handleMeshUpload on a worker's thread in the server, into the cache
//   POST /v1/jobs       JobManager::create on a worker's thread in the server
//   GET  /v1/jobs, GET and DELETE /v1/jobs/{id}, GET /v1/jobs/{id}/results.{csv,jsonl}
//                       JobManager::list / get / cancel / results, at once (store reads)
//   GET  /, /NAME.js, /examples, /examples/NAME   the built-in page and examples (web_assets.h)
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <string_view>

#include "api/render_api.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"
#include "server/access.h"
#include "server/jobs.h"
#include "server/request_log.h"
#include "server/service_metrics.h"
#include "server/web_assets.h"
#include "server/worker_pool.h"

namespace limn::server {

struct Request {
  std::string method;  // as sent: "GET", "POST", ...
  std::string target;  // path, possibly with "?query"
  std::string body;
  std::string accept = {};  // the Accept header ("" when absent): /v1/silhouette may answer SVG
  std::string authorization = {};   // the Authorization header ("" when absent)
  std::string origin = {};          // the Origin header ("" when absent)
  uint64_t id = 0;                  // the X-Request-Id its answer will carry
  std::string idempotencyKey = {};  // the Idempotency-Key header ("" when absent): POST /v1/jobs
  std::string peer = {};            // the client's address ("" in tests without a socket)
  std::string priority = {};        // the Priority header (RFC 9218): "u=6" or "u=7" is batch
  std::string contentType = {};     // the Content-Type header: POST /v1/meshes takes mesh files
};

class Router {
 public:
  using Reply = std::function<void(api::Answer)>;

  // `metrics` (shared with the pool, which records its jobs there) must outlive the router.
  // `meshes` (owned by the caller, may be null: no uploads) holds POST /v1/meshes' meshes;
  // `jobs` (the same; null: no /v1/jobs) runs POST /v1/jobs.
  Router(const render::pipeline::JobLimits& limits, WorkerPool& pool, ServiceMetrics& metrics,
         AccessOptions access = {}, const std::string& logLevel = "info",
         render::mesh::MeshCache* meshes = nullptr, JobManager* jobs = nullptr);

  // Calls `reply` exactly once: before returning for everything but renders, from a worker or
  // the pool's watchdog for renders. For work that went to the pool, returns the handle that
  // cancels it when the client goes away (WorkerPool::Abandon); else an empty one.
  WorkerPool::Abandon handle(Request request, Reply reply);

  // The label a request's path gets in /metrics: the path when limn serves it, else "other".
  static std::string routeLabel(std::string_view target);

  struct Route;

  // The HTTP layer records every answer it writes here.
  ServiceMetrics& metrics() { return metrics_; }
  RequestLog& log() { return log_; }

 private:
  // Every handler of the route table has this shape; those answering at once return {}.
  using Handler = WorkerPool::Abandon (Router::*)(const Route&, Request&, Reply&);
  static const Route kRoutes[];

  WorkerPool::Abandon healthz(const Route&, Request&, Reply& reply);
  WorkerPool::Abandon readyz(const Route&, Request&, Reply& reply);
  WorkerPool::Abandon metricsText(const Route&, Request&, Reply& reply);
  WorkerPool::Abandon openApi(const Route&, Request&, Reply& reply);
  // The route's Endpoint as a Task for the workers.
  WorkerPool::Abandon compute(const Route& route, Request& request, Reply& reply);
  // The request's lane and cost for the pool: its client, whether it asked to be background,
  // and its work estimated from its JSON (api/work_estimate.h).
  JobClass classify(const Route& route, const Request& request) const;
  WorkerPool::Abandon uploadMesh(const Route&, Request& request, Reply& reply);
  WorkerPool::Abandon createJob(const Route&, Request& request, Reply& reply);
  WorkerPool::Abandon getJob(const Route&, Request& request, Reply& reply);
  WorkerPool::Abandon listJobs(const Route&, Request& request, Reply& reply);
  WorkerPool::Abandon cancelJob(const Route&, Request& request, Reply& reply);
  WorkerPool::Abandon jobResults(const Route&, Request& request, Reply& reply);
  api::Answer webAsset(const EmbeddedFile& file) const;

  WorkerPool::Abandon route(Request request, Reply reply);

  render::pipeline::JobLimits limits_;
  WorkerPool& pool_;
  ServiceMetrics& metrics_;
  render::mesh::MeshCache* meshes_;
  JobManager* jobs_;
  Access access_;
  RequestLog log_;
  std::chrono::steady_clock::time_point started_;
};

// The path part of a request target ("/v1/render?x=1" -> "/v1/render").
std::string_view pathOf(std::string_view target);

}  // namespace limn::server
