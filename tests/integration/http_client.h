// A small blocking HTTP/1.1 client over POSIX sockets for the integration tests: one
// HttpClient is one TCP connection (requests on it reuse it: keep-alive), and get()/post() open
// a fresh connection per call. It is deliberately independent of the server's own HTTP code, so
// a framing bug in the server cannot hide behind the same bug in the client.
#pragma once

#include <chrono>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace limn::testing {

using Headers = std::vector<std::pair<std::string, std::string>>;

struct HttpResponse {
  int status = 0;
  Headers headers;
  std::string body;

  // The value of the first header called `name` (case-insensitive), or "" when absent.
  std::string header(std::string_view name) const;
  bool has(std::string_view name) const;
};

class HttpClient {
 public:
  explicit HttpClient(int port, const std::string& host = "127.0.0.1",
                      std::chrono::seconds timeout = std::chrono::seconds(120));
  ~HttpClient();
  HttpClient(const HttpClient&) = delete;
  HttpClient& operator=(const HttpClient&) = delete;

  // Sends one request (Content-Length set from `body`) and reads its answer, skipping interim
  // 1xx answers. Throws std::runtime_error when the connection fails or closes early.
  HttpResponse request(const std::string& method, const std::string& path,
                       const std::string& body = "", const Headers& headers = {});

  // Low level, for malformed requests and protocol tests.
  void send(std::string_view bytes);
  // Reads one answer, 1xx included.
  HttpResponse readResponse();
  // True when the server has closed the connection (reads end of stream within `wait`).
  bool peerClosed(std::chrono::milliseconds wait = std::chrono::milliseconds(2000));

 private:
  bool fill();  // reads more bytes into buffer_; false at end of stream

  int fd_ = -1;
  std::string buffer_;
};

HttpResponse get(int port, const std::string& path);
HttpResponse post(int port, const std::string& path, const std::string& body,
                  const Headers& headers = {});

// Standard base64 (RFC 4648) decoding; throws std::runtime_error on a malformed input.
std::vector<unsigned char> decodeBase64(std::string_view text);

}  // namespace limn::testing
