// ContourJob -> ContourResult: the contour of a limit surface for one camera as polylines, each
// point marked seen or hidden (POST /v1/silhouette). One straight line through the layers:
//   surface = build(mesh); curves = silhouette method's search and curves (silhouette_build.h);
//   polylines = chain(curves); visible = rays against the reference (oracle/visibility.h);
//   pieces = runs of equal visibility.
// The api layer builds ContourJobs from JSON and writes ContourResults as JSON or SVG.
#pragma once

#include <string>
#include <vector>

#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/mesh/control_mesh.h"
#include "render/pipeline/render_job.h"
#include "render/pipeline/silhouette_build.h"
#include "render/silhouette/contour_polylines.h"

namespace limn::render::pipeline {

struct ContourJob {
  mesh::ControlMesh mesh;
  CameraSpec camera;
  SilhouetteParams params;
};

// A polyline with the visibility of each point and its pieces (see splitPieces()).
struct ContourLine {
  bool closed = false;
  std::vector<silhouette::PolylinePoint> points;
  std::vector<bool> visible;  // per point
  std::vector<silhouette::PolylinePiece> pieces;
};

struct ContourStats {
  int controlVertices = 0, controlFaces = 0;
  bool presubdivided = false;
  silhouette::SilhouetteStats silhouette;  // of the method's search and curves
  size_t polylines = 0, closedPolylines = 0, points = 0, hiddenPoints = 0;
  size_t visiblePieces = 0, hiddenPieces = 0;
  size_t referenceTriangles = 0;  // of the surface the visibility rays are cast against
  size_t raysCast = 0;
};

struct ContourTimings {
  double parseMs = 0;       // set by the api layer
  double surfaceMs = 0;     // the limit surface of the request's mesh
  double contourMs = 0;     // pre-subdivision, contour search and curves
  double chainMs = 0;       // curves joined into polylines
  double visibilityMs = 0;  // the reference tessellation, its BVH and the rays, together
  double referenceTessellateMs = 0, bvhMs = 0, raysMs = 0;  // its parts
  double totalMs = 0;
};

struct ContourResult {
  Camera camera;  // as resolved
  std::vector<ContourLine> polylines;
  ContourStats stats;
  ContourTimings timings;
  std::vector<std::string> warnings;
};

// Throws InputError for what the job got wrong (checked against `limits` here too) and
// Cancelled when `cancel` expires.
ContourResult runContours(const ContourJob& job, const JobLimits& limits,
                          const CancelToken& cancel);

}  // namespace limn::render::pipeline
