// Checks real answers of a running limn against api/openapi.json: each exchange is sent, its
// answer saved, and tests/integration/check_openapi.py (python3-jsonschema) checks that the
// status and media type are declared for the operation and that a JSON body validates,
// strictly, against the declared schema.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "tests/integration/http_client.h"

namespace limn::testing {

struct ApiExchange {
  std::string method;
  std::string path;  // as requested
  std::string
      documented;  // the document's path for it ("" = path; templates like /examples/{name})
  std::string body;
  Headers headers = {};
};

struct OpenApiCheck {
  int status = -1;         // the checker's exit status: 0 when every answer conforms
  std::string output;      // one line per problem, then a count
  std::set<int> statuses;  // the HTTP statuses the exchanges got
};

OpenApiCheck checkAgainstOpenApi(int port, const std::vector<ApiExchange>& exchanges);

}  // namespace limn::testing
