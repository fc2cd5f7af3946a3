#include "server/http_connection.h"

#include <sys/socket.h>

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core/string.hpp>
#include <cerrno>
#include <iostream>
#include <utility>

#ifndef LIMN_VERSION
#define LIMN_VERSION "unknown"
#endif

namespace limn::server {

namespace net = boost::asio;
namespace http = boost::beast::http;
using boost::system::error_code;
using Clock = std::chrono::steady_clock;

// ---- ConnectionRegistry ----

void ConnectionRegistry::add(const std::shared_ptr<Connection>& connection) {
  std::lock_guard lock(mutex_);
  open_[connection.get()] = connection;
}

void ConnectionRegistry::remove(const Connection* connection) {
  std::lock_guard lock(mutex_);
  open_.erase(connection);
  if (open_.empty()) emptied_.notify_all();
}

std::vector<std::shared_ptr<Connection>> ConnectionRegistry::snapshot() {
  std::vector<std::shared_ptr<Connection>> open;
  std::lock_guard lock(mutex_);
  for (auto& [raw, weak] : open_) {
    if (auto c = weak.lock()) open.push_back(std::move(c));
  }
  return open;
}

bool ConnectionRegistry::waitUntilEmpty(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return emptied_.wait_for(lock, timeout, [this] { return open_.empty(); });
}

// ---- Connection ----

Connection::Connection(net::ip::tcp::socket socket, ConnectionShared& shared)
    : socket_(std::move(socket)), timer_(socket_.get_executor()), shared_(shared) {}

Connection::~Connection() { shared_.registry.remove(this); }

void Connection::start() {
  shared_.registry.add(shared_from_this());
  // Run the first step on the connection's strand like every later one.
  net::dispatch(socket_.get_executor(), [self = shared_from_this()] { self->readHeader(); });
}

void Connection::closeIfIdle() {
  net::dispatch(socket_.get_executor(), [self = shared_from_this()] {
    bool idle = self->phase_ == Phase::Reading && self->buffer_.size() == 0 &&
                !(self->parser_ && self->parser_->got_some());
    if (idle) {
      self->closeNow();
    } else {
      self->closeAfterWrite_ = true;
    }
  });
}

void Connection::readHeader() {
  if (shared_.stopping) return closeNow();
  phase_ = Phase::Reading;
  readTimedOut_ = false;
  route_ = "other";
  method_ = "-";
  bytesIn_ = 0;
  version_ = 11;
  parser_.emplace();
  parser_->body_limit(shared_.limits.maxBodyBytes);
  parser_->header_limit(shared_.limits.maxHeaderBytes);
  armTimer(shared_.limits.readTimeout);
  http::async_read_header(
      socket_, buffer_, *parser_,
      [self = shared_from_this()](error_code ec, size_t) { self->onHeader(ec); });
}

void Connection::onHeader(error_code ec) {
  requestStart_ = Clock::now();
  if (parser_->is_header_done()) {
    // Numbered now, so that a worker that dies on this request can name it in the answer.
    requestId_ = shared_.router.log().nextId();
    const auto& request = parser_->get();
    version_ = request.version();
    route_ = Router::routeLabel(std::string_view(request.target().data(), request.target().size()));
    method_ = std::string(request.method_string());
  }
  if (ec) return refuse(ec);
  if (version_ != 10 && version_ != 11) {
    version_ = 11;
    return answer(
        api::errorAnswer({400, "invalid_request", "only HTTP/1.0 and 1.1 are spoken here"}), true);
  }

  // curl and browsers send "Expect: 100-continue" before large bodies and wait (curl: 1 s)
  // for this go-ahead; without it every big render would start a second late.
  const auto& request = parser_->get();
  if (boost::beast::iequals(request[http::field::expect], "100-continue") && !parser_->is_done()) {
    auto go = std::make_shared<http::response<http::empty_body>>(http::status::continue_,
                                                                 request.version());
    http::async_write(socket_, *go, [self = shared_from_this(), go](error_code ec, size_t) {
      if (ec) return self->closeNow();
      self->readBody();
    });
    return;
  }
  readBody();
}

void Connection::readBody() {
  // The body gets its own allowance: a large body on a slow link is not an attack.
  armTimer(shared_.limits.readTimeout);
  http::async_read(socket_, buffer_, *parser_,
                   [self = shared_from_this()](error_code ec, size_t) { self->onBody(ec); });
}

void Connection::onBody(error_code ec) {
  if (ec) return refuse(ec);
  timer_.cancel();
  handle();
}

std::string Connection::peerAddress() const {
  error_code ec;
  const auto peer = socket_.remote_endpoint(ec);
  return ec ? std::string("unknown") : peer.address().to_string();
}

void Connection::handle() {
  phase_ = Phase::Handling;
  auto message = parser_->release();
  bool keepAlive = message.keep_alive();
  bytesIn_ = message.body().size();
  Request request{std::string(message.method_string()),
                  std::string(message.target()),
                  std::move(message.body()),
                  std::string(message[http::field::accept]),
                  std::string(message[http::field::authorization]),
                  std::string(message[http::field::origin]),
                  requestId_,
                  std::string(message["Idempotency-Key"]),
                  peerAddress(),
                  std::string(message["Priority"]),
                  std::string(message[http::field::content_type])};
  // The router may answer from a worker thread: hop back onto this connection's strand.
  const unsigned generation = ++handling_;
  abandon_ = shared_.router.handle(
      std::move(request), [self = shared_from_this(), keepAlive](api::Answer answer) {
        net::post(self->socket_.get_executor(),
                  [self, keepAlive, answer = std::move(answer)]() mutable {
                    self->answer(std::move(answer), !keepAlive);
                  });
      });
  if (abandon_ && phase_ == Phase::Handling) watchForHangUp(generation);
}

void Connection::watchForHangUp(unsigned generation) {
  socket_.async_wait(net::ip::tcp::socket::wait_read, [self = shared_from_this(),
                                                       generation](error_code ec) {
    if (ec || generation != self->handling_ || self->phase_ != Phase::Handling) return;
    char byte;
    const ssize_t got = ::recv(self->socket_.native_handle(), &byte, 1, MSG_PEEK | MSG_DONTWAIT);
    if (got > 0) return;  // the next request (pipelined): it waits in the socket for its turn
    if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      return self->watchForHangUp(generation);
    }
    // End of stream or a reset: nobody is left to read the answer.
    if (auto abandon = std::move(self->abandon_)) abandon();
    self->closeNow();
  });
}

void Connection::answer(api::Answer answer, bool close) {
  abandon_ = nullptr;
  if (phase_ == Phase::Closing) return;
  phase_ = Phase::Writing;
  close = close || closeAfterWrite_ || shared_.stopping;
  closeAfterWrite_ = close;

  auto& response = response_.emplace(static_cast<http::status>(answer.status), version_);
  response.set(http::field::server, "limn/" LIMN_VERSION);
  response.set(http::field::content_type, answer.contentType);
  for (const auto& [name, value] : answer.headers) response.set(name, value);
  // An answer before a header was read (a refused connection) gets its number here.
  const uint64_t id = requestId_ ? requestId_ : shared_.router.log().nextId();
  requestId_ = 0;
  response.set("X-Request-Id", std::to_string(id));
  response.keep_alive(!close);
  const size_t bytesOut = answer.body.size();
  response.body() = std::move(answer.body);
  response.prepare_payload();

  double seconds = std::chrono::duration<double>(Clock::now() - requestStart_).count();
  shared_.router.metrics().answered(route_, answer.status, seconds);
  shared_.router.log().answered(
      {id, method_, route_, answer.status, seconds, bytesIn_, bytesOut, &answer.stages});

  armTimer(shared_.limits.writeTimeout);
  http::async_write(socket_, response,
                    [self = shared_from_this()](error_code ec, size_t) { self->onWrite(ec); });
}

void Connection::onWrite(error_code ec) {
  timer_.cancel();
  response_.reset();
  if (ec) return closeNow();
  if (closeAfterWrite_) return lingerAndClose();
  readHeader();
}

void Connection::refuse(error_code ec) {
  timer_.cancel();
  // The client closed the connection between requests, or went away in the middle of one:
  // nobody is left to read an answer.
  if (ec == http::error::end_of_stream || ec == http::error::partial_message ||
      ec == net::error::eof || ec == net::error::connection_reset) {
    return closeNow();
  }
  if (ec == net::error::operation_aborted) {
    if (!readTimedOut_) return closeNow();  // closed by shutdown while idle
    return answer(
        api::errorAnswer({408, "timeout",
                          "the request was not received within " +
                              std::to_string(shared_.limits.readTimeout.count()) + " ms"}),
        true);
  }
  if (ec == http::error::body_limit) {
    return answer(api::errorAnswer({413, "too_large",
                                    "the request body is larger than maxBodyBytes (" +
                                        std::to_string(shared_.limits.maxBodyBytes) + " bytes)",
                                    "{\"limit\":\"maxBodyBytes\",\"maxBodyBytes\":" +
                                        std::to_string(shared_.limits.maxBodyBytes) + "}"}),
                  true);
  }
  if (ec == http::error::header_limit) {
    return answer(api::errorAnswer({431, "too_large",
                                    "the request header is larger than " +
                                        std::to_string(shared_.limits.maxHeaderBytes) + " bytes"}),
                  true);
  }
  if (ec.category() == http::make_error_code(http::error::bad_method).category()) {
    return answer(api::errorAnswer({400, "invalid_request", "malformed HTTP: " + ec.message()}),
                  true);
  }
  closeNow();  // a socket error: nothing can be sent
}

void Connection::lingerAndClose() {
  // Closing a socket with unread input makes the kernel send a reset, which can destroy the
  // answer before the client has read it. Shut down our side and drain for a while instead.
  phase_ = Phase::Closing;
  error_code ignored;
  socket_.shutdown(net::ip::tcp::socket::shutdown_send, ignored);
  armTimer(shared_.limits.lingerTimeout);
  drain();
}

void Connection::drain() {
  socket_.async_read_some(net::buffer(drainBuffer_),
                          [self = shared_from_this()](error_code ec, size_t) {
                            if (ec) return self->closeNow();
                            self->drain();
                          });
}

void Connection::closeNow() {
  phase_ = Phase::Closing;
  timer_.cancel();
  error_code ignored;
  socket_.shutdown(net::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
}

void Connection::armTimer(std::chrono::milliseconds after) {
  timer_.expires_after(after);
  timer_.async_wait([self = shared_from_this()](error_code ec) { self->onTimer(ec); });
}

void Connection::onTimer(error_code ec) {
  // A wait that was cancelled or re-armed after it had already fired is stale.
  if (ec == net::error::operation_aborted || timer_.expiry() > Clock::now()) return;
  switch (phase_) {
    case Phase::Reading: {
      bool midRequest = buffer_.size() > 0 || (parser_ && parser_->got_some());
      if (!midRequest) return closeNow();  // an idle keep-alive connection
      // A request that trickles in too slowly (slowloris): stop reading and say so.
      readTimedOut_ = true;
      error_code ignored;
      socket_.cancel(ignored);
      return;
    }
    case Phase::Handling:
      return;  // the worker pool owns the render deadline
    case Phase::Writing:
    case Phase::Closing:
      return closeNow();  // a client that does not read its answer
  }
}

}  // namespace limn::server
