// HttpServer: the network shell around the Router. It listens on host:port, runs Boost.Beast
// connections on its own IO threads (render work runs on the WorkerPool's threads, never here),
// and shuts down cleanly on SIGINT/SIGTERM:
//   1. stop accepting;
//   2. stop the pool: queued and running renders are answered 503 and cancelled;
//   3. close idle keep-alive connections, let the others write their answers;
//   4. return from run() once every connection is closed (or after a grace period).
// Beast lives only in the .cpp files, so including this header costs nothing.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "server/router.h"
#include "server/worker_pool.h"

namespace limn::server {

struct HttpOptions {
  std::string host = "127.0.0.1";
  unsigned short port = 8080;  // 0 = any free port; port() says which
  int ioThreads = 1;
  size_t maxBodyBytes = 16 << 20;
  unsigned maxHeaderBytes = 16 << 10;
  std::chrono::milliseconds readTimeout{30'000};  // to receive one request (slowloris guard)
  std::chrono::milliseconds shutdownGrace{10'000};
};

class HttpServer {
 public:
  // Binds and listens (throws std::runtime_error when it cannot), and takes over SIGINT and
  // SIGTERM, so a signal that arrives from here on is a clean shutdown.
  HttpServer(const HttpOptions& options, Router& router, WorkerPool& pool);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // The address actually bound (the port is the ephemeral one when options.port was 0).
  std::string host() const;
  unsigned short port() const;

  // Serves until a signal or stop(), then shuts down as described above.
  void run();
  // Starts the shutdown from any thread.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace limn::server
