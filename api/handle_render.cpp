// handleRender: parse -> run -> write for POST /v1/render, with every failure turned into its
// JSON error answer (answerOrError). The server and the CLI call it; it never throws.
#include <chrono>

#include "api/render_api.h"

namespace limn::api {

namespace {

std::vector<StageTime> stageTimes(const render::pipeline::Timings& t) {
  return {{"parse", t.parseMs},   {"surface", t.surfaceMs},     {"approx", t.approxMs},
          {"raster", t.rasterMs}, {"reference", t.referenceMs}, {"metrics", t.metricsMs}};
}

}  // namespace

Answer handleRender(std::string_view body, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                    render::mesh::MeshCache* meshes) {
  return answerOrError("render", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    RenderRequest request = parseRenderRequest(body, limits, meshes);
    const double parseMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

    render::pipeline::RenderResult result =
        render::pipeline::run(request.job, limits, context, cancel);
    result.timings.parseMs = parseMs;

    Answer answer;
    answer.body = writeRenderResponse(result, request);
    answer.stages = stageTimes(result.timings);
    answer.meshFaces = static_cast<size_t>(result.stats.controlFaces);
    return answer;
  });
}

}  // namespace limn::api
