// The parts of an answer that several endpoints share (POST /v1/render and
// POST /v1/silhouette): the resolved camera and the silhouette method's counts, written the
// same way in both. Defined in render_response.cpp.
#pragma once

#include "api/json_util.h"
#include "render/core/camera.h"
#include "render/silhouette/silhouette_mesh.h"

namespace limn::api::response {

// {"eye": [..], "target": [..], "up": [..], "fovYDeg", "projection", "orthoHeight", "width",
// "height"}
void writeCamera(json::Writer& w, const render::Camera& camera);

// The member "silhouette": {"presubdivided": .., "edgesTested": .., ...}.
void writeSilhouetteStats(json::Writer& w, const render::silhouette::SilhouetteStats& stats,
                          bool presubdivided);

}  // namespace limn::api::response
