#include "render/pipeline/job_checks.h"

#include <cmath>
#include <optional>

#include "render/core/error.h"

namespace limn::render::pipeline {

void badParameter(const std::string& name, const std::string& message) {
  throw InputError(InputError::Kind::InvalidParameter, name, name + " " + message);
}

void checkSilhouetteParams(int searchSteps, int curveSamples, const JobLimits& limits) {
  if (searchSteps < 0 || searchSteps > limits.maxSearchSteps) {
    badParameter("params.searchSteps", "must be in 0.." + std::to_string(limits.maxSearchSteps));
  }
  if (curveSamples < 0 || curveSamples > limits.maxCurveSamples) {
    badParameter("params.curveSamples", "must be in 0.." + std::to_string(limits.maxCurveSamples));
  }
}

void checkDisplacement(const subdiv::DisplacementSpec& displacement, Method method,
                       const std::string& methodField) {
  if (!displacement.enabled()) return;
  if (!std::isfinite(displacement.amplitude) ||
      std::fabs(displacement.amplitude) > subdiv::kMaxDisplacementAmplitude) {
    badParameter("displacement.amplitude", "must be within +-" +
                                               std::to_string(subdiv::kMaxDisplacementAmplitude) +
                                               " (a fraction of the mesh's bounding-box diagonal)");
  }
  if (!(displacement.frequency > 0) || displacement.frequency > subdiv::kMaxDisplacementFrequency) {
    badParameter("displacement.frequency", "must be in (0, " +
                                               std::to_string(subdiv::kMaxDisplacementFrequency) +
                                               "] (waves along the mesh's bounding-box diagonal)");
  }
  if (method != Method::Adaptive && method != Method::Patches && method != Method::Limit) {
    badParameter(methodField, std::string("\"") + methodName(method) +
                                  "\" does not draw a displacement; the displaced surface is "
                                  "drawn by \"patches\" and \"adaptive\" (and ray-cast by "
                                  "\"limit\")");
  }
}

void checkSupersampledMasks(const CameraSpec& camera, int supersample, const JobLimits& limits) {
  const size_t samples = static_cast<size_t>(camera.width.value_or(kDefaultImageSide)) *
                         static_cast<size_t>(camera.height.value_or(kDefaultImageSide)) *
                         static_cast<size_t>(supersample) * static_cast<size_t>(supersample);
  if (samples > limits.maxSupersampledPixels) {
    throw InputError(InputError::Kind::LimitExceeded, "maxSupersampledPixels",
                     "the silhouette metrics' masks at params.metricSupersample " +
                         std::to_string(supersample) + " would have " + std::to_string(samples) +
                         " samples each: exceeds limit maxSupersampledPixels (" +
                         std::to_string(limits.maxSupersampledPixels) +
                         "); lower metricSupersample or the image size");
  }
}

void checkAntialias(const Outputs& outputs) {
  const int n = outputs.antialias;
  if (n != 1 && n != 4 && n != 8 && n != 16) {
    badParameter("antialias", "must be 1, 4, 8 or 16 samples per pixel, got " + std::to_string(n));
  }
}

void checkImageSides(const CameraSpec& camera, const JobLimits& limits) {
  for (const std::optional<int>& side : {camera.width, camera.height}) {
    if (side && (*side < 1 || *side > limits.maxImageSide)) {
      throw InputError(InputError::Kind::LimitExceeded, "maxImageSide",
                       "image side " + std::to_string(*side) + " exceeds limit maxImageSide " +
                           std::to_string(limits.maxImageSide));
    }
  }
}

}  // namespace limn::render::pipeline
