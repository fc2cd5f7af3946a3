// Router: what limn does with one HTTP request, with no socket in sight.
//
// The HTTP layer hands it (method, target, body) and a reply callback; the router answers the
// service endpoints at once (/healthz, /readyz, /metrics, /openapi.json), sends renders to the
// WorkerPool, and answers 404/405 JSON for everything else; access.h's rules (bearer token,
// CORS) come first. Tests call it directly.
//
//   GET  /healthz       liveness and what the workers run on
//   GET  /readyz        200 when a render would be accepted now, else 503
//   GET  /metrics       Prometheus text format
//   GET  /openapi.json  the API description
//   POST /v1/render     api::handleRender on a worker thread
//   POST /v1/silhouette api::handleSilhouette on a worker thread (same queue, limits, timeout)
//   POST /v1/meshes     api::handleMeshUpload on a worker thread, into the MeshCache
//   POST /v1/tessellate api::handleTessellate on a worker thread (the mesh, no raster)
//   POST /v1/implicit   api::handleImplicit on a worker thread (an implicit field's scene)
//   POST /v1/compare    api::handleCompare on a worker thread (methods x cameras, one job)
//   POST /v1/jobs       JobManager::create on a worker thread (a batch spec, run in the back)
//   GET, DELETE /v1/jobs/{id}   JobManager::get / cancel, at once
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
  std::string authorization = {};  // the Authorization header ("" when absent)
  std::string origin = {};         // the Origin header ("" when absent)
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

  // The HTTP layer records every answer it writes here.
  ServiceMetrics& metrics() { return metrics_; }
  RequestLog& log() { return log_; }

 private:
  api::Answer healthz() const;
  api::Answer readyz() const;
  api::Answer metricsAnswer() const;
  WorkerPool::Abandon render(std::string body, Reply reply);
  WorkerPool::Abandon silhouette(std::string body, std::string accept, Reply reply);
  WorkerPool::Abandon uploadMesh(std::string body, Reply reply);
  WorkerPool::Abandon tessellate(std::string body, std::string accept, Reply reply);
  WorkerPool::Abandon implicit(std::string body, std::string accept, Reply reply);
  WorkerPool::Abandon compare(std::string body, Reply reply);
  WorkerPool::Abandon jobs(const Request& request, Reply reply);
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
