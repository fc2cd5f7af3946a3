// Access: who may call limn's /v1 routes and which web origins may read its answers.
//
// Both are off unless configured (ServiceConfig::authToken / corsOrigins). With a token, every
// /v1 request must carry `Authorization: Bearer <token>` or gets 401 `unauthorized`; /healthz,
// /readyz, /metrics and /openapi.json stay open (probes and scrapers carry no token). With
// origins, an answer to a request whose Origin is listed (or any, for "*") carries
// Access-Control-Allow-Origin, and an OPTIONS preflight on a known path is answered 204 with
// the methods and headers a front end needs — before authentication, since browsers send
// preflights without credentials. The Router applies these rules; nothing here knows sockets.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/answer.h"

namespace limn::server {

// Who is asking, for fair shares of the queue, GET /v1/jobs and Idempotency-Key: a digest of
// the Authorization header when the request carries one, else the peer's address.
std::string clientOf(const std::string& authorization, const std::string& peer);
// A short stable digest of `text`: 16 hex digits of XXH3-64 (not a secret's protection: a
// token's digest only tells requests apart).
std::string digestHex(std::string_view text);

// Access-Control-Allow-Origin (and Vary: Origin) for an origin Access allowed.
void addCorsHeaders(std::string_view origin, api::Answer& answer);

struct AccessOptions {
  std::string authToken;                 // "" = no authentication
  std::vector<std::string> corsOrigins;  // "" entries ignored; "*" = any origin
};

class Access {
 public:
  explicit Access(AccessOptions options) : options_(std::move(options)) {}

  // The 401 for a /v1 path without the right bearer token, or nothing when it may pass.
  std::optional<api::Answer> refuse(std::string_view path, std::string_view authorization) const;

  // The preflight answer for an allowed origin (204 with the methods and headers; the origin
  // headers are the caller's, as for every answer), or nothing.
  std::optional<api::Answer> preflight(std::string_view origin) const;

  // Whether answers to this Origin carry Access-Control-Allow-Origin.
  bool originAllowed(std::string_view origin) const;

 private:
  AccessOptions options_;
};

}  // namespace limn::server
