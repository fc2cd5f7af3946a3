// RenderJob -> RenderResult: one request's whole path through the engine, as a straight line:
// surface = build(mesh); approx = method(surface, camera); images = raster(approx, camera);
// reference = oracle(surface, camera); metrics = compare(images, reference) + geometry.
// The api layer builds RenderJobs from JSON and writes RenderResults back; nothing here knows
// about either.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/core/background.h"
#include "render/core/camera.h"
#include "render/core/cancel.h"
#include "render/core/image.h"
#include "render/core/passes.h"
#include "render/implicit/polygonize.h"
#include "render/mesh/control_mesh.h"
#include "render/metrics/metrics.h"
#include "render/oracle/reference.h"
#include "render/patches/patch_set.h"
#include "render/patches/patch_tessellation.h"
#include "render/silhouette/presubdivide.h"
#include "render/silhouette/silhouette_mesh.h"
#include "render/subdiv/displacement.h"

namespace limn::render::raster {
class Rasterizer;
}
namespace limn::render::patches {
class GpuPatchTessellator;
}

namespace limn::render::pipeline {

enum class Method { Coarse, Uniform, Adaptive, Limit, Silhouette, Patches };

// Who refines for method "uniform": OpenSubdiv's Far, or limn's own rules (render/rules) by
// masks or, for Catmull-Clark, in factored form.
// Who refines a uniform mesh (tessellate.h's UniformEngine): Auto takes limn's quad path where
// limn's rules take the mesh and OpenSubdiv elsewhere.
enum class Engine { Auto, OpenSubdiv, Masks, Factored };

enum class PatchTessellator { Cpu, Gpu };

struct MethodParams {
  int level = 3;                 // uniform
  Engine engine = Engine::Auto;  // uniform
  bool pushToLimit = false;      // uniform: move every refined vertex to its limit position
  double dicingRate = 1.0;       // adaptive, patches: target edge length in pixels
  int isolation = patches::kDefaultIsolation;  // patches: Far's adaptive isolation level
  bool cullPatches = true;  // patches: leave out patches outside the view or facing away
  // patches: who dices the patches, the CPU (welded, shared edge vertices) or the GPU's
  // tessellation stages (the same factors; llvmpipe where there is no GPU).
  PatchTessellator tessellator = PatchTessellator::Cpu;
  // patches with frames: dice every frame anew (its own factors and culling) rather than
  // re-evaluate the first frame's tessellation at each frame's points.
  bool retessellateFrames = false;
  int metricSupersample = 4;  // S for the silhouette metrics
  // Also ray-cast Embree's own subdivision geometry and report its agreement with the reference
  // (Catmull-Clark only; costs about as much as the reference itself).
  bool referenceCrossCheck = false;
  // silhouette
  silhouette::Presubdivide presubdivide = silhouette::Presubdivide::Auto;
  int searchSteps = 5;    // bisection steps of the edge search
  int curveSamples = 32;  // samples per contour curve at most
  silhouette::CurveMode contour = silhouette::CurveMode::Exact;
};

struct Outputs {
  bool color = true, mask = false, depth = false, normal = false, wireframe = false;
  bool contours = false;  // silhouette: contour curves, corrected faces, searched edges
  bool cage = false;      // the control mesh's edges drawn over the colour image
  bool diff = false;      // a heat map of the colour difference against the reference
  bool patches = false;   // patches: each pixel coloured by its patch's level and kind
  // Samples per pixel of the colour-like outputs (colour, wireframe, contours, cage, patches,
  // and the reference's colour at the same sample positions): 1, 4, 8 or 16. Masks, depth and
  // normals, and so every metric but the colour difference, are one sample per pixel either way.
  int antialias = kDefaultAntialias;
  static constexpr int kDefaultAntialias = 4;
  // Where the colour-like outputs are not covered (background.h): transparent by default.
  Background background{};

  // How many images are asked for.
  int count() const {
    return color + mask + depth + normal + wireframe + contours + cage + diff + patches;
  }
};

// Limits on what one job may consume; the api layer checks requests against the same values.
struct JobLimits {
  mesh::MeshLimits mesh;
  int maxImageSide = 4096;
  int maxSupersample = 8;
  // Samples of one supersampled metrics mask (width x height x S^2; 4 bytes each, two masks):
  // 16384^2 by default, i.e. 4096^2 at S = 4 or 2048^2 at S = 8.
  size_t maxSupersampledPixels = size_t{1} << 28;
  int maxLevel = 6;
  int maxIsolation = patches::kMaxIsolation;
  double minDicingRate = 0.25;
  int maxSearchSteps = 30;
  int maxCurveSamples = 256;
  size_t maxTriangles = 8'000'000;
  // Triangles the exact reference's dense tessellation aims to stay within (about 100 bytes
  // each with its BVH); past it the reference coarsens away from outlines, then raises its
  // outline chord error and says so (ReferenceStats::accuracyPx).
  size_t maxReferenceTriangles = 3'000'000;
  // Implicit fields (runImplicit): primitives per field, polygonizer.resolution, characters of a
  // custom expression (its cost per evaluation is linear in its length).
  int maxPrimitives = 64;
  int maxResolution = 512;
  size_t maxExpressionLength = 256;
  // Rows of one comparison (methods x cameras): each camera holds every method's images at
  // once (about 100 MB per method at 1024^2, S = 4) until its reference is built.
  size_t maxCompareRows = 64;
  // Animation frames of one request, and their image pixels (frames x width x height x
  // requested outputs): each frame holds its images until the answer is written.
  size_t maxFrames = 120;
  size_t maxFramePixels = size_t{1} << 24;
  // Resident memory of one render worker process (the server's process isolation; the engine
  // does not read it): past it the worker is killed and its request answered as a crash.
  // 0: sized from the machine's memory and the worker count.
  size_t maxWorkerMemoryBytes = 0;
};

struct RenderJob {
  mesh::ControlMesh mesh;
  // Moves the limit surface along its normals (the reference's too); methods adaptive and
  // patches draw it, limit ray-casts it.
  subdiv::DisplacementSpec displacement;
  CameraSpec camera;
  Method method = Method::Adaptive;
  MethodParams params;
  Shading shading = Shading::Smooth;
  Outputs outputs;
  bool reference = false;
  // Method patches: the control points of each animation frame (same topology as `mesh`);
  // empty: one image of mesh.points. The patch table is built once and re-evaluated per frame.
  std::vector<std::vector<Vec3>> frames;
};

struct Stats {
  int controlVertices = 0, controlFaces = 0;
  size_t triangles = 0, vertices = 0;
  size_t patches = 0;
  size_t referenceTriangles = 0;
  // Silhouette Hausdorff distance (output pixels) between the two reference paths
  // (dense tessellation + Newton vs. Embree's subdivision geometry); absent when not computed.
  // Quantised to 1/metricSupersample: a single differing supersampled pixel reads 1/S.
  std::optional<double> referenceCrossCheckPx;
  std::optional<double> referenceCrossCheckMeanPx;  // mean outline distance of the same pair
  // The same pair's continuous outline distances (metrics/outline.h), not quantised.
  std::optional<double> referenceCrossCheckOutlinePx, referenceCrossCheckOutlineMeanPx;
  // The silhouette method's own counts (absent for other methods).
  std::optional<silhouette::SilhouetteStats> silhouette;
  bool presubdivided = false;
  // The patches method's table and tessellation (absent for other methods).
  struct Patches {
    patches::PatchTableStats table;
    patches::TessellationStats tessellation;
    double tableMs = 0, tessellateMs = 0;
    PatchTessellator tessellator = PatchTessellator::Cpu;
    size_t gpuDraws = 0;  // the GPU path's draw calls
  };
  std::optional<Patches> patchTable;
  // Implicit jobs: what the polygoniser did and how closed its mesh is.
  struct Implicit {
    size_t primitives = 0;
    implicit::PolygonizerMethod method = implicit::PolygonizerMethod::MarchingCubes;
    implicit::PolygonizerStats polygonizer;
    implicit::MeshClosure closure;
  };
  std::optional<Implicit> implicit;
};

struct Timings {
  double parseMs = 0, surfaceMs = 0, approxMs = 0, rasterMs = 0, referenceMs = 0, metricsMs = 0,
         totalMs = 0;
  // referenceMs split by stage (when a reference was made); crossCheckMs is part of referenceMs.
  std::optional<oracle::ReferenceStats> reference;
  double crossCheckMs = 0;
  // metricsMs split by group of metrics (when an approximation was measured).
  std::optional<metrics::MetricsTimings> metricsStages;
};

struct RenderResult {
  ImageSet images;                          // the selected outputs of the method
  std::optional<ImageSet> referenceImages;  // when the job asked for the reference
  metrics::Metrics metrics;
  Stats stats;
  Timings timings;
  std::vector<std::string> warnings;
  Camera camera;  // as resolved
  // One per RenderJob::frames entry (then `images` is empty and stats are the first frame's).
  struct Frame {
    ImageSet images;
    size_t triangles = 0;
    double approxMs = 0, rasterMs = 0;
  };
  std::vector<Frame> frames;
};

// Per-thread resources a job runs with (each worker owns one).
struct RenderContext {
  raster::Rasterizer* rasterizer = nullptr;
  // Shared by all workers; null: every reference builds its own scene.
  oracle::ReferenceSceneCache* referenceCache = nullptr;
  // The patches' tessellation shaders, compiled in the rasterizer's context on first use.
  std::shared_ptr<patches::GpuPatchTessellator> gpuTessellator;
};

// Runs the job. Throws InputError for what the request got wrong and Cancelled when `cancel`
// expires. The engine checks `limits` itself rather than trusting its caller.
RenderResult run(const RenderJob& job, const JobLimits& limits, RenderContext& context,
                 const CancelToken& cancel);

// run() for a job with frames: one image set per frame, the patch table built once. Throws
// InputError for frames with another method, with the reference, over maxFrames, or of the
// wrong size.
RenderResult runFrames(const RenderJob& job, const JobLimits& limits, RenderContext& context,
                       const CancelToken& cancel);

const char* methodName(Method method);

}  // namespace limn::render::pipeline
