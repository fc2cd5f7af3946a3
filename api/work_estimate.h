// estimateWork: how much a request asks of a render worker, read from its JSON before it is
// queued — what the scheduler (server/scheduler.h) needs to put it in a lane and to say how long
// a queue will take to drain. It reads only sizes (image, supersampling, frames, rows, level or
// dicing rate, the mesh's face count, the implicit grid): cheap next to the request itself, and
// never an error (a request the engine will refuse still gets an estimate; the worker refuses
// it). A body larger than kMaxReadBytes is not read at all: a mesh that large costs seconds to
// parse and refine whatever else the request says.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace limn::api {

struct WorkSize {
  double pixels = 0;           // output pixels over every camera and frame
  double referencePixels = 0;  // pixels x metricSupersample^2 with a reference, else 0
  double triangles = 0;        // the approximations' triangles, over every row and frame
  double controlFaces = 0;
  double implicitCells = 0;  // resolution^3 of /v1/implicit
  // The raster cost of an output pixel relative to one sample: multisampling ("antialias" above
  // 1, 4 by default) costs llvmpipe 2-3x (bench/antialias_results.md).
  double samplesCost = 1;
  bool unread = false;  // the body was too large to read: count it as heavy
};

inline constexpr size_t kMaxReadBytes = 256 * 1024;

// `path` is the endpoint ("/v1/render", "/v1/compare", ...); `facesOfMesh` answers the face
// count of an uploaded mesh by id (-1 when unknown).
WorkSize estimateWork(std::string_view path, std::string_view body,
                      const std::function<int(const std::string&)>& facesOfMesh);

// The work in seconds of this machine's reference speed (a 2-core llvmpipe machine): a fixed
// weight per pixel, reference sample, triangle and implicit cell, measured there
// (bench/load_results.md, "Lanes"). The scheduler corrects it by the times it measures.
double referenceSeconds(const WorkSize& work);

}  // namespace limn::api
