// writeTurntable: a /v1/render request with "turntable" — its views drawn as the rows of one
// comparison of the one method (render/pipeline/compare.h), so the limit surface is built once
// and each view's reference, when asked for, is made and measured as /v1/compare makes it.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "api/base64.h"
#include "api/render_api.h"
#include "api/response_parts.h"
#include "render/image/encode.h"
#include "render/metrics/metrics.h"
#include "render/pipeline/compare.h"

namespace limn::api {

namespace {

using render::pipeline::CompareJob;
using render::pipeline::CompareResult;

// The views share their warnings: each is said once.
void addOnce(std::vector<std::string>& warnings, const std::string& warning) {
  if (std::find(warnings.begin(), warnings.end(), warning) == warnings.end()) {
    warnings.push_back(warning);
  }
}

// The views: the request's camera with its orbit's azimuth stepped once round.
std::vector<render::CameraSpec> turntableCameras(const render::CameraSpec& camera,
                                                 const Turntable& turntable) {
  std::vector<render::CameraSpec> cameras;
  const render::Orbit start = camera.orbit.value_or(render::Orbit{});
  for (int k = 0; k < turntable.frames; ++k) {
    render::CameraSpec view = camera;
    view.orbit = render::Orbit{start.azimuthDeg + 360.0 * k / turntable.frames,
                               turntable.elevationDeg, start.distance};
    cameras.push_back(view);
  }
  return cameras;
}

// Every view's images are held until the answer is written: the same budget as frames.
void checkPixels(const RenderRequest& request, const render::pipeline::JobLimits& limits) {
  const size_t perView = request.job.outputs.count() + request.turntable->animation;
  const size_t side =
      static_cast<size_t>(request.job.camera.width.value_or(render::kDefaultImageSide)) *
      request.job.camera.height.value_or(render::kDefaultImageSide);
  const size_t pixels = request.turntable->frames * side * std::max<size_t>(perView, 1) *
                        (request.job.reference ? 2 : 1);
  if (pixels > limits.maxFramePixels) {
    throw tooLarge("maxFramePixels", "turntable.frames",
                   "a turntable of " + std::to_string(request.turntable->frames) + " views holds " +
                       std::to_string(pixels) + " image pixels, over limit maxFramePixels (" +
                       std::to_string(limits.maxFramePixels) + ")");
  }
}

CompareJob compareJobOf(const RenderRequest& request) {
  const render::pipeline::RenderJob& job = request.job;
  CompareJob compare;
  compare.mesh = job.mesh;
  compare.displacement = job.displacement;
  compare.cameras = turntableCameras(job.camera, *request.turntable);
  compare.methods = {{job.method, job.params, job.shading}};
  compare.metricSupersample = job.params.metricSupersample;
  compare.outputs = job.outputs;
  compare.outputs.color = job.outputs.color || request.turntable->animation;
  compare.reference = job.reference;
  return compare;
}

void writeAnimation(json::Writer& w, const CompareResult& result, const Turntable& turntable) {
  std::vector<const render::Image*> frames;
  for (const render::pipeline::CompareRow& row : result.rows) {
    auto color = row.images.passes.find(render::pass::kColor);
    if (color != row.images.passes.end()) frames.push_back(&color->second);
  }
  if (frames.size() != result.rows.size()) return;  // a view failed: its error says why
  const render::image::EncodedImage gif = render::image::encodeAnimation(frames, turntable.fps);
  w.Key("animation");
  w.StartObject();
  w.Key("mime");
  w.String(gif.mime.c_str());
  w.Key("width");
  w.Int(gif.width);
  w.Key("height");
  w.Int(gif.height);
  w.Key("data");
  json::writeString(w, encodeBase64(gif.bytes));
  w.EndObject();
}

void writeView(json::Writer& w, const RenderRequest& request, const CompareResult& result, size_t k,
               std::vector<std::string>& warnings, const response::EncodedImages& encoded) {
  const render::pipeline::CompareRow& row = result.rows[k];
  w.StartObject();
  w.Key("azimuthDeg");
  w.Double(request.job.camera.orbit.value_or(render::Orbit{}).azimuthDeg +
           360.0 * static_cast<double>(k) / request.turntable->frames);
  if (row.error) {
    w.Key("error");
    w.StartObject();
    w.Key("subject");
    json::writeString(w, row.error->subject);
    w.Key("message");
    json::writeString(w, row.error->message);
    w.EndObject();
    w.EndObject();
    return;
  }
  w.Key("images");
  response::writeImages(w, row.images, request.job.outputs, request.encoding, "method", warnings,
                        &encoded);
  if (request.job.reference) {
    w.Key("metrics");
    response::writeMetrics(w, row.metrics);
    if (k < result.references.size()) {
      w.Key("reference");
      w.StartObject();
      w.Key("camera");
      response::writeCamera(w, result.references[k].camera);
      w.Key("images");
      response::writeImages(w, result.references[k].images, request.job.outputs, request.encoding,
                            "reference", warnings, &encoded);
      w.Key("referenceMs");
      w.Double(result.references[k].referenceMs);
      w.EndObject();
    }
  }
  w.Key("stats");
  response::writeStats(w, row.stats);
  w.Key("approxMs");
  w.Double(row.timings.approxMs);
  w.Key("rasterMs");
  w.Double(row.timings.rasterMs);
  w.EndObject();
  for (const std::string& warning : row.warnings) addOnce(warnings, warning);
}

}  // namespace

std::string writeTurntable(const RenderRequest& request, const render::pipeline::JobLimits& limits,
                           render::pipeline::RenderContext& context,
                           const render::CancelToken& cancel) {
  checkPixels(request, limits);
  const CompareResult result =
      render::pipeline::compare(compareJobOf(request), limits, context, cancel);
  const Turntable& turntable = *request.turntable;
  std::vector<std::string> warnings = request.warnings;
  std::vector<response::EncodedImages::Owned> sets;
  for (size_t k = 0; k < result.rows.size(); ++k) {
    if (result.rows[k].error) continue;
    sets.push_back({&result.rows[k].images, "method"});
    if (request.job.reference && k < result.references.size()) {
      sets.push_back({&result.references[k].images, "reference"});
    }
  }
  const response::EncodedImages encoded(sets, request.job.outputs, request.encoding);

  rapidjson::StringBuffer buffer;
  json::Writer w(buffer);
  w.StartObject();
  w.Key("turntable");
  w.StartObject();
  w.Key("frames");
  w.Int(turntable.frames);
  w.Key("elevationDeg");
  w.Double(turntable.elevationDeg);
  w.Key("fps");
  w.Double(turntable.fps);
  if (turntable.animation) writeAnimation(w, result, turntable);
  w.EndObject();
  w.Key("frames");
  w.StartArray();
  for (size_t k = 0; k < result.rows.size(); ++k) {
    writeView(w, request, result, k, warnings, encoded);
  }
  w.EndArray();
  if (request.job.reference) {
    std::vector<render::metrics::Metrics> measured;
    for (const auto& row : result.rows) {
      if (!row.error) measured.push_back(row.metrics);
    }
    w.Key("worst");
    response::writeMetrics(w, render::metrics::worstOf(measured));
  }
  for (const auto& reference : result.references) {
    for (const std::string& warning : reference.warnings) addOnce(warnings, warning);
  }
  w.Key("timings");
  w.StartObject();
  w.Key("surfaceMs");
  w.Double(result.surfaceMs);
  w.Key("totalMs");
  w.Double(result.totalMs);
  w.EndObject();
  w.Key("warnings");
  json::writeStrings(w, warnings);
  w.EndObject();
  return {buffer.GetString(), buffer.GetSize()};
}

}  // namespace limn::api
