// Answer and ApiError: what the api layer hands back to the server instead of throwing through
// it. An ApiError carries one of DESIGN.md's error codes with the HTTP status that goes with it;
// errorAnswer() turns it into the JSON error body every failure uses.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "render/core/error.h"

namespace limn::api {

// One stage of a job and the milliseconds it took ("surface", 12.5).
struct StageTime {
  std::string name;
  double ms = 0;
};

// An HTTP-shaped answer with no socket attached: what the server writes back.
struct Answer {
  int status = 200;
  std::string contentType = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra, e.g. Retry-After
  // For the server's request log and /metrics, not the client: the engine's stage times and
  // the control mesh's face count (0 when no mesh was read).
  std::vector<StageTime> stages;
  size_t meshFaces = 0;
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

// The usual errors, with the detail object filled the same way everywhere:
// invalid_request -> {"field": ...}; too_large -> {"limit": ..., "field": ... when known};
// invalid_mesh -> {"subject": ...}.
ApiError invalidRequest(const std::string& field, const std::string& message);
ApiError tooLarge(const std::string& limit, const std::string& field, const std::string& message);
ApiError invalidMesh(const std::string& subject, const std::string& message);

// InvalidMesh -> 422 invalid_mesh, LimitExceeded -> 413 too_large, InvalidParameter -> 400
// invalid_request; the InputError's subject goes into the detail.
ApiError fromInputError(const render::InputError& error);

// Runs `work` and turns every failure into its JSON error answer: ApiError as it is,
// InputError through fromInputError, Cancelled -> 504 ("the `what` did not finish within the
// request time limit ..."), bad_alloc -> 413, anything else -> 500. Never throws.
Answer answerOrError(const std::string& what, const std::function<Answer()>& work);

}  // namespace limn::api
