// handleCompare: parse -> compare -> write for POST /v1/compare (and every row of `limn batch`
// and POST /v1/jobs), every failure turned into its JSON error answer. Never throws.
#include <chrono>

#include "api/compare_api.h"

namespace limn::api {

namespace {

// For the request log and /metrics: each stage summed over the rows, the reference over the
// cameras.
std::vector<StageTime> stageTimes(const render::pipeline::CompareResult& result, double parseMs) {
  double approx = 0, raster = 0, metrics = 0, reference = 0;
  for (const auto& row : result.rows) {
    approx += row.timings.approxMs;
    raster += row.timings.rasterMs;
    metrics += row.timings.metricsMs;
  }
  for (const auto& ref : result.references) reference += ref.referenceMs;
  return {{"parse", parseMs}, {"surface", result.surfaceMs}, {"approx", approx},
          {"raster", raster}, {"reference", reference},      {"metrics", metrics}};
}

}  // namespace

Answer handleCompare(std::string_view body, const render::pipeline::JobLimits& limits,
                     render::pipeline::RenderContext& context, const render::CancelToken& cancel,
                     render::mesh::MeshCache* meshes) {
  return answerOrError("comparison", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    CompareRequest request = parseCompareRequest(body, limits, meshes);
    const double parseMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    render::pipeline::CompareResult result =
        render::pipeline::compare(request.job, limits, context, cancel);
    Answer answer;
    answer.body = writeCompareResponse(result, request, parseMs);
    answer.stages = stageTimes(result, parseMs);
    answer.meshFaces = static_cast<size_t>(result.controlFaces);
    return answer;
  });
}

}  // namespace limn::api
