// Seeded random cameras for the silhouette method's every-view harness (issue 10): the eye on a
// sphere of 1.5-4 bounding radii around the bounds' centre, a random up vector, a vertical field
// of view of 20-60 degrees, and one view in four orthographic (framing what the perspective
// view would frame at the target). Views are reproducible from (seed, index) alone, and
// describeCamera() prints one as the JSON camera a request takes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/core/camera.h"

namespace limn::testing {

struct RandomView {
  int index = 0;
  render::CameraSpec camera;
};

// The seed of one shape's views: `seed` mixed with the shape's name (FNV-1a), so that shapes
// are seen from different views and each stays reproducible from (seed, name).
uint64_t viewSeed(uint64_t seed, const std::string& name);

// `count` views of a surface with these bounds, `side` x `side` pixels.
std::vector<RandomView> randomViews(const render::Bounds& bounds, int count, uint64_t seed,
                                    int side);

// {"eye": [...], "target": [...], "up": [...], "fovYDeg": ..., ...}: the view as a request's
// "camera" object, numbers printed so that they parse back to the same doubles.
std::string describeCamera(const render::CameraSpec& camera);

}  // namespace limn::testing
