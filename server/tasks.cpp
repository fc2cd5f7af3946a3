#include "server/tasks.h"

#include <malloc.h>
#include <unistd.h>

#include <fstream>
#include <iostream>

#include "api/compare_api.h"
#include "api/implicit_api.h"
#include "api/render_api.h"
#include "api/silhouette_api.h"
#include "render/raster/warm_up.h"

namespace limn::server {

api::Answer runTask(const Task& task, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                    render::mesh::MeshCache* meshes) {
  switch (task.endpoint) {
    case Endpoint::Render:
      return api::handleRender(task.body, limits, context, cancel, meshes, task.accept);
    case Endpoint::Silhouette:
      return api::handleSilhouette(task.body, task.accept, limits, cancel, meshes);
    case Endpoint::Tessellate:
      return api::handleTessellate(task.body, task.accept, limits, cancel, meshes);
    case Endpoint::Implicit:
      return api::handleImplicit(task.body, task.accept, limits, context, cancel);
    case Endpoint::Compare:
      return api::handleCompare(task.body, limits, context, cancel, meshes);
    case Endpoint::ImportMesh:
      return api::handleMeshImport(task.body, limits);
  }
  return api::errorAnswer({500, "internal", "unknown task endpoint"});
}

std::optional<std::string> referencedMeshId(const Task& task) {
  if (task.endpoint == Endpoint::Implicit || task.endpoint == Endpoint::ImportMesh) {
    return std::nullopt;
  }
  return api::referencedMeshId(task.body);
}

const char* endpointPath(Endpoint endpoint) {
  switch (endpoint) {
    case Endpoint::Render:
      return "/v1/render";
    case Endpoint::Silhouette:
      return "/v1/silhouette";
    case Endpoint::Tessellate:
      return "/v1/tessellate";
    case Endpoint::Implicit:
      return "/v1/implicit";
    case Endpoint::Compare:
      return "/v1/compare";
    case Endpoint::ImportMesh:
      return "/v1/meshes";
  }
  return "?";
}

size_t residentBytesOf(const std::string& process) {
  std::ifstream statm("/proc/" + process + "/statm");
  size_t pages = 0, resident = 0;
  if (!(statm >> pages >> resident)) return 0;
  return resident * static_cast<size_t>(::sysconf(_SC_PAGESIZE));
}

void trimFreedMemoryAbove(size_t keepBytes) {
  if (residentBytesOf("self") > keepBytes) ::malloc_trim(0);
}

size_t keptWorkerMemoryBytes(size_t ceilingBytes) {
  return ceilingBytes > 0 ? ceilingBytes / 4 : size_t{1} << 30;
}

void keepFreedMemoryForReuse() {
  constexpr int kHeapBlockBytes = 32 << 20;
  constexpr int kKeptAtTopBytes = 128 << 20;
  ::mallopt(M_MMAP_THRESHOLD, kHeapBlockBytes);
  ::mallopt(M_TRIM_THRESHOLD, kKeptAtTopBytes);
}

std::unique_ptr<render::raster::Rasterizer> startRasterizer() {
  auto rasterizer = std::make_unique<render::raster::Rasterizer>();
  if (!render::raster::warmUp(*rasterizer)) {
    std::cerr << "limn: a render worker's shader warm-up failed; its first requests compile "
                 "the shaders instead\n";
  }
  return rasterizer;
}

}  // namespace limn::server
