// handleSilhouette: parse -> runContours -> JSON or SVG for POST /v1/silhouette, with every
// failure turned into its JSON error answer (answerOrError, as handleRender). Never throws.
#include <chrono>

#include "api/silhouette_api.h"

namespace limn::api {

Answer handleSilhouette(std::string_view body, std::string_view accept,
                        const render::pipeline::JobLimits& limits,
                        const render::CancelToken& cancel, render::mesh::MeshCache* meshes) {
  return answerOrError("contour search", [&] {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    SilhouetteRequest request = parseSilhouetteRequest(body, accept, limits, meshes);
    const double parseMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();

    render::pipeline::ContourResult result =
        render::pipeline::runContours(request.job, limits, cancel);
    result.timings.parseMs = parseMs;

    Answer answer;
    if (request.format == ContourFormat::Svg) {
      answer.contentType = "image/svg+xml";
      answer.body = writeSilhouetteSvg(result, request);
    } else {
      answer.body = writeSilhouetteJson(result, request);
    }
    const render::pipeline::ContourTimings& t = result.timings;
    answer.stages = {{"parse", t.parseMs},
                     {"surface", t.surfaceMs},
                     {"contour", t.contourMs},
                     {"chain", t.chainMs},
                     {"visibility", t.visibilityMs}};
    answer.meshFaces = static_cast<size_t>(result.stats.controlFaces);
    return answer;
  });
}

}  // namespace limn::api
