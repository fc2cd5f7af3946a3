// Connection: one client's TCP connection, as a small class whose methods are the steps of its
// life: read the header, (say 100 Continue), read the body, hand the request to the Router,
// write the answer, then read the next request (keep-alive) or close.
//
// While a request is with the worker pool the connection watches its socket: a client that
// closes it (a page that aborted the request for a newer camera) gets its job abandoned, so
// the worker stops instead of finishing a picture nobody will see.
//
// Every failure that can still be answered is answered in JSON before the connection closes:
// malformed HTTP 400, header over its limit 431, body over maxBodyBytes 413, a client too slow
// to send its request 408. When the server closes after such an answer it lingers (shuts down
// its side, drains what the client still sends) so that the client reads the answer instead of
// a connection reset.
//
// This header is the server's internal business: only http_server.cpp and http_connection.cpp
// include it, because Beast is slow to compile.
#pragma once

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "api/render_api.h"
#include "server/router.h"

namespace limn::server {

class Connection;

// The connections that are open, so that shutdown can close the idle ones and wait for the rest.
class ConnectionRegistry {
 public:
  void add(const std::shared_ptr<Connection>& connection);
  void remove(const Connection* connection);
  // The open connections, owned by the caller: a connection that closes meanwhile is
  // destroyed outside the registry's lock.
  std::vector<std::shared_ptr<Connection>> snapshot();
  // True when every connection closed before `timeout`.
  bool waitUntilEmpty(std::chrono::milliseconds timeout);

 private:
  std::mutex mutex_;
  std::condition_variable emptied_;
  std::map<const Connection*, std::weak_ptr<Connection>> open_;
};

struct ConnectionLimits {
  size_t maxBodyBytes = 16 << 20;
  unsigned maxHeaderBytes = 16 << 10;
  std::chrono::milliseconds readTimeout{30'000};   // to receive one whole request
  std::chrono::milliseconds writeTimeout{30'000};  // to send one answer
  std::chrono::milliseconds lingerTimeout{2'000};  // draining before a close
};

// What every connection of one server shares.
struct ConnectionShared {
  ConnectionShared(Router& r, const ConnectionLimits& l) : router(r), limits(l) {}

  Router& router;
  ConnectionLimits limits;
  std::atomic<bool> stopping{false};
  ConnectionRegistry registry;
};

class Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(boost::asio::ip::tcp::socket socket, ConnectionShared& shared);
  ~Connection();

  void start();
  // Shutdown: a connection waiting for its next request closes now; one in the middle of a
  // request finishes it (and closes after answering).
  void closeIfIdle();

 private:
  using Parser = boost::beast::http::request_parser<boost::beast::http::string_body>;
  enum class Phase { Reading, Handling, Writing, Closing };

  void readHeader();
  void onHeader(boost::system::error_code ec);
  void readBody();
  void onBody(boost::system::error_code ec);
  void handle();
  // The client's IP address, for GET /v1/jobs' "your jobs" when no token names the caller.
  std::string peerAddress() const;
  // While handling: waits for the socket to turn readable, then tells end of stream (the client
  // went away: abandon the job) from the next request's first bytes (keep waiting for nothing).
  void watchForHangUp(unsigned generation);
  void answer(api::Answer answer, bool close);
  void onWrite(boost::system::error_code ec);
  // Answers a request that cannot be read any further, then closes.
  void refuse(boost::system::error_code ec);
  void lingerAndClose();
  void drain();
  void closeNow();
  void armTimer(std::chrono::milliseconds after);
  void onTimer(boost::system::error_code ec);

  boost::asio::ip::tcp::socket socket_;
  boost::asio::steady_timer timer_;
  ConnectionShared& shared_;
  boost::beast::flat_buffer buffer_;
  std::optional<Parser> parser_;
  std::optional<boost::beast::http::response<boost::beast::http::string_body>> response_;
  Phase phase_ = Phase::Reading;
  bool readTimedOut_ = false;
  bool closeAfterWrite_ = false;
  unsigned version_ = 11;
  std::string route_ = "other";
  std::string method_ = "-";  // of the request being answered, for the request log
  size_t bytesIn_ = 0;        // its body
  std::chrono::steady_clock::time_point requestStart_;
  char drainBuffer_[4096];
  uint64_t requestId_ = 0;       // of the request being read or answered (X-Request-Id)
  WorkerPool::Abandon abandon_;  // the job of the request being handled, while it runs
  unsigned handling_ = 0;        // counts handle() calls: a stale watch sees another number
};

}  // namespace limn::server
