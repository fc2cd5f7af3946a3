#include "server/http_server.h"

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/strand.hpp>
#include <condition_variable>
#include <csignal>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "server/http_connection.h"

namespace limn::server {

namespace net = boost::asio;
using boost::system::error_code;
using net::ip::tcp;

struct HttpServer::Impl {
  Impl(const HttpOptions& opts, Router& router, WorkerPool& workerPool)
      : options(opts),
        pool(workerPool),
        shared{router, connectionLimits(opts)},
        ioc(std::max(1, opts.ioThreads)),
        control(net::make_strand(ioc)),
        acceptor(control),
        signals(control, SIGINT, SIGTERM) {}

  static ConnectionLimits connectionLimits(const HttpOptions& opts) {
    ConnectionLimits limits;
    limits.maxBodyBytes = opts.maxBodyBytes;
    limits.maxHeaderBytes = opts.maxHeaderBytes;
    limits.readTimeout = opts.readTimeout;
    return limits;
  }

  void listen() {
    tcp::endpoint endpoint;
    try {
      tcp::resolver resolver(ioc);
      auto results =
          resolver.resolve(options.host, std::to_string(options.port), tcp::resolver::passive);
      if (results.empty()) throw std::runtime_error("no address");
      endpoint = results.begin()->endpoint();
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot resolve listen address '" + options.host + "': " + e.what());
    }
    error_code ec;
    acceptor.open(endpoint.protocol(), ec);
    if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(endpoint, ec);
    if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (ec) {
      throw std::runtime_error("cannot listen on " + options.host + ":" +
                               std::to_string(options.port) + ": " + ec.message());
    }
    bound = acceptor.local_endpoint();
  }

  void accept() {
    // Each connection gets its own strand: its handlers never run concurrently, yet many
    // connections share the IO threads.
    acceptor.async_accept(net::make_strand(ioc), [this](error_code ec, tcp::socket socket) {
      if (!acceptor.is_open()) return;
      if (!ec) {
        std::make_shared<Connection>(std::move(socket), shared)->start();
      } else if (ec != net::error::operation_aborted) {
        std::cerr << "limn: accept failed: " << ec.message() << "\n";
      }
      accept();
    });
  }

  // On the control strand: the first step of shutdown, then wake run().
  void beginShutdown() {
    error_code ignored;
    acceptor.close(ignored);
    signals.cancel(ignored);
    std::lock_guard lock(mutex);
    stopRequested = true;
    stopped.notify_all();
  }

  HttpOptions options;
  WorkerPool& pool;
  // Declared before the io_context so that connections still owned by its handlers when it is
  // destroyed can unregister themselves.
  ConnectionShared shared;
  net::io_context ioc;
  net::strand<net::io_context::executor_type> control;
  tcp::acceptor acceptor;
  net::signal_set signals;
  tcp::endpoint bound;

  std::mutex mutex;
  std::condition_variable stopped;
  bool stopRequested = false;
};

HttpServer::HttpServer(const HttpOptions& options, Router& router, WorkerPool& pool)
    : impl_(std::make_unique<Impl>(options, router, pool)) {
  impl_->listen();
}

HttpServer::~HttpServer() = default;

std::string HttpServer::host() const { return impl_->bound.address().to_string(); }

unsigned short HttpServer::port() const { return impl_->bound.port(); }

void HttpServer::stop() {
  net::post(impl_->control, [impl = impl_.get()] { impl->beginShutdown(); });
}

void HttpServer::run() {
  Impl& s = *impl_;
  net::post(s.control, [&s] { s.accept(); });
  s.signals.async_wait([&s](error_code ec, int) {
    if (!ec) s.beginShutdown();
  });

  auto work = net::make_work_guard(s.ioc);
  std::vector<std::thread> threads;
  for (int i = 0; i < std::max(1, s.options.ioThreads); ++i) {
    threads.emplace_back([&s] {
      // A handler that throws must not take the process down with it: log and carry on.
      for (;;) {
        try {
          s.ioc.run();
          return;
        } catch (const std::exception& e) {
          std::cerr << "limn: IO thread: " << e.what() << "\n";
        }
      }
    });
  }

  {
    std::unique_lock lock(s.mutex);
    s.stopped.wait(lock, [&s] { return s.stopRequested; });
  }

  // Drain: no new connections (the acceptor is closed) and no new jobs (503), idle keep-alive
  // connections closed, every answer from here on closes its connection; the jobs already
  // queued or running get until the drain deadline to finish. Then what is left is answered
  // 503 and cancelled, and the connections get a short grace to write their answers.
  s.shared.stopping = true;
  for (const auto& connection : s.shared.registry.snapshot()) connection->closeIfIdle();
  if (!s.pool.drain(std::chrono::steady_clock::now() + s.options.drainTimeout)) {
    std::cerr << "limn: jobs still running after the " << s.options.drainTimeout.count()
              << " ms drain; answering them 503 and cancelling them\n";
  }
  s.pool.stop();
  for (const auto& connection : s.shared.registry.snapshot()) connection->closeIfIdle();
  if (!s.shared.registry.waitUntilEmpty(s.options.shutdownGrace)) {
    std::cerr << "limn: some connections were still open after " << s.options.shutdownGrace.count()
              << " ms; closing them\n";
  }

  work.reset();
  s.ioc.stop();
  for (auto& t : threads) t.join();
}

}  // namespace limn::server
