#include "tests/integration/http_client.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <strings.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace limn::testing {

namespace {

std::runtime_error socketError(const std::string& what) {
  return std::runtime_error(what + ": " + std::strerror(errno));
}

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string trim(std::string_view text) {
  size_t b = text.find_first_not_of(" \t");
  size_t e = text.find_last_not_of(" \t\r");
  if (b == std::string_view::npos) return "";
  return std::string(text.substr(b, e - b + 1));
}

}  // namespace

std::string HttpResponse::header(std::string_view name) const {
  for (const auto& [n, v] : headers) {
    if (lower(n) == lower(name)) return v;
  }
  return "";
}

bool HttpResponse::has(std::string_view name) const {
  for (const auto& [n, v] : headers) {
    if (lower(n) == lower(name)) return true;
  }
  return false;
}

HttpClient::HttpClient(int port, const std::string& host, std::chrono::seconds timeout) {
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw socketError("socket");
  timeval tv{};
  tv.tv_sec = static_cast<time_t>(timeout.count());
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (::inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1) {
    ::close(fd_);
    throw std::runtime_error("not an IPv4 address: " + host);
  }
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    auto error = socketError("connect to " + host + ":" + std::to_string(port));
    ::close(fd_);
    throw error;
  }
}

HttpClient::~HttpClient() {
  if (fd_ >= 0) ::close(fd_);
}

void HttpClient::send(std::string_view bytes) {
  while (!bytes.empty()) {
    ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw socketError("send");
    }
    bytes.remove_prefix(static_cast<size_t>(n));
  }
}

bool HttpClient::fill() {
  char chunk[16384];
  for (;;) {
    ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n > 0) {
      buffer_.append(chunk, static_cast<size_t>(n));
      return true;
    }
    if (n == 0) return false;
    if (errno == EINTR) continue;
    throw socketError("recv");
  }
}

HttpResponse HttpClient::readResponse() {
  size_t end;
  while ((end = buffer_.find("\r\n\r\n")) == std::string::npos) {
    if (!fill()) {
      throw std::runtime_error(buffer_.empty() ? "connection closed without an answer"
                                               : "connection closed inside an answer's header");
    }
  }
  std::string head = buffer_.substr(0, end);
  buffer_.erase(0, end + 4);

  HttpResponse response;
  size_t lineEnd = head.find("\r\n");
  std::string statusLine = head.substr(0, lineEnd);
  // "HTTP/1.1 200 OK"
  if (statusLine.rfind("HTTP/1.", 0) != 0 || statusLine.size() < 12) {
    throw std::runtime_error("not an HTTP status line: " + statusLine);
  }
  response.status = std::stoi(statusLine.substr(9, 3));
  size_t pos = lineEnd == std::string::npos ? head.size() : lineEnd + 2;
  while (pos < head.size()) {
    size_t next = head.find("\r\n", pos);
    if (next == std::string::npos) next = head.size();
    std::string_view line(head.data() + pos, next - pos);
    size_t colon = line.find(':');
    if (colon != std::string_view::npos) {
      response.headers.emplace_back(trim(line.substr(0, colon)), trim(line.substr(colon + 1)));
    }
    pos = next + 2;
  }
  if (response.status >= 100 && response.status < 200) return response;

  if (response.has("Content-Length")) {
    size_t length = std::stoul(response.header("Content-Length"));
    while (buffer_.size() < length) {
      if (!fill()) throw std::runtime_error("connection closed inside an answer's body");
    }
    response.body = buffer_.substr(0, length);
    buffer_.erase(0, length);
  } else if (lower(response.header("Transfer-Encoding")).find("chunked") != std::string::npos) {
    throw std::runtime_error("chunked answers are not expected from limn");
  } else {
    while (fill()) {
    }
    response.body = std::move(buffer_);
    buffer_.clear();
  }
  return response;
}

HttpResponse HttpClient::request(const std::string& method, const std::string& path,
                                 const std::string& body, const Headers& headers) {
  std::string message = method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n";
  bool hasType = false;
  for (const auto& [name, value] : headers) {
    message += name + ": " + value + "\r\n";
    hasType = hasType || lower(name) == "content-type";
  }
  if (!body.empty() && !hasType) message += "Content-Type: application/json\r\n";
  if (!body.empty() || method == "POST") {
    message += "Content-Length: " + std::to_string(body.size()) + "\r\n";
  }
  message += "\r\n";
  message += body;
  send(message);
  for (;;) {
    HttpResponse response = readResponse();
    if (response.status >= 200) return response;
  }
}

bool HttpClient::peerClosed(std::chrono::milliseconds wait) {
  if (!buffer_.empty()) return false;
  pollfd p{fd_, POLLIN, 0};
  int ready = ::poll(&p, 1, static_cast<int>(wait.count()));
  if (ready <= 0) return false;
  char c;
  ssize_t n = ::recv(fd_, &c, 1, MSG_PEEK);
  return n == 0 || (n < 0 && errno == ECONNRESET);
}

HttpResponse get(int port, const std::string& path) {
  HttpClient client(port);
  return client.request("GET", path);
}

HttpResponse post(int port, const std::string& path, const std::string& body,
                  const Headers& headers) {
  HttpClient client(port);
  return client.request("POST", path, body, headers);
}

std::vector<unsigned char> decodeBase64(std::string_view text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  if (text.size() % 4 != 0) throw std::runtime_error("base64 length is not a multiple of 4");
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  for (size_t i = 0; i < text.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      char c = text[i + k];
      if (c == '=' && i + 4 == text.size() && k >= 2) {
        v[k] = 0;
        ++pad;
      } else if ((v[k] = value(c)) < 0 || pad > 0) {
        throw std::runtime_error("invalid base64 character");
      }
    }
    unsigned triple = (v[0] << 18) | (v[1] << 12) | (v[2] << 6) | v[3];
    out.push_back(static_cast<unsigned char>(triple >> 16));
    if (pad < 2) out.push_back(static_cast<unsigned char>((triple >> 8) & 0xff));
    if (pad < 1) out.push_back(static_cast<unsigned char>(triple & 0xff));
  }
  return out;
}

}  // namespace limn::testing
