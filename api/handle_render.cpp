// handleRender: parse -> run -> write for POST /v1/render, with every failure turned into its
// JSON error answer (answerOrError). The server and the CLI call it; it never throws.
#include <chrono>
#include <cstdio>

#include "api/render_api.h"

namespace limn::api {

namespace {

std::string stageTimesJson(const render::pipeline::Timings& t) {
  char text[256];
  std::snprintf(text, sizeof text,
                R"({"parseMs":%.3f,"surfaceMs":%.3f,"approxMs":%.3f,"rasterMs":%.3f,)"
                R"("referenceMs":%.3f,"metricsMs":%.3f,"totalMs":%.3f})",
                t.parseMs, t.surfaceMs, t.approxMs, t.rasterMs, t.referenceMs, t.metricsMs,
                t.parseMs + t.totalMs);
  return text;
}

}  // namespace

Answer handleRender(std::string_view body, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel) {
  return answerOrError("render", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    RenderRequest request = parseRenderRequest(body, limits);
    const double parseMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

    render::pipeline::RenderResult result =
        render::pipeline::run(request.job, limits, context, cancel);
    result.timings.parseMs = parseMs;

    Answer answer;
    answer.body = writeRenderResponse(result, request);
    answer.logStages = stageTimesJson(result.timings);
    return answer;
  });
}

}  // namespace limn::api
