// handleRender: parse -> run -> write for POST /v1/render, with every failure turned into its
// JSON error answer (answerOrError). The server and the CLI call it; it never throws.
#include <chrono>
#include <optional>

#include "api/accept.h"
#include "api/render_api.h"

namespace limn::api {

namespace {

std::vector<StageTime> stageTimes(const render::pipeline::Timings& t) {
  return {{"parse", t.parseMs},   {"surface", t.surfaceMs},     {"approx", t.approxMs},
          {"raster", t.rasterMs}, {"reference", t.referenceMs}, {"metrics", t.metricsMs}};
}

// The image format an Accept header ranks above JSON (the answer is then the picture itself), or
// none: JSON wins ties and absent headers.
std::optional<render::image::Format> acceptedImage(std::string_view accept) {
  if (accept.empty()) return std::nullopt;
  struct Choice {
    const char* type;
    render::image::Format format;
  };
  static const Choice kImages[] = {{"image/png", render::image::Format::Png},
                                   {"image/jpeg", render::image::Format::Jpeg},
                                   {"image/webp", render::image::Format::Webp},
                                   {"image/x-exr", render::image::Format::Exr},
                                   {"image/*", render::image::Format::Png}};
  double json = -1, best = -1;
  render::image::Format format = render::image::Format::Png;
  for (const MediaRange& range : parseAccept(accept)) {
    auto is = [&](const char* type) { return sameMediaType(range.type, type); };
    if (is("application/json") || is("application/*") || is("*/*")) json = std::max(json, range.q);
    for (const Choice& choice : kImages) {
      if (is(choice.type) && range.q > best) {
        best = range.q;
        format = choice.format;
      }
    }
  }
  if (best > 0 && best > json) return format;
  return std::nullopt;
}

// The one picture a request asks for, as the answer's body.
Answer imageAnswer(const RenderRequest& request, const render::pipeline::RenderResult& result,
                   render::image::Format format) {
  const render::Image* image = nullptr;
  std::string pass;
  for (const auto& [name, candidate] : result.images.passes) {
    image = &candidate;
    pass = name;
  }
  if (image == nullptr) throw ApiError{500, "internal", "the render made no image", "{}"};
  render::image::EncodedImage encoded =
      render::image::encode(*image, pass, format, request.encoding.quality);
  Answer answer;
  answer.contentType = encoded.mime;
  answer.body.assign(encoded.bytes.begin(), encoded.bytes.end());
  answer.headers.emplace_back("X-Limn-Pass", pass);
  answer.headers.emplace_back("X-Limn-Triangles", std::to_string(result.stats.triangles));
  answer.headers.emplace_back("X-Limn-Warnings",
                              std::to_string(request.warnings.size() + result.warnings.size()));
  return answer;
}

}  // namespace

Answer handleRender(std::string_view body, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                    render::mesh::MeshCache* meshes, std::string_view accept) {
  return answerOrError("render", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    RenderRequest request = parseRenderRequest(body, limits, meshes);
    const std::optional<render::image::Format> image = acceptedImage(accept);
    const int images = request.job.outputs.count();
    const bool referenceImages =
        request.job.reference && request.job.method != render::pipeline::Method::Limit;
    if (image &&
        (images != 1 || referenceImages || !request.job.frames.empty() || request.turntable)) {
      throw ApiError{406, "not_acceptable",
                     "an image answer (Accept: image/...) is one picture: ask for one output, "
                     "without reference images or frames, or accept application/json",
                     "{\"accept\":[\"application/json\"]}"};
    }
    const double parseMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    if (request.turntable) {
      Answer answer;
      answer.body = writeTurntable(request, limits, context, cancel);
      answer.meshFaces = static_cast<size_t>(request.job.mesh.faceCount());
      return answer;
    }

    render::pipeline::RenderResult result =
        render::pipeline::run(request.job, limits, context, cancel);
    result.timings.parseMs = parseMs;

    if (image) {
      Answer answer = imageAnswer(request, result, *image);
      answer.stages = stageTimes(result.timings);
      answer.meshFaces = static_cast<size_t>(result.stats.controlFaces);
      return answer;
    }
    Answer answer;
    answer.body = writeRenderResponse(result, request);
    answer.stages = stageTimes(result.timings);
    answer.meshFaces = static_cast<size_t>(result.stats.controlFaces);
    return answer;
  });
}

}  // namespace limn::api
