#include "render/pipeline/drawing.h"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "render/core/error.h"
#include "render/normalmap/mapped_cage.h"
#include "render/normalmap/normal_atlas.h"
#include "render/patches/gpu_tessellation.h"
#include "render/patches/patch_image.h"
#include "render/pipeline/job_checks.h"
#include "render/pipeline/measure.h"
#include "render/pipeline/silhouette_build.h"
#include "render/raster/rasterizer.h"
#include "render/rules/refine.h"
#include "render/silhouette/contour_overlay.h"
#include "render/tessellate/cage_overlay.h"
#include "render/tessellate/tessellate.h"

namespace limn::render::pipeline {

// How much finer `adaptive` and `patches` dice the faces whose contour runs within a pixel of
// another part's (tessellate/contour_proximity.h). Measured on the realistic corpus's grazing
// slits (bench/fidelity_results.md): 1.5 left the humanoid's at 0.78 px, 2 takes every one
// under 0.25 px.
constexpr double kCrowdedContourScale = 2;

namespace {

// Normal-map shading: an atlas of the limit normals of `surface`'s faces, sized so the face
// that looks largest gets about half a texel per pixel (bilinear filtering does the rest),
// with at most 64 x 64 texels per face and 4M texels in all.
normalmap::NormalAtlas makeAtlas(const subdiv::LimitSurface& surface, const Camera& camera) {
  constexpr size_t kTexelBudget = size_t{1} << 22;
  constexpr int kMaxSide = 4096, kMaxChartTexels = 64;
  int texels = normalmap::chartTexelsForCamera(surface, camera, 0.5, kTexelBudget, kMaxSide,
                                               kMaxChartTexels);
  return normalmap::NormalAtlas(surface, texels, kMaxSide);
}

// Atlas coordinates for a mesh whose vertices each belong to one face (the silhouette mesh):
// read off the face and (u, v) its triangles record.
void mapNormals(tessellate::TriangleMesh& mesh, const normalmap::NormalAtlas& atlas) {
  mesh.texcoords.assign(mesh.positions.size(), Vec2f{});
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Vec2f& uv = mesh.cornerUVs[3 * t + k];
      mesh.texcoords[mesh.indices[3 * t + k]] =
          atlas.coordinate(mesh.triangleFaces[t], Vec2{uv.x, uv.y});
    }
  }
  mesh.normalMap = atlas.image();
}

// Whether every face of `surface` has a limit and lies on a closed piece wound outward, with no
// displacement (which may fold the surface through itself).
bool closedOutward(const subdiv::LimitSurface& surface) {
  if (surface.displaced()) return false;
  for (int f = 0; f < surface.faceCount(); ++f) {
    if (!surface.hasLimit(f) || surface.hiddenSide(f) <= 0) return false;
  }
  return true;
}

// The methods that tessellate the surface directly (all but silhouette).
tessellate::TriangleMesh tessellateMethod(const MethodChoice& choice, const JobLimits& limits,
                                          const subdiv::LimitSurface& surface, const Camera& camera,
                                          const CancelToken& cancel) {
  switch (choice.method) {
    case Method::Coarse:
      if (choice.shading == Shading::NormalMap) {
        return normalmap::mappedCage(surface, makeAtlas(surface, camera));
      }
      return tessellate::tessellateCoarse(surface);
    case Method::Uniform: {
      tessellate::UniformOptions options;
      options.level = choice.params.level;
      switch (choice.params.engine) {
        case Engine::Auto:
          options.engine = tessellate::UniformEngine::Auto;
          break;
        case Engine::OpenSubdiv:
          options.engine = tessellate::UniformEngine::OpenSubdiv;
          break;
        case Engine::Masks:
          options.engine = tessellate::UniformEngine::Masks;
          break;
        case Engine::Factored:
          options.engine = tessellate::UniformEngine::Factored;
          break;
      }
      options.pushToLimit = choice.params.pushToLimit;
      options.maxTriangles = limits.maxTriangles;
      return tessellate::tessellateUniform(surface, options);
    }
    case Method::Adaptive: {
      tessellate::AdaptiveOptions options;
      options.dicingRate = choice.params.dicingRate;
      options.maxTriangles = limits.maxTriangles;
      options.crowdedContourScale = kCrowdedContourScale;
      tessellate::TriangleMesh mesh =
          tessellate::tessellateAdaptive(surface, camera, options, cancel);
      mesh.closedOutward = closedOutward(surface);  // watertight by construction
      return mesh;
    }
    case Method::Limit:
    case Method::Silhouette:
    case Method::Patches:
      break;
  }
  throw std::logic_error(std::string("method ") + methodName(choice.method) +
                         " is not tessellated here");
}

std::string formatRate(double rate) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", rate);
  return text;
}

}  // namespace

namespace {

// The context's tessellation shaders, compiled on first use (in its rasterizer's GL context,
// made current here).
patches::GpuPatchTessellator& gpuTessellator(RenderContext* context) {
  if (context == nullptr || context->rasterizer == nullptr) {
    badParameter("params.tessellator",
                 "params.tessellator \"gpu\" dices the patches in the renderer's OpenGL context; "
                 "a mesh for download (/v1/tessellate) is made by \"cpu\"");
  }
  context->rasterizer->makeCurrent();
  if (!context->gpuTessellator) {
    context->gpuTessellator = std::make_shared<patches::GpuPatchTessellator>();
  }
  return *context->gpuTessellator;
}

patches::PatchMesh dicePatches(const patches::PatchSet& set, patches::TessellationOptions options,
                               PatchTessellator tessellator, RenderContext* context,
                               const Camera& camera, const CancelToken& cancel,
                               Stats::Patches& stats) {
  stats.tessellator = tessellator;
  if (tessellator == PatchTessellator::Cpu) {
    return patches::tessellatePatches(set, camera, options, cancel);
  }
  patches::GpuPatchTessellator& gpu = gpuTessellator(context);
  options.maxEdgeFactor = std::min(options.maxEdgeFactor, gpu.maxTessLevel());
  const patches::TessellationPlan plan =
      patches::planPatchTessellation(set, camera, options, cancel);
  patches::GpuTessellationStats gpuStats;
  patches::PatchMesh out = gpu.tessellate(set, plan, cancel, &gpuStats);
  stats.gpuDraws = gpuStats.draws;
  return out;
}

}  // namespace

patches::PatchMesh tessellatePatchSet(const patches::PatchSet& set, const MethodChoice& choice,
                                      const JobLimits& limits, const Camera& camera,
                                      RenderContext* context, const CancelToken& cancel,
                                      Approximated& out, bool keepHidden) {
  Stopwatch clock;
  Stats::Patches stats{.table = set.stats(), .tessellation = {}, .tableMs = set.stats().buildMs};
  patches::TessellationOptions options;
  options.dicingRate = choice.params.dicingRate;
  options.cullHidden = choice.params.cullPatches && !keepHidden;
  options.maxTriangles = limits.maxTriangles;
  // At 1 px and 1024^2 a coarse Loop mesh would ask for 10M+ triangles (adaptive caps its
  // faces' edges at 128 segments instead): the rate is coarsened to fit, and said.
  options.fitToBudget = true;
  options.crowdedContourScale = kCrowdedContourScale;
  patches::PatchMesh tessellation =
      dicePatches(set, options, choice.params.tessellator, context, camera, cancel, stats);
  if (tessellation.stats.dicingRate > options.dicingRate) {
    out.warnings.push_back("params.dicingRate raised from " + formatRate(options.dicingRate) +
                           " to " + formatRate(tessellation.stats.dicingRate) +
                           " px to stay within maxTriangles (" +
                           std::to_string(limits.maxTriangles) + ")");
  }
  stats.tessellation = tessellation.stats;
  stats.tessellateMs = clock.lapMs();
  if (tessellation.stats.clampedEdges > 0) {
    out.warnings.push_back(std::to_string(tessellation.stats.clampedEdges) +
                           " patch edges wanted more than " +
                           std::to_string(options.maxEdgeFactor) +
                           " segments even after cutting their patches into domains");
  }
  out.stats.patchTable = stats;
  return tessellation;
}

void drawPatchMesh(patches::PatchMesh tessellation, const patches::PatchSet& set,
                   const MethodChoice& choice, Approximated& out) {
  if (choice.outputs.patches) out.patchImageMesh = patches::patchColoredMesh(tessellation, set);
  out.stats.patches = set.stats().patches;
  out.mesh = std::move(tessellation.mesh);
}

namespace {

// The patches method: Far's feature-adaptive patch table, tessellated for the camera.
void approximateWithPatches(const MethodChoice& choice, const JobLimits& limits,
                            const subdiv::LimitSurface& surface, const Camera& camera,
                            RenderContext* context, const CancelToken& cancel, Approximated& out) {
  const patches::PatchSet set(choice.mesh, choice.params.isolation, cancel,
                              surface.displacementSpec());
  drawPatchMesh(tessellatePatchSet(set, choice, limits, camera, context, cancel, out), set, choice,
                out);
}

}  // namespace

Approximated approximateMethod(const MethodChoice& choice, const JobLimits& limits,
                               const subdiv::LimitSurface& surface, const Camera& camera,
                               RenderContext* context, const CancelToken& cancel) {
  Stopwatch clock;
  Approximated out;
  if (choice.method == Method::Silhouette) {
    const MethodParams& p = choice.params;
    SilhouetteBuild build =
        buildSilhouette(surface, camera, {p.presubdivide, p.searchSteps, p.curveSamples, p.contour},
                        limits.maxTriangles, cancel, out.warnings);
    out.presubdivided = std::move(build.presubdivided);
    out.stats.presubdivided = out.presubdivided != nullptr;
    out.stats.silhouette = build.built.stats;
    if (choice.outputs.contours) {
      out.overlays.push_back(
          silhouette::contourOverlay(out.drawnOn(surface), build.built, pass::kContours));
    }
    out.mesh = std::move(build.built.mesh);
  } else if (choice.method == Method::Patches) {
    approximateWithPatches(choice, limits, surface, camera, context, cancel, out);
  } else {
    out.mesh = tessellateMethod(choice, limits, surface, camera, cancel);
  }
  if (choice.outputs.cage) {
    out.overlays.push_back(tessellate::cageOverlay(choice.mesh, pass::kCage));  // the client's
  }
  out.stats.triangles = out.mesh.triangleCount();
  out.stats.vertices = out.mesh.vertexCount();
  out.approxMs = clock.lapMs();
  return out;
}

MethodDrawing drawMethod(const MethodChoice& choice, const JobLimits& limits,
                         const subdiv::LimitSurface& surface, const Camera& camera,
                         RenderContext& context, bool measured, int supersample,
                         const CancelToken& cancel) {
  return rasterizeApproximation(
      approximateMethod(choice, limits, surface, camera, &context, cancel), choice, surface, camera,
      context, measured, supersample, cancel);
}

MethodDrawing rasterizeApproximation(Approximated approx, const MethodChoice& choice,
                                     const subdiv::LimitSurface& surface, const Camera& camera,
                                     RenderContext& context, bool measured, int supersample,
                                     const CancelToken& cancel) {
  MethodDrawing drawing{.approx = std::move(approx), .images = {}, .rasterMs = 0};
  Stopwatch clock;
  if (choice.method == Method::Silhouette && choice.shading == Shading::NormalMap) {
    mapNormals(drawing.approx.mesh, makeAtlas(drawing.approx.drawnOn(surface), camera));
  }
  drawing.approx.approxMs += clock.lapMs();
  cancel.check();

  const Outputs& outputs = choice.outputs;
  PassSelection passes{.color = outputs.color || measured,
                       .mask = outputs.mask || measured,
                       .depth = outputs.depth || measured,
                       .normal = outputs.normal || measured,
                       .wireframe = outputs.wireframe,
                       .supersample = measured ? supersample : 0,
                       .antialias = outputs.antialias};
  if (context.rasterizer == nullptr) throw std::runtime_error("no rasterizer in this context");
  drawing.images = context.rasterizer->render(drawing.approx.mesh, camera, passes, choice.shading,
                                              drawing.approx.overlays, cancel);
  if (drawing.approx.patchImageMesh) {
    ImageSet patchImage = context.rasterizer->render(
        *drawing.approx.patchImageMesh, camera, {.color = true, .antialias = outputs.antialias},
        Shading::Smooth, {}, cancel);
    drawing.images.passes[pass::kPatches] = std::move(patchImage.passes.at(pass::kColor));
  }
  drawing.rasterMs = clock.lapMs();
  cancel.check();
  return drawing;
}

std::vector<std::array<float, 2>> colorSamples(RenderContext& context, const Outputs& outputs) {
  if (outputs.antialias <= 1 || context.rasterizer == nullptr) return {};
  return context.rasterizer->samplePositions(outputs.antialias);
}

std::optional<std::string> antialiasWarning(RenderContext& context, const Outputs& outputs) {
  if (context.rasterizer == nullptr) return std::nullopt;
  const int taken = context.rasterizer->samplesTaken(outputs.antialias);
  if (taken == outputs.antialias) return std::nullopt;
  return "antialias " + std::to_string(outputs.antialias) + " drawn with " + std::to_string(taken) +
         " samples per pixel, the most this device's OpenGL takes";
}

PassSelection referencePasses(bool measured, int supersample) {
  return {.color = true,
          .mask = true,
          .depth = true,
          .normal = true,
          .supersample = measured ? supersample : 0};
}

metrics::Metrics measureDrawing(MethodDrawing& drawing, const oracle::ReferenceResult& reference,
                                const subdiv::LimitSurface& surface, const Camera& camera,
                                int supersample, bool diff, const CancelToken& cancel,
                                metrics::MetricsTimings* timings) {
  metrics::Metrics m = measureImages(drawing.approx.mesh, drawing.images, camera, supersample,
                                     reference, surface.bounds().diagonal(), diff, cancel, timings);
  Stopwatch clock;
  // Silhouette meshes live on the pre-subdivided copy: the same limit surface, finer faces.
  m.geometry = metrics::measureGeometry(drawing.approx.mesh, drawing.approx.drawnOn(surface));
  if (timings) timings->geometryMs = clock.lapMs();
  return m;
}

void checkMethod(const MethodChoice& choice, const JobLimits& limits) {
  const MethodParams& p = choice.params;
  checkAntialias(choice.outputs);
  if (choice.shading == Shading::NormalMap && choice.method != Method::Silhouette &&
      choice.method != Method::Coarse) {
    badParameter("shading",
                 "\"normal-map\" is available with methods \"silhouette\" and "
                 "\"coarse\" (the others draw limit normals per vertex)");
  }
  if (choice.method == Method::Uniform &&
      (p.engine == Engine::Masks || p.engine == Engine::Factored)) {
    std::string whyNot = rules::unsupportedReason(
        choice.mesh, p.engine == Engine::Masks ? rules::Method::Masks : rules::Method::Factored);
    if (!whyNot.empty()) {
      const char* name = p.engine == Engine::Masks ? "\"masks\"" : "\"factored\"";
      badParameter("params.engine", std::string(name) + " cannot refine this mesh: " + whyNot);
    }
  }
  if (p.isolation < 1 || p.isolation > limits.maxIsolation) {
    badParameter("params.isolation", "must be in 1.." + std::to_string(limits.maxIsolation));
  }
  if (p.level < 0 || p.level > limits.maxLevel) {
    badParameter("params.level", "must be in 0.." + std::to_string(limits.maxLevel));
  }
  if (!(p.dicingRate >= limits.minDicingRate)) {
    badParameter("params.dicingRate", "must be >= " + std::to_string(limits.minDicingRate));
  }
  checkSilhouetteParams(p.searchSteps, p.curveSamples, limits);
  if (p.metricSupersample < 1 || p.metricSupersample > limits.maxSupersample) {
    badParameter("params.metricSupersample",
                 "must be in 1.." + std::to_string(limits.maxSupersample));
  }
}

}  // namespace limn::render::pipeline
