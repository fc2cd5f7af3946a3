// handleImplicit: POST /v1/implicit. JSON answers by default (images, metrics, stats); with an
// Accept header that ranks OBJ (text/plain, model/obj) or PLY (application/x-ply, model/ply)
// above JSON, the polygonised mesh itself with its gradient normals, and no rendering.
#include <chrono>

#include "api/accept.h"
#include "api/implicit_api.h"
#include "api/render_api.h"
#include "api/request_parts.h"
#include "formats/mesh_writers.h"

namespace limn::api {

namespace {

enum class ImplicitAnswer { Json, Obj, Ply };

// The best of JSON, OBJ and PLY by the Accept header; JSON wins ties and absent headers.
std::optional<ImplicitAnswer> chooseAnswer(std::string_view accept) {
  if (accept.empty()) return ImplicitAnswer::Json;
  double json = -1, obj = -1, ply = -1;
  for (const MediaRange& range : parseAccept(accept)) {
    auto is = [&](const char* type) { return sameMediaType(range.type, type); };
    if (is("application/json") || is("application/*") || is("*/*")) json = std::max(json, range.q);
    if (is("text/plain") || is("model/obj")) obj = std::max(obj, range.q);
    if (is("application/x-ply") || is("model/ply")) ply = std::max(ply, range.q);
  }
  if (json > 0 && json >= obj && json >= ply) return ImplicitAnswer::Json;
  if (obj > 0 && obj >= ply) return ImplicitAnswer::Obj;
  if (ply > 0) return ImplicitAnswer::Ply;
  return std::nullopt;
}

std::vector<StageTime> stageTimes(const render::pipeline::Timings& t) {
  return {{"parse", t.parseMs},   {"surface", t.surfaceMs},     {"approx", t.approxMs},
          {"raster", t.rasterMs}, {"reference", t.referenceMs}, {"metrics", t.metricsMs}};
}

Answer meshAnswer(const ImplicitRequest& request, ImplicitAnswer format,
                  const render::pipeline::JobLimits& limits, const render::CancelToken& cancel) {
  render::pipeline::ImplicitMesh polygonised =
      render::pipeline::polygonizeImplicit(request.job, limits, cancel);
  const auto& implicitStats = *polygonised.stats.implicit;
  std::vector<std::string> comments = {
      std::string("limn implicit, ") +
      render::implicit::polygonizerName(request.job.polygonizer.method) + ": " +
      std::to_string(polygonised.stats.triangles) + " triangles, " +
      std::to_string(polygonised.stats.vertices) + " vertices, " +
      (implicitStats.closure.closed() ? "closed" : "not closed") +
      ", normals from the field's gradient"};
  for (const std::string& w : request.warnings) comments.push_back("warning: " + w);
  Answer answer;
  if (format == ImplicitAnswer::Obj) {
    answer.contentType = meshMime(MeshFormat::Obj);
    answer.body = formats::writeObjMesh(polygonised.mesh, comments);
  } else {
    answer.contentType = meshMime(MeshFormat::Ply);
    answer.body = formats::writePly(polygonised.mesh, comments);
  }
  answer.headers.emplace_back("X-Limn-Triangles", std::to_string(polygonised.stats.triangles));
  answer.headers.emplace_back("X-Limn-Vertices", std::to_string(polygonised.stats.vertices));
  answer.headers.emplace_back("X-Limn-Closed", implicitStats.closure.closed() ? "true" : "false");
  answer.stages = stageTimes(polygonised.timings);
  return answer;
}

}  // namespace

Answer handleImplicit(std::string_view body, std::string_view accept,
                      const render::pipeline::JobLimits& limits,
                      render::pipeline::RenderContext& context, const render::CancelToken& cancel) {
  return answerOrError("implicit render", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    const std::optional<ImplicitAnswer> format = chooseAnswer(accept);
    if (!format) {
      throw ApiError{406, "not_acceptable",
                     "POST /v1/implicit answers application/json, text/plain (OBJ) or "
                     "application/x-ply; the Accept header allows none of them",
                     "{\"accept\":[\"application/json\",\"text/plain\",\"application/x-ply\"]}"};
    }
    ImplicitRequest request = parseImplicitRequest(body, limits);
    {
      // The camera is checked against the field's domain, which only the prepared field knows.
      const render::implicit::Field field(request.job.field);
      request::checkCameraAgainstBounds(request.job.camera, field.bounds());
    }
    if (*format != ImplicitAnswer::Json) return meshAnswer(request, *format, limits, cancel);
    const double parseMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

    render::pipeline::RenderResult result =
        render::pipeline::runImplicit(request.job, limits, context, cancel);
    result.timings.parseMs = parseMs;
    Answer answer;
    answer.body = writeRenderResponse(result, AnswerShape{.outputs = request.job.outputs,
                                                          .reference = request.job.reference,
                                                          .encoding = request.encoding,
                                                          .warnings = request.warnings});
    answer.stages = stageTimes(result.timings);
    return answer;
  });
}

}  // namespace limn::api
