#include "render/pipeline/silhouette_build.h"

#include "render/core/error.h"

namespace limn::render::pipeline {

SilhouetteBuild buildSilhouette(const subdiv::LimitSurface& surface, const Camera& camera,
                                const SilhouetteParams& params, size_t maxTriangles,
                                const CancelToken& cancel, std::vector<std::string>& warnings) {
  using silhouette::Presubdivide;
  const mesh::ControlMesh& mesh = surface.mesh();
  bool refine = params.presubdivide == Presubdivide::Once;
  if (params.presubdivide == Presubdivide::Auto) {
    refine = !silhouette::presubdivisionReason(mesh).empty();
  }
  SilhouetteBuild out;
  if (refine) {
    try {
      out.presubdivided =
          std::make_unique<subdiv::LimitSurface>(silhouette::refineOnce(mesh), cancel);
      out.presubdivided->prepare(cancel);
      out.presubdivisionLevels = 1;
      while (params.presubdivide == Presubdivide::Auto &&
             out.presubdivisionLevels < silhouette::kMaxPresubdivisionLevels &&
             out.presubdivided->faceCount() < silhouette::kAutoFaceLimit &&
             silhouette::chordDeviationPx(*out.presubdivided, camera) >
                 silhouette::kMaxChordDeviationPx) {
        out.presubdivided = std::make_unique<subdiv::LimitSurface>(
            silhouette::refineOnce(out.presubdivided->mesh()), cancel);
        out.presubdivided->prepare(cancel);
        ++out.presubdivisionLevels;
      }
    } catch (const InputError& e) {
      // A safety net: if OpenSubdiv refuses the refined topology (interior valence-2 vertices
      // that refining non-manifold meshes makes no longer are refused), draw the mesh unrefined.
      warnings.push_back((out.presubdivisionLevels == 0
                              ? std::string("pre-subdivision skipped: ")
                              : "pre-subdivision stopped after " +
                                    std::to_string(out.presubdivisionLevels) + " levels: ") +
                         e.what());
    }
  }

  silhouette::SilhouetteOptions options;
  options.search.searchSteps = params.searchSteps;
  options.search.outlineSamples = params.curveSamples;
  options.curves.curveSamples = params.curveSamples;
  options.curves.mode = params.contour;
  options.maxTriangles = maxTriangles;
  out.built = silhouette::buildSilhouetteMesh(out.drawn(surface), camera, options, cancel);
  out.built.stats.presubdivisionLevels = out.presubdivisionLevels;

  const silhouette::SilhouetteStats& stats = out.built.stats;
  if (stats.oddFaces > 0) {
    warnings.push_back(std::to_string(stats.oddFaces) +
                       " faces had an odd number of contour crossings and were drawn "
                       "without a contour curve");
  }
  if (stats.unresolvedSamples > 0) {
    warnings.push_back(std::to_string(stats.unresolvedSamples) +
                       " exact contour samples found no root and stayed on the chord");
  }
  return out;
}

}  // namespace limn::render::pipeline
