// The parts of an answer that several endpoints share (POST /v1/render, /v1/silhouette and
// /v1/compare): images, metrics, stats, the reference's stages, the resolved camera and the
// silhouette method's counts, written the same way in each. Defined in render_response.cpp.
#pragma once

#include <string>
#include <unordered_map>
#include <utility>
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

// One image of an answer: encoded, and its bytes in base64 between double quotes (a JSON string
// as it is written).
struct EncodedPass {
  std::string mime;
  int width = 0, height = 0;
  std::string quotedBase64;
};
EncodedPass encodePass(const render::Image& image, const char* passName,
                       render::image::Encoding encoding);

// The images of one answer encoded ahead of its JSON, all at once on every core: a 1024^2 PNG
// takes ~12 ms to compress, and a compared answer carries the method's and the reference's (a
// comparison one per method and camera). writeImages takes the passes it finds here.
class EncodedImages {
 public:
  struct Owned {
    const render::ImageSet* images;
    const char* owner;  // "method" or "reference"
  };
  // Every pass writeImages would write of each set for `outputs`.
  EncodedImages(const std::vector<Owned>& sets, const render::pipeline::Outputs& outputs,
                render::image::Encoding encoding);
  // The pass encoded from `image`, or null when it was not among them.
  const EncodedPass* find(const render::Image* image) const;

 private:
  std::unordered_map<const render::Image*, EncodedPass> passes_;
};

// {"color": {"mime", "width", "height", "data"}, ...}: the passes `outputs` asks for, encoded
// and in base64 (taken from `encodedAhead` when there); a requested pass `owner` ("method",
// "reference") lacks is a warning instead.
void writeImages(json::Writer& w, const render::ImageSet& images,
                 const render::pipeline::Outputs& outputs, render::image::Encoding encoding,
                 const char* owner, std::vector<std::string>& warnings,
                 const EncodedImages* encodedAhead = nullptr);

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
