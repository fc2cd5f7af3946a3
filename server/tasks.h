// Task: one unit of engine work a request asks for — an endpoint's name and the request as it
// came — and runTask(), which runs it through that endpoint's api handler. The server's worker
// pool runs tasks on its worker threads or sends them to its worker processes; `limn render`
// runs one in its own process. A task is plain data so that it can cross a process boundary.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "api/answer.h"
#include "render/core/cancel.h"
#include "render/mesh/mesh_cache.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"

namespace limn::server {

// ImportMesh: POST /v1/meshes' reading of the mesh (api::handleMeshImport); the server keeps
// what it answers (api::storeImportedMesh).
enum class Endpoint : uint8_t { Render, Silhouette, Tessellate, Implicit, Compare, ImportMesh };

struct Task {
  Endpoint endpoint = Endpoint::Render;
  std::string body;
  std::string accept = {};  // the Accept header: silhouette, tessellate and implicit may answer
                            // SVG or a mesh file instead of JSON
};

// The endpoint's handler on the task. Never throws (every failure is its JSON error answer).
// `meshes` resolves the {"mesh": {"id"}} of render, silhouette, tessellate and compare bodies.
api::Answer runTask(const Task& task, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                    render::mesh::MeshCache* meshes);

// The id of the uploaded mesh a task's body refers to ({"mesh": {"id": "..."}}), if any: the
// server hands that mesh to the worker process that runs the task.
std::optional<std::string> referencedMeshId(const Task& task);

const char* endpointPath(Endpoint endpoint);

// A render worker's rasteriser: its GL context, with the shaders warmed up
// (render/raster/warm_up.h; a failed warm-up is said on stderr and the worker goes on without
// it). Throws what the Rasterizer constructor throws when no context can be made.
std::unique_ptr<render::raster::Rasterizer> startRasterizer();

// Resident memory of a process ("self" or a pid), from /proc; 0 when it cannot be read.
size_t residentBytesOf(const std::string& process);

// After a task, hands the memory the process freed back to the system (`malloc_trim`) when it
// holds more than `keepBytes` resident; below that the next task reuses it. A 1024^2
// comparison leaves about a gigabyte freed but resident in glibc's arenas, and faulting it in
// again is most of a request's time in a VM: the pawn's adaptive tessellation took 243 ms
// after a trim against 39 ms without one (docs/engine.md, "Limits").
void trimFreedMemoryAbove(size_t keepBytes);

// What a render worker keeps resident between tasks before it trims: a quarter of its memory
// ceiling (`maxWorkerMemoryBytes`; the ceiling counts resident memory, and a kept gigabyte
// is reused, not added to, by the next task), or 1 GiB where there is no ceiling.
size_t keptWorkerMemoryBytes(size_t ceilingBytes);

// Keeps memory freed by one task in the process for the next: blocks up to 32 MiB come from the
// heap, not from their own mappings, and up to 128 MiB freed at the heap's top stays. Fresh
// pages cost dearly in a VM (about 4 ms per MB touched here): glibc's defaults gave back and
// faulted in again the megabytes of images and buffers of every small render. What a task
// leaves beyond keptWorkerMemoryBytes is returned (trimFreedMemoryAbove).
void keepFreedMemoryForReuse();

}  // namespace limn::server
