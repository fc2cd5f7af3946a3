// HttpClient: the client side of `limn batch --server URL` — one blocking HTTP/1.1 request per
// call on a fresh connection, answered as an api::Answer (status 0 when the server could not
// be reached, with the reason as a JSON error body, so callers treat it like any refusal).
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "api/answer.h"

namespace limn::server {

// http://HOST[:PORT][/PREFIX]: where a limn server answers (no TLS).
struct ServerUrl {
  std::string host, port = "80", prefix;  // prefix: "" or "/path" without a trailing slash
};
std::optional<ServerUrl> parseServerUrl(const std::string& text, std::string* why);

class HttpClient {
 public:
  // `token`: sent as "Authorization: Bearer <token>" when not empty.
  HttpClient(ServerUrl url, std::string token, std::chrono::seconds timeout);

  api::Answer get(const std::string& path) const;
  api::Answer post(const std::string& path, const std::string& body) const;

 private:
  api::Answer request(bool post, const std::string& path, const std::string& body) const;

  ServerUrl url_;
  std::string token_;
  std::chrono::seconds timeout_;
};

}  // namespace limn::server
