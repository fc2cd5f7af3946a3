// compare(): several methods against one exact reference per camera — the engine behind
// POST /v1/compare and `limn batch`.
//
// For one mesh it builds the limit surface once; for each camera it draws every method, builds
// one reference hinted with all of their masks at once (oracle::maskBlocks), and measures every
// method against it. Each row is computed by the same steps as run() with `reference: true`
// (pipeline/drawing.h), so a row equals the render of its method alone: the merged hint only
// casts more mask samples where the reference's coverage is uniform anyway (see
// oracle::ReferenceOptions). The reference's time is paid once per camera, not once per row.
//
// A method that cannot be made for this mesh or view (over maxTriangles, say) fails its own
// rows, which carry the error; the others go on. What the request got wrong (a parameter out of
// range, too many rows) throws InputError before any work, naming the field
// ("methods[2].params.level", "cameras[1]"); Cancelled when the deadline passes between stages.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/error.h"
#include "render/core/image.h"
#include "render/mesh/control_mesh.h"
#include "render/metrics/metrics.h"
#include "render/oracle/reference.h"
#include "render/pipeline/render_job.h"

namespace limn::render::pipeline {

// One method of a comparison. Its params.metricSupersample is ignored: one S serves the
// whole comparison (CompareJob::metricSupersample), since the reference is shared.
struct CompareMethod {
  Method method = Method::Adaptive;  // anything but Limit
  MethodParams params;
  Shading shading = Shading::Smooth;
};

struct CompareJob {
  mesh::ControlMesh mesh;
  subdiv::DisplacementSpec displacement;  // as RenderJob's: every method must draw it
  std::vector<CameraSpec> cameras;        // at least one
  std::vector<CompareMethod> methods;
  int metricSupersample = 4;
  Outputs outputs{.color = false};  // images of every row and reference (none by default)
  // false: every row drawn and not measured: no reference, rows without metrics (a turntable
  // of /v1/render without "reference": its frames are the rows of one method).
  bool reference = true;
};

// Why a row could not be made (an InputError of the engine, as the api layer maps them).
struct RowError {
  InputError::Kind kind;
  std::string subject, message;
};

// One method seen from one camera.
struct CompareRow {
  size_t method = 0, camera = 0;  // indices into CompareJob::methods and ::cameras
  std::optional<RowError> error;  // set: nothing else below is
  metrics::Metrics metrics;
  Stats stats;      // triangles, vertices, the silhouette method's counts
  Timings timings;  // approxMs, rasterMs, metricsMs and their sum in totalMs
  ImageSet images;  // the requested outputs
  std::vector<std::string> warnings;
};

// The reference of one camera, shared by its rows (none when CompareJob::reference is false).
struct CompareReference {
  Camera camera;  // as resolved
  oracle::ReferenceStats stats;
  double referenceMs = 0;  // its whole time, once
  ImageSet images;         // the requested outputs
  std::vector<std::string> warnings;
};

struct CompareResult {
  std::vector<CompareRow> rows;  // camera-major: every method for cameras[0], then cameras[1]...
  std::vector<CompareReference> references;  // one per camera
  int controlVertices = 0, controlFaces = 0;
  double surfaceMs = 0, totalMs = 0;
};

// Throws InputError (the request's own mistakes; see above) and Cancelled.
CompareResult compare(const CompareJob& job, const JobLimits& limits, RenderContext& context,
                      const CancelToken& cancel);

}  // namespace limn::render::pipeline
