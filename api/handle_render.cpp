// handleRender: parse -> run -> write for POST /v1/render, with every failure turned into its
// JSON error answer. The server and the CLI call it; it never throws.
#include <chrono>
#include <new>

#include "api/render_api.h"

namespace limn::api {

Answer handleRender(std::string_view body, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel) {
  try {
    try {
      using Clock = std::chrono::steady_clock;
      const Clock::time_point start = Clock::now();
      RenderRequest request = parseRenderRequest(body, limits);
      const double parseMs =
          std::chrono::duration<double, std::milli>(Clock::now() - start).count();

      render::pipeline::RenderResult result =
          render::pipeline::run(request.job, limits, context, cancel);
      result.timings.parseMs = parseMs;

      Answer answer;
      answer.body = writeRenderResponse(result, request);
      return answer;
    } catch (const ApiError& error) {
      return errorAnswer(error);
    } catch (const render::InputError& error) {
      return errorAnswer(fromInputError(error));
    } catch (const render::Cancelled&) {
      return errorAnswer({504, "timeout",
                          "the render did not finish within the request time limit "
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
    // Building the error answer itself failed (out of memory): a fixed body still answers.
    Answer answer;
    answer.status = 500;
    answer.body = R"({"error":{"code":"internal","message":"out of memory","detail":{}}})";
    return answer;
  }
}

}  // namespace limn::api
