// The OpenAPI 3.0 document of limn's HTTP API, embedded at build time from api/openapi.json so
// that the file stays the single source; the server answers GET /openapi.json with it.
#pragma once

#include <string_view>

namespace limn::api {

std::string_view openApiDocument();

}  // namespace limn::api
