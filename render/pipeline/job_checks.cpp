#include "render/pipeline/job_checks.h"

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
