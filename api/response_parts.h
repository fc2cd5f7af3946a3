// The parts of an answer that several endpoints share (POST /v1/render, /v1/silhouette and
// /v1/compare): images, metrics, stats, the reference's stages, the resolved camera and the
// silhouette method's counts, written the same way in each. Defined in render_response.cpp.
#pragma once

#include <string>
#include <vector>

#include "api/json_util.h"
#include "render/core/camera.h"
#include "render/core/image.h"
#include "render/image/encode.h"
#include "render/metrics/metrics.h"
#include "render/oracle/reference.h"
#include "render/pipeline/render_job.h"
#include "render/silhouette/silhouette_mesh.h"

namespace limn::api::response {

// {"eye": [..], "target": [..], "up": [..], "fovYDeg", "projection", "orthoHeight", "width",
// "height"}
void writeCamera(json::Writer& w, const render::Camera& camera);

// The member "silhouette": {"presubdivided": .., "edgesTested": .., ...}.
// {"color": {"mime", "width", "height", "data"}, ...}: the passes `outputs` asks for, encoded
// and in base64; a requested pass `owner` ("method", "reference") lacks is a warning instead.
void writeImages(json::Writer& w, const render::ImageSet& images,
                 const render::pipeline::Outputs& outputs, render::image::Encoding encoding,
                 const char* owner, std::vector<std::string>& warnings);

// {"silhouette": {...}, "image": {...}, "depth", "normal", "geometry"}: the metrics present.
void writeMetrics(json::Writer& w, const render::metrics::Metrics& metrics);

// {"controlVertices", "controlFaces", "triangles", "vertices", ...}
void writeStats(json::Writer& w, const render::pipeline::Stats& stats);

// The member "referenceStages": referenceMs by stage, rays cast, whether the scene was cached.
void writeReferenceStages(json::Writer& w, const render::oracle::ReferenceStats& stats,
                          double crossCheckMs);

void writeSilhouetteStats(json::Writer& w, const render::silhouette::SilhouetteStats& stats,
                          bool presubdivided);

}  // namespace limn::api::response
