// What run() and runContours() share before they start: a stopwatch for the timings and the
// checks of request values against JobLimits (the engine checks its limits itself rather than
// trusting its caller).
#pragma once

#include <chrono>
#include <string>

#include "render/core/camera.h"
#include "render/pipeline/render_job.h"
#include "render/subdiv/displacement.h"

namespace limn::render::pipeline {

// Milliseconds since construction or the previous lap.
class Stopwatch {
 public:
  double lapMs() {
    auto now = std::chrono::steady_clock::now();
    double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Throws InputError(InvalidParameter) naming `name`.
[[noreturn]] void badParameter(const std::string& name, const std::string& message);

// params.searchSteps and params.curveSamples of the silhouette method.
void checkSilhouetteParams(int searchSteps, int curveSamples, const JobLimits& limits);

// A displacement's function, amplitude and frequency, and that `method` draws it: adaptive and
// patches evaluate the displaced surface, limit ray-casts it; the others draw the undisplaced
// control mesh or its refinement. `methodField` names the method in messages.
void checkDisplacement(const subdiv::DisplacementSpec& displacement, Method method,
                       const std::string& methodField);

// outputs.antialias: 1, 4, 8 or 16 samples per pixel.
void checkAntialias(const Outputs& outputs);

// camera.width and camera.height against maxImageSide (LimitExceeded).
void checkImageSides(const CameraSpec& camera, const JobLimits& limits);

// The supersampled masks of the silhouette metrics (width x height x S^2 floats each, two of
// them) against maxSupersampledPixels (LimitExceeded), before any is allocated.
void checkSupersampledMasks(const CameraSpec& camera, int supersample, const JobLimits& limits);

}  // namespace limn::render::pipeline
