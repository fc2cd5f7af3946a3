#include "server/access.h"

#define XXH_INLINE_ALL
#include <xxhash.h>

#include <cstdio>

namespace limn::server {

std::string digestHex(std::string_view text) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(XXH3_64bits(text.data(), text.size())));
  return hex;
}

std::string clientOf(const std::string& authorization, const std::string& peer) {
  return authorization.empty() ? "peer:" + peer : "token:" + digestHex(authorization);
}

namespace {

// Compares without stopping at the first difference, so the time taken does not tell a caller
// how much of a guessed token was right.
bool sameSecret(std::string_view a, std::string_view b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < a.size(); ++i) diff |= a[i] ^ b[i % (b.empty() ? 1 : b.size())];
  return diff == 0 && !b.empty();
}

}  // namespace

std::optional<api::Answer> Access::refuse(std::string_view path,
                                          std::string_view authorization) const {
  if (options_.authToken.empty() || path.substr(0, 4) != "/v1/") return std::nullopt;
  constexpr std::string_view kScheme = "Bearer ";
  bool bearer = authorization.substr(0, kScheme.size()) == kScheme;
  if (bearer && sameSecret(authorization.substr(kScheme.size()), options_.authToken)) {
    return std::nullopt;
  }
  api::Answer answer = api::errorAnswer(
      {401, "unauthorized",
       bearer ? "the bearer token is not valid for this server"
              : "this server wants an Authorization: Bearer <token> header on /v1 routes"});
  answer.headers.emplace_back("WWW-Authenticate", "Bearer");
  return answer;
}

bool Access::originAllowed(std::string_view origin) const {
  if (origin.empty()) return false;
  for (const std::string& allowed : options_.corsOrigins) {
    if (allowed == "*" || (!allowed.empty() && allowed == origin)) return true;
  }
  return false;
}

std::optional<api::Answer> Access::preflight(std::string_view origin) const {
  if (!originAllowed(origin)) return std::nullopt;
  api::Answer answer;
  answer.status = 204;
  answer.contentType = "text/plain";
  answer.headers.emplace_back("Access-Control-Allow-Methods", "GET, POST, OPTIONS");
  answer.headers.emplace_back("Access-Control-Allow-Headers",
                              "Content-Type, Authorization, Accept");
  answer.headers.emplace_back("Access-Control-Max-Age", "600");
  return answer;
}

void addCorsHeaders(std::string_view origin, api::Answer& answer) {
  answer.headers.emplace_back("Access-Control-Allow-Origin", std::string(origin));
  answer.headers.emplace_back("Vary", "Origin");
}

}  // namespace limn::server
