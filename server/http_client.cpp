#include "server/http_client.h"

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/version.hpp>

namespace limn::server {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;

std::optional<ServerUrl> parseServerUrl(const std::string& text, std::string* why) {
  const std::string scheme = "http://";
  if (text.rfind(scheme, 0) != 0) {
    if (why) *why = "the server URL must start with http:// (got " + text + ")";
    return std::nullopt;
  }
  std::string rest = text.substr(scheme.size());
  ServerUrl url;
  const size_t slash = rest.find('/');
  if (slash != std::string::npos) {
    url.prefix = rest.substr(slash);
    rest = rest.substr(0, slash);
    while (!url.prefix.empty() && url.prefix.back() == '/') url.prefix.pop_back();
  }
  const size_t colon = rest.rfind(':');
  const bool v6 = !rest.empty() && rest.front() == '[';
  if (colon != std::string::npos && (!v6 || rest.find(']') < colon)) {
    url.port = rest.substr(colon + 1);
    rest = rest.substr(0, colon);
  }
  if (v6 && rest.size() >= 2 && rest.back() == ']') rest = rest.substr(1, rest.size() - 2);
  url.host = rest;
  if (url.host.empty() || url.port.empty() ||
      url.port.find_first_not_of("0123456789") != std::string::npos) {
    if (why) *why = "cannot read host and port from " + text;
    return std::nullopt;
  }
  return url;
}

HttpClient::HttpClient(ServerUrl url, std::string token, std::chrono::seconds timeout)
    : url_(std::move(url)), token_(std::move(token)), timeout_(timeout) {}

api::Answer HttpClient::get(const std::string& path) const { return request(false, path, ""); }

api::Answer HttpClient::post(const std::string& path, const std::string& body) const {
  return request(true, path, body);
}

api::Answer HttpClient::request(bool post, const std::string& path, const std::string& body) const {
  try {
    net::io_context ioc;
    net::ip::tcp::resolver resolver(ioc);
    beast::tcp_stream stream(ioc);
    stream.expires_after(timeout_);
    stream.connect(resolver.resolve(url_.host, url_.port));
    http::request<http::string_body> req(post ? http::verb::post : http::verb::get,
                                         url_.prefix + path, 11);
    req.set(http::field::host, url_.host);
    req.set(http::field::user_agent, "limn-batch");
    // RFC 9218: the lowest urgency. limn runs it in its batch lane, after everyone's requests.
    req.set("Priority", "u=7");
    if (!token_.empty()) req.set(http::field::authorization, "Bearer " + token_);
    if (post) {
      req.set(http::field::content_type, "application/json");
      req.body() = body;
      req.prepare_payload();
    }
    http::write(stream, req);
    beast::flat_buffer buffer;
    http::response_parser<http::string_body> parser;
    parser.body_limit(std::numeric_limits<std::uint64_t>::max());
    http::read(stream, buffer, parser);
    http::response<http::string_body> res = parser.release();
    beast::error_code ignored;
    stream.socket().shutdown(net::ip::tcp::socket::shutdown_both, ignored);
    api::Answer answer;
    answer.status = static_cast<int>(res.result_int());
    answer.contentType = std::string(res[http::field::content_type]);
    answer.body = std::move(res.body());
    return answer;
  } catch (const std::exception& e) {
    api::Answer answer = api::errorAnswer(
        {0, "unreachable",
         "http://" + url_.host + ":" + url_.port + url_.prefix + path + ": " + e.what()});
    return answer;
  }
}

}  // namespace limn::server
