// The wire format of POST /v1/implicit: JSON request -> ImplicitJob, RenderResult -> the same
// answer shape as /v1/render's (plus stats.closed and stats.implicit), or the polygonised mesh
// itself as OBJ or PLY text when the Accept header asks for it.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "api/answer.h"
#include "render/core/cancel.h"
#include "render/image/encode.h"
#include "render/pipeline/implicit_job.h"
#include "render/pipeline/render_job.h"

namespace limn::api {

struct ImplicitRequest {
  render::pipeline::ImplicitJob job;
  render::image::Encoding encoding;  // "imageFormat", "imageQuality"
  std::vector<std::string> warnings;
};

// Throws ApiError 400 (invalid_json / invalid_request naming the field: unknown primitive
// types, non-finite numbers, expressions that do not compile or use names other than x, y, z)
// and 413 too_large (maxPrimitives, maxResolution, maxExpressionLength).
ImplicitRequest parseImplicitRequest(std::string_view json,
                                     const render::pipeline::JobLimits& limits);

// True when `body` is an implicit request (it has a "field" member): `limn render` takes both.
bool isImplicitRequest(std::string_view body);

// parse -> run (or only polygonise, for Accept: text/plain (OBJ) or application/x-ply) -> write;
// every failure becomes its JSON error answer. Never throws.
Answer handleImplicit(std::string_view body, std::string_view accept,
                      const render::pipeline::JobLimits& limits,
                      render::pipeline::RenderContext& context, const render::CancelToken& cancel);

}  // namespace limn::api
