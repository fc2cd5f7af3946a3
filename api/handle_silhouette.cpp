// handleSilhouette: parse -> runContours -> JSON or SVG for POST /v1/silhouette, with every
// failure turned into its JSON error answer (the same mapping as handleRender). Never throws.
#include <chrono>
#include <new>

#include "api/silhouette_api.h"

namespace limn::api {

Answer handleSilhouette(std::string_view body, std::string_view accept,
                        const render::pipeline::JobLimits& limits,
                        const render::CancelToken& cancel) {
  try {
    try {
      using Clock = std::chrono::steady_clock;
      const Clock::time_point start = Clock::now();
      SilhouetteRequest request = parseSilhouetteRequest(body, accept, limits);
      const double parseMs =
          std::chrono::duration<double, std::milli>(Clock::now() - start).count();

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
      return answer;
    } catch (const ApiError& error) {
      return errorAnswer(error);
    } catch (const render::InputError& error) {
      return errorAnswer(fromInputError(error));
    } catch (const render::Cancelled&) {
      return errorAnswer({504, "timeout",
                          "the contours were not found within the request time limit "
                          "(requestTimeoutMs), or the server is shutting down"});
    } catch (const std::bad_alloc&) {
      return errorAnswer(
          {413, "too_large", "request needs more memory than available", R"({"limit": "memory"})"});
    } catch (const std::exception& error) {
      return errorAnswer({500, "internal", error.what()});
    } catch (...) {
      return errorAnswer({500, "internal", "unknown error"});
    }
  } catch (...) {
    Answer answer;
    answer.status = 500;
    answer.body = R"({"error":{"code":"internal","message":"out of memory","detail":{}}})";
    return answer;
  }
}

}  // namespace limn::api
