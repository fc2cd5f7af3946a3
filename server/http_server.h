// HttpServer: the network shell around the Router. It listens on host:port, runs Boost.Beast
// connections on its own IO threads (render work runs on the WorkerPool's threads, never here),
// and shuts down cleanly on SIGINT/SIGTERM:
//   1. stop accepting, refuse new jobs with 503, close idle keep-alive connections;
//   2. drain: queued and running jobs may finish until drainTimeout;
//   3. stop the pool: what is still queued or running is answered 503 and cancelled;
//   4. return from run() once every connection has written its answer and closed (or after
//      shutdownGrace). The caller then joins the workers (WorkerPool::joinFor).
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
  std::chrono::milliseconds readTimeout{30'000};   // to receive one request (slowloris guard)
  std::chrono::milliseconds drainTimeout{10'000};  // for the jobs in flight at a SIGTERM
  std::chrono::milliseconds shutdownGrace{2'000};  // for connections to write their answers
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
