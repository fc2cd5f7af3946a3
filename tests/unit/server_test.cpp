// The server's logic without a network: the WorkerPool's admission, deadline and shutdown
// rules, and the Router's answers. (tests/integration drives the real process over HTTP.)
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <spdlog/sinks/ostream_sink.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "api/render_api.h"
#include "server/http_server.h"
#include "server/request_log.h"
#include "server/router.h"
#include "server/worker_pool.h"
#include "tests/integration/http_client.h"

namespace limn::server {
namespace {

using namespace std::chrono_literals;
using render::CancelToken;
using render::pipeline::RenderContext;

// A reply that can be waited for and that counts how often it was called.
struct Captured {
  std::promise<api::Answer> promise;
  std::future<api::Answer> future = promise.get_future();
  std::atomic<int> calls{0};

  WorkerPool::Reply reply() {
    return [this](api::Answer answer) {
      if (calls.fetch_add(1) == 0) promise.set_value(std::move(answer));
    };
  }
  api::Answer wait(std::chrono::milliseconds timeout = 30s) {
    if (future.wait_for(timeout) != std::future_status::ready) {
      ADD_FAILURE() << "no reply within " << timeout.count() << " ms";
      return {};
    }
    return future.get();
  }
};

// A gate that jobs block on until the test opens it.
class Gate {
 public:
  void open() {
    std::lock_guard lock(mutex_);
    open_ = true;
    cv_.notify_all();
  }
  void wait() {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [this] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
};

std::string errorCode(const api::Answer& answer) {
  rapidjson::Document doc;
  doc.Parse(answer.body.c_str());
  if (doc.HasParseError() || !doc.IsObject() || !doc.HasMember("error")) return "<not an error>";
  return doc["error"]["code"].GetString();
}

std::string headerOf(const api::Answer& answer, const std::string& name) {
  for (const auto& [n, v] : answer.headers) {
    if (n == name) return v;
  }
  return "";
}

PoolOptions options(int workers, size_t queueDepth, std::chrono::milliseconds timeout = 30s) {
  PoolOptions o;
  o.workers = workers;
  o.queueDepth = queueDepth;
  o.timeout = timeout;
  return o;
}

api::Answer ok(const char* body = "{}") {
  api::Answer a;
  a.body = body;
  return a;
}

// A job that works for `duration` unless its token is cancelled first (it checks every ms).
WorkerPool::Work sleepJob(std::chrono::milliseconds duration) {
  return [duration](RenderContext&, const CancelToken& cancel) {
    const auto until = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < until && !cancel.expired()) {
      std::this_thread::sleep_for(1ms);
    }
    return ok();
  };
}

// The request log writes one parseable JSON object per line, with the fields a log shipper
// expects, errors at level error, and nothing below its level.
TEST(RequestLog, OneJsonObjectPerAnsweredRequest) {
  std::ostringstream text;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(text);
  RequestLog log("info", sink);
  uint64_t first = log.nextId(), second = log.nextId();
  EXPECT_EQ(second, first + 1);
  const std::vector<api::StageTime> stages = {{"surface", 0.4}, {"raster", 5.0}};
  log.answered({first, "POST", "/v1/render", 200, 0.0123, 512, 20060, &stages});
  log.answered({second, "GET", "other", 503, 0.001, 0, 90, nullptr});
  std::istringstream lines(text.str());
  std::vector<rapidjson::Document> docs;
  for (std::string line; std::getline(lines, line);) {
    docs.emplace_back();
    docs.back().Parse(line.c_str());
    ASSERT_FALSE(docs.back().HasParseError()) << line;
  }
  ASSERT_EQ(docs.size(), 2u);
  EXPECT_EQ(docs[0]["id"].GetUint64(), first);
  EXPECT_STREQ(docs[0]["level"].GetString(), "info");
  EXPECT_STREQ(docs[0]["route"].GetString(), "/v1/render");
  EXPECT_EQ(docs[0]["status"].GetInt(), 200);
  EXPECT_NEAR(docs[0]["ms"].GetDouble(), 12.3, 1e-9);
  EXPECT_EQ(docs[0]["out"].GetInt(), 20060);
  EXPECT_DOUBLE_EQ(docs[0]["stages"]["rasterMs"].GetDouble(), 5.0);
  EXPECT_EQ(std::string(docs[0]["ts"].GetString()).back(), 'Z');
  EXPECT_STREQ(docs[1]["level"].GetString(), "error");
  EXPECT_FALSE(docs[1].HasMember("stages"));

  std::ostringstream quiet;
  RequestLog errorsOnly("error", std::make_shared<spdlog::sinks::ostream_sink_mt>(quiet));
  errorsOnly.answered({1, "GET", "/healthz", 200, 0.001, 0, 10, nullptr});
  EXPECT_TRUE(quiet.str().empty());
  EXPECT_THROW(RequestLog("loud"), std::invalid_argument);
}

TEST(WorkerPool, RunsJobsOnWorkersThatOwnARasterizer) {
  WorkerPool pool(options(2, 4));
  ASSERT_EQ(pool.snapshot().readyWorkers, 2) << pool.workerStatus()[0].error;
  EXPECT_FALSE(pool.workerStatus()[0].device.renderer.empty());

  Captured captured;
  std::thread::id caller = std::this_thread::get_id();
  pool.submitInServer(
      [caller](RenderContext& context, const CancelToken&) {
        EXPECT_NE(context.rasterizer, nullptr);
        EXPECT_NE(std::this_thread::get_id(), caller);
        return ok("{\"done\":true}");
      },
      captured.reply());
  api::Answer answer = captured.wait();
  EXPECT_EQ(answer.status, 200);
  EXPECT_EQ(answer.body, "{\"done\":true}");
  std::this_thread::sleep_for(20ms);
  EXPECT_EQ(captured.calls, 1);
  EXPECT_EQ(pool.snapshot().renderCount, 1u);
}

TEST(WorkerPool, FullQueueAnswers429WithRetryAfterAtOnce) {
  WorkerPool pool(options(1, 1));
  Gate gate;
  auto blocked = [&gate](RenderContext&, const CancelToken&) {
    gate.wait();
    return ok();
  };
  Captured running, queued, refused;
  pool.submitInServer(blocked, running.reply());
  // Wait until the worker has taken the first job, so the second one is the one waiting.
  for (int i = 0; i < 500 && pool.snapshot().busyWorkers == 0; ++i)
    std::this_thread::sleep_for(2ms);
  pool.submitInServer(blocked, queued.reply());
  pool.submitInServer(blocked, refused.reply());

  api::Answer answer = refused.wait(1s);
  EXPECT_EQ(answer.status, 429);
  EXPECT_EQ(errorCode(answer), "busy");
  EXPECT_FALSE(headerOf(answer, "Retry-After").empty());
  EXPECT_EQ(pool.snapshot().queued, 1u);

  gate.open();
  EXPECT_EQ(running.wait().status, 200);
  EXPECT_EQ(queued.wait().status, 200);
}

TEST(WorkerPool, DeadlineAnswers504WhileTheWorkerIsStillBusyAndCancelsIt) {
  WorkerPool pool(options(1, 4, 100ms));
  std::atomic<bool> sawCancel{false};
  std::atomic<bool> workReturned{false};
  Captured captured;
  auto start = std::chrono::steady_clock::now();
  pool.submitInServer(
      [&](RenderContext&, const CancelToken& cancel) {
        // A render that would run for 10 s unless it notices its token.
        auto until = std::chrono::steady_clock::now() + 10s;
        while (std::chrono::steady_clock::now() < until && !cancel.expired()) {
          std::this_thread::sleep_for(1ms);
        }
        sawCancel = cancel.expired();
        std::this_thread::sleep_for(200ms);  // still busy after the deadline
        workReturned = true;
        return ok();
      },
      captured.reply());
  api::Answer answer = captured.wait(5s);
  auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(answer.status, 504);
  EXPECT_EQ(errorCode(answer), "timeout");
  EXPECT_FALSE(workReturned) << "the 504 must not wait for the worker";
  EXPECT_LT(elapsed, 2s);
  for (int i = 0; i < 500 && !workReturned; ++i) std::this_thread::sleep_for(2ms);
  EXPECT_TRUE(sawCancel);
  EXPECT_EQ(captured.calls, 1) << "the worker's late answer must be dropped";
}

TEST(WorkerPool, JobsStillQueuedAtTheirDeadlineAreDroppedWith504) {
  WorkerPool pool(options(1, 4, 100ms));
  Gate gate;
  std::atomic<bool> secondRan{false};
  Captured first, second;
  pool.submitInServer(
      [&gate](RenderContext&, const CancelToken&) {
        gate.wait();
        return ok();
      },
      first.reply());
  pool.submitInServer(
      [&secondRan](RenderContext&, const CancelToken&) {
        secondRan = true;
        return ok();
      },
      second.reply());
  EXPECT_EQ(second.wait(5s).status, 504);
  EXPECT_EQ(pool.snapshot().queued, 0u);
  gate.open();
  EXPECT_EQ(first.wait().status, 504);
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(secondRan);
}

TEST(WorkerPool, StopAnswers503ToQueuedAndRunningJobsAndCancelsTheRunningOnes) {
  WorkerPool pool(options(1, 4));
  std::atomic<bool> runningCancelled{false};
  Captured running, queued, late;
  pool.submitInServer(
      [&](RenderContext&, const CancelToken& cancel) {
        while (!cancel.expired()) std::this_thread::sleep_for(1ms);
        runningCancelled = true;
        return ok();
      },
      running.reply());
  for (int i = 0; i < 500 && pool.snapshot().busyWorkers == 0; ++i)
    std::this_thread::sleep_for(2ms);
  pool.submitInServer([](RenderContext&, const CancelToken&) { return ok(); }, queued.reply());

  pool.stop();
  EXPECT_EQ(running.wait(1s).status, 503);
  api::Answer dropped = queued.wait(1s);
  EXPECT_EQ(dropped.status, 503);
  EXPECT_EQ(errorCode(dropped), "unavailable");
  pool.submitInServer([](RenderContext&, const CancelToken&) { return ok(); }, late.reply());
  api::Answer refused = late.wait(1s);
  EXPECT_EQ(refused.status, 503);
  EXPECT_EQ(errorCode(refused), "unavailable");
  pool.join();
  EXPECT_TRUE(runningCancelled);
}

TEST(WorkerPool, AThrowingJobBecomes500) {
  WorkerPool pool(options(1, 1));
  Captured captured;
  pool.submitInServer(
      [](RenderContext&, const CancelToken&) -> api::Answer { throw std::runtime_error("boom"); },
      captured.reply());
  api::Answer answer = captured.wait();
  EXPECT_EQ(answer.status, 500);
  EXPECT_EQ(errorCode(answer), "internal");
}

// ---- Router ----

api::Answer route(Router& router, const std::string& method, const std::string& target,
                  const std::string& body = "") {
  Captured captured;
  router.handle({method, target, body}, captured.reply());
  return captured.wait(60s);
}

class RouterTest : public ::testing::Test {
 protected:
  WorkerPool pool{options(1, 2)};
  ServiceMetrics metrics;
  Router router{render::pipeline::JobLimits{}, pool, metrics};
};

TEST_F(RouterTest, UnknownPathIs404Json) {
  api::Answer answer = route(router, "GET", "/nope");
  EXPECT_EQ(answer.status, 404);
  EXPECT_EQ(answer.contentType, "application/json");
  EXPECT_EQ(errorCode(answer), "not_found");
}

TEST_F(RouterTest, WrongMethodIs405WithAllow) {
  api::Answer answer = route(router, "GET", "/v1/render");
  EXPECT_EQ(answer.status, 405);
  EXPECT_EQ(errorCode(answer), "method_not_allowed");
  EXPECT_EQ(headerOf(answer, "Allow"), "POST");
  EXPECT_EQ(headerOf(route(router, "DELETE", "/healthz"), "Allow"), "GET");
}

TEST_F(RouterTest, HealthzDescribesTheWorkers) {
  api::Answer answer = route(router, "GET", "/healthz?verbose=1");
  ASSERT_EQ(answer.status, 200);
  rapidjson::Document doc;
  doc.Parse(answer.body.c_str());
  ASSERT_FALSE(doc.HasParseError()) << answer.body;
  EXPECT_STREQ(doc["status"].GetString(), "ok");
  EXPECT_EQ(doc["workers"].GetInt(), 1);
  EXPECT_EQ(doc["queueCapacity"].GetInt(), 2);
  EXPECT_EQ(doc["queueDepth"].GetInt(), 0);
  EXPECT_GT(std::string(doc["renderer"].GetString()).size(), 0u);
  EXPECT_TRUE(doc["version"].IsString());
  EXPECT_TRUE(doc["uptimeS"].IsNumber());
}

TEST_F(RouterTest, ReadyzFollowsThePool) {
  EXPECT_EQ(route(router, "GET", "/readyz").status, 200);
  pool.stop();
  api::Answer answer = route(router, "GET", "/readyz");
  EXPECT_EQ(answer.status, 503);
  EXPECT_NE(answer.body.find("\"ready\":false"), std::string::npos);
}

TEST_F(RouterTest, MetricsCountAnswersByRouteAndStatus) {
  router.metrics().answered(Router::routeLabel("/healthz"), 200, 0.5);
  router.metrics().answered(Router::routeLabel("/healthz"), 200, 0.25);
  router.metrics().answered(Router::routeLabel("/wp-admin.php"), 404, 0.001);
  api::Answer answer = route(router, "GET", "/metrics");
  ASSERT_EQ(answer.status, 200);
  EXPECT_EQ(answer.contentType.rfind("text/plain", 0), 0u);
  const std::string& text = answer.body;
  EXPECT_NE(text.find("limn_requests_total{path=\"/healthz\",status=\"200\"} 2\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("limn_requests_total{path=\"other\",status=\"404\"} 1\n"), std::string::npos);
  // Cumulative buckets: 0.25 is in le="0.25" and above, 0.5 from le="0.5".
  const std::string healthz = "path=\"/healthz\",status=\"200\"";
  EXPECT_NE(text.find("limn_request_duration_seconds_bucket{" + healthz + ",le=\"0.1\"} 0\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("limn_request_duration_seconds_bucket{" + healthz + ",le=\"0.25\"} 1\n"),
            std::string::npos);
  EXPECT_NE(text.find("limn_request_duration_seconds_bucket{" + healthz + ",le=\"0.5\"} 2\n"),
            std::string::npos);
  EXPECT_NE(text.find("limn_request_duration_seconds_bucket{" + healthz + ",le=\"+Inf\"} 2\n"),
            std::string::npos);
  EXPECT_NE(text.find("limn_request_duration_seconds_sum{" + healthz + "} 0.75\n"),
            std::string::npos);
  EXPECT_NE(text.find("limn_request_duration_seconds_count{" + healthz + "} 2\n"),
            std::string::npos);
  EXPECT_NE(text.find("limn_queue_depth 0\n"), std::string::npos);
  EXPECT_NE(text.find("limn_workers_busy 0\n"), std::string::npos);
  EXPECT_EQ(text.find("wp-admin"), std::string::npos) << "unknown paths are folded into other";
}

TEST_F(RouterTest, OpenApiIsServed) {
  api::Answer answer = route(router, "GET", "/openapi.json");
  ASSERT_EQ(answer.status, 200);
  rapidjson::Document doc;
  doc.Parse(answer.body.c_str());
  ASSERT_FALSE(doc.HasParseError());
  EXPECT_TRUE(doc.HasMember("openapi"));
}

TEST_F(RouterTest, RenderRunsOnTheWorkerPool) {
  const std::string body = R"({
    "mesh": {"format": "obj", "data": "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n"},
    "camera": {"width": 32, "height": 32},
    "method": "coarse",
    "outputs": ["color"]
  })";
  api::Answer answer = route(router, "POST", "/v1/render", body);
  EXPECT_EQ(answer.status, 200) << answer.body.substr(0, 300);
  EXPECT_EQ(pool.snapshot().renderCount, 1u);

  api::Answer bad = route(router, "POST", "/v1/render", "{not json");
  EXPECT_EQ(bad.status, 400);
  EXPECT_EQ(errorCode(bad), "invalid_json");
}

// ---- HttpServer in process, for the limits the process tests cannot wait for ----

TEST(HttpServer, SlowRequestsGet408AndIdleConnectionsAreClosed) {
  WorkerPool pool(options(1, 2));
  ServiceMetrics metrics;
  Router router(render::pipeline::JobLimits{}, pool, metrics);
  HttpOptions http;
  http.port = 0;
  http.readTimeout = 300ms;
  HttpServer server(http, router, pool);
  std::thread serving([&server] { server.run(); });

  {
    // Slowloris: a header that never ends.
    limn::testing::HttpClient slow(server.port());
    slow.send("GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: ");
    auto start = std::chrono::steady_clock::now();
    limn::testing::HttpResponse r = slow.readResponse();
    EXPECT_EQ(r.status, 408);
    EXPECT_NE(r.body.find("\"code\":\"timeout\""), std::string::npos) << r.body;
    EXPECT_GE(std::chrono::steady_clock::now() - start, 250ms);
    EXPECT_TRUE(slow.peerClosed());
  }
  // Trickled byte by byte, a header or a body still gets 408 at readTimeout from its start:
  // the timer is not re-armed per byte, and no worker is held while it arrives.
  for (std::string request :
       {std::string("GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: abcdefghijklmnopqrstuvwxyz"),
        std::string("POST /v1/render HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\n") +
            std::string(100, ' ')}) {
    limn::testing::HttpClient slow(server.port());
    const size_t body = request.find("\r\n\r\n");
    const size_t trickleFrom = body == std::string::npos ? 20 : body + 4;
    slow.send(request.substr(0, trickleFrom));
    auto start = std::chrono::steady_clock::now();
    std::atomic<bool> answered{false};
    std::thread trickle([&] {
      for (size_t i = trickleFrom; i < request.size() && !answered; ++i) {
        try {
          slow.send(request.substr(i, 1));
        } catch (const std::exception&) {
          return;  // closed by the server after its 408
        }
        EXPECT_EQ(pool.snapshot().busyWorkers, 0);
        std::this_thread::sleep_for(20ms);
      }
    });
    limn::testing::HttpResponse r = slow.readResponse();
    answered = true;
    trickle.join();
    EXPECT_EQ(r.status, 408) << request.substr(0, 20);
    EXPECT_LT(std::chrono::steady_clock::now() - start, 1500ms);
  }
  {
    // A keep-alive connection that stays idle after its answer is closed without a word.
    limn::testing::HttpClient idle(server.port());
    EXPECT_EQ(idle.request("GET", "/readyz").status, 200);
    EXPECT_FALSE(idle.peerClosed(100ms));
    EXPECT_TRUE(idle.peerClosed(2000ms));
  }
  server.stop();
  serving.join();
}

// Shutdown drains: jobs already running finish within the drain time, new ones get 503, and
// after the drain deadline what is left is answered 503 and cancelled.
TEST(WorkerPool, DrainLetsRunningJobsFinishThenStopCancelsTheRest) {
  WorkerPool pool(options(1, 4));
  Captured quick, slow, late;
  pool.submitInServer(sleepJob(200ms), quick.reply());
  std::this_thread::sleep_for(50ms);  // the quick job is running
  pool.submitInServer(sleepJob(10s), slow.reply());
  auto start = std::chrono::steady_clock::now();
  std::thread draining([&] { EXPECT_FALSE(pool.drain(start + 600ms)); });
  std::this_thread::sleep_for(50ms);
  pool.submitInServer(sleepJob(1ms), late.reply());
  EXPECT_EQ(late.wait(1s).status, 503) << "no new jobs while draining";
  EXPECT_EQ(quick.wait(2s).status, 200) << "a job that fits the drain finishes";
  draining.join();
  EXPECT_GE(std::chrono::steady_clock::now() - start, 550ms);
  pool.stop();
  EXPECT_EQ(slow.wait(2s).status, 503);
  EXPECT_TRUE(pool.joinFor(2s)) << "the cancelled job stops at its next check";
}

// A job that never looks at its token cannot hold the process: joinFor() gives up.
TEST(WorkerPool, JoinForGivesUpOnAWorkerThatIgnoresItsCancellation) {
  auto pool = std::make_unique<WorkerPool>(options(1, 1));
  std::atomic<bool> release{false};
  Captured stuck;
  pool->submitInServer(
      [&release](render::pipeline::RenderContext&, const render::CancelToken&) {
        while (!release) std::this_thread::sleep_for(5ms);
        return api::Answer{};
      },
      stuck.reply());
  std::this_thread::sleep_for(50ms);
  pool->stop();
  EXPECT_EQ(stuck.wait(1s).status, 503);
  auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(pool->joinFor(300ms));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 1s);
  release = true;  // let the thread end so that the test can join it
  EXPECT_TRUE(pool->joinFor(2s));
}

}  // namespace
}  // namespace limn::server
