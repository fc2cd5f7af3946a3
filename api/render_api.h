// The wire format of POST /v1/render: JSON request -> RenderJob, RenderResult -> JSON answer.
// The server and the CLI call these; nothing below api/ knows JSON.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "render/core/cancel.h"
#include "render/image/encode.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

// An HTTP-shaped answer with no socket attached: what the server writes back.
struct Answer {
  int status = 200;
  std::string contentType = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra, e.g. Retry-After
};

// A request the api layer refuses. `code` is one of DESIGN.md's error codes
// (invalid_json, invalid_request, not_found, method_not_allowed, too_large, invalid_mesh, busy,
// internal, unavailable, timeout); `detailJson` is a JSON object (may be "{}").
struct ApiError {
  int status;
  std::string code;
  std::string message;
  std::string detailJson = "{}";
};

// {"error": {"code": ..., "message": ..., "detail": {...}}}
Answer errorAnswer(const ApiError& error);

struct RenderRequest {
  render::pipeline::RenderJob job;
  render::image::Format imageFormat = render::image::Format::Png;
};

// Throws ApiError (400 invalid_json / invalid_request, 413 too_large, 422 invalid_mesh).
RenderRequest parseRenderRequest(std::string_view json, const render::pipeline::JobLimits& limits);

// The 200 answer's JSON: images (base64), reference.images, metrics, stats, timings, warnings.
std::string writeRenderResponse(const render::pipeline::RenderResult& result,
                                const RenderRequest& request);

// parse -> run -> write, with every failure turned into its JSON error answer (InputError ->
// 4xx, Cancelled -> 504 timeout, anything else -> 500 internal). Never throws.
Answer handleRender(std::string_view body, const render::pipeline::JobLimits& limits,
                    render::pipeline::RenderContext& context, const render::CancelToken& cancel);

}  // namespace limn::api
