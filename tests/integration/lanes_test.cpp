// Lanes and admission through the real server (issue 25), asserting what holds at any machine
// speed: a small request is answered while a heavy one that started before it still runs (the
// heavy one is kept long by its size); a heavy request over the heavy lane's budget is refused
// 429 with Retry-After while a small one is taken; a client flooding the queue gets its own
// 429s while another client's request passes; a background request (Priority: u=7) waits for
// the others; /metrics reports the lanes.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/integration/http_client.h"
#include "tests/integration/json_answer.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const char* kCubeObj =
    "v -1 -1 1\\nv 1 -1 1\\nv -1 1 1\\nv 1 1 1\\nv -1 1 -1\\nv 1 1 -1\\nv -1 -1 -1\\nv 1 -1 -1\\n"
    "f 1 2 4 3\\nf 3 4 6 5\\nf 5 6 8 7\\nf 7 8 2 1\\nf 2 8 6 4\\nf 7 1 3 5\\n";

// A quick preview: the cube at 64 px, colour only.
std::string smallBody() {
  return std::string(R"({"mesh": {"format": "obj", "data": ")") + kCubeObj +
         R"("}, "camera": {"width": 64, "height": 64}, "method": "coarse", "outputs": ["color"]})";
}

// Hundreds of milliseconds (interactive under a raised heavyRequestMs): answers one after
// another are told apart by the client's clock even on a loaded machine, where reading an
// answer can lag its writing by tens of milliseconds.
std::string previewBody() {
  return std::string(R"({"mesh": {"format": "obj", "data": ")") + kCubeObj +
         R"("}, "camera": {"width": 1536, "height": 1536}, "method": "uniform",)"
         R"( "params": {"level": 4}, "outputs": ["color", "normal", "depth"]})";
}

// Seconds of work on any machine: the cube refined to level 5 at 2048 px with the reference
// and its metrics at 4x4 supersampling.
std::string heavyBody() {
  return std::string(R"({"mesh": {"format": "obj", "data": ")") + kCubeObj +
         R"("}, "camera": {"width": 2048, "height": 2048}, "method": "uniform",)"
         R"( "params": {"level": 5}, "reference": true, "outputs": ["color"]})";
}

struct Timed {
  HttpResponse response;
  Clock::time_point done;
};

std::future<Timed> postAsync(int port, std::string body, Headers headers = {}) {
  return std::async(std::launch::async, [=] {
    HttpResponse r = post(port, "/v1/render", body, headers);
    return Timed{r, Clock::now()};
  });
}

// A value of the /metrics text ("name{labels} value"), or -1.
double metric(int port, const std::string& series) {
  const std::string body = get(port, "/metrics").body;
  const size_t at = body.find("\n" + series + " ");
  return at == std::string::npos ? -1 : std::stod(body.substr(at + series.size() + 2));
}

// Waits until /metrics shows `series` at `value` or more (120 s at most).
bool waitForMetric(int port, const std::string& series, double value) {
  const auto deadline = Clock::now() + 120s;
  while (Clock::now() < deadline) {
    if (metric(port, series) >= value) return true;
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

TEST(Lanes, ASmallRequestIsAnsweredWhileAHeavyOneThatStartedFirstStillRuns) {
  ServerProcess server = ServerProcess::withConfig(R"({"workers": 2})");
  const int port = server.port();
  std::future<Timed> heavy = postAsync(port, heavyBody());
  ASSERT_TRUE(waitForMetric(port, "limn_lane_running{lane=\"heavy\"}", 1));
  // A second heavy request waits (heavy work has one of the two workers), a small one does not.
  std::future<Timed> second = postAsync(port, heavyBody());
  ASSERT_TRUE(waitForMetric(port, "limn_lane_queue_depth{lane=\"heavy\"}", 1));
  const auto sent = Clock::now();
  HttpResponse small = post(port, "/v1/render", smallBody());
  const auto answered = Clock::now();
  ASSERT_EQ(small.status, 200) << small.body.substr(0, 300);
  // Its answer says where its time went (W3C Server-Timing): the lane and the wait, the run,
  // the estimate.
  const std::string timing = small.header("Server-Timing");
  EXPECT_NE(timing.find("queue;dur="), std::string::npos) << timing;
  EXPECT_NE(timing.find("desc=\"interactive\""), std::string::npos) << timing;
  EXPECT_NE(timing.find("run;dur="), std::string::npos) << timing;
  EXPECT_NE(timing.find("estimate;dur="), std::string::npos) << timing;
  Timed first = heavy.get();
  EXPECT_NE(first.response.header("Server-Timing").find("desc=\"heavy\""), std::string::npos);
  ASSERT_EQ(first.response.status, 200) << first.response.body.substr(0, 300);
  EXPECT_LT(answered, first.done) << "the small request waited for the heavy one";
  EXPECT_EQ(second.get().response.status, 200);
  std::printf("small request: %.0f ms while the heavy ones ran\n",
              std::chrono::duration<double, std::milli>(answered - sent).count());
  EXPECT_GE(metric(port, "limn_admissions_total{lane=\"heavy\"}"), 2);
  EXPECT_GE(metric(port, "limn_admissions_total{lane=\"interactive\"}"), 1);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(Lanes, AHeavyRequestOverTheHeavyBudgetIs429WhileASmallOneIsTaken) {
  // Any heavy work waiting fills a budget of 1 ms.
  ServerProcess server = ServerProcess::withConfig(R"({"workers": 2, "heavyQueueMs": 1})");
  const int port = server.port();
  std::future<Timed> running = postAsync(port, heavyBody());
  ASSERT_TRUE(waitForMetric(port, "limn_lane_running{lane=\"heavy\"}", 1));
  std::future<Timed> waiting = postAsync(port, heavyBody());
  ASSERT_TRUE(waitForMetric(port, "limn_lane_queue_depth{lane=\"heavy\"}", 1));
  HttpResponse refused = post(port, "/v1/render", heavyBody());
  EXPECT_EQ(refused.status, 429) << refused.body.substr(0, 300);
  ASSERT_TRUE(refused.has("Retry-After"));
  const int retryAfter = std::stoi(refused.header("Retry-After"));
  EXPECT_GE(retryAfter, 1);
  EXPECT_LE(retryAfter, 60);
  auto doc = parseJson(refused.body);
  EXPECT_STREQ(doc["error"]["code"].GetString(), "busy");
  EXPECT_STREQ(doc["error"]["detail"]["limit"].GetString(), "heavyQueueMs");
  EXPECT_EQ(post(port, "/v1/render", smallBody()).status, 200);
  EXPECT_EQ(running.get().response.status, 200);
  EXPECT_EQ(waiting.get().response.status, 200);
  EXPECT_EQ(metric(port, "limn_admission_refusals_total{reason=\"heavy\"}"), 1);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(Lanes, AFloodingClientGetsIts429sWhileAnotherClientsRequestPasses) {
  // One worker, no reserve; a client may have 2 requests waiting; the previews are interactive.
  ServerProcess server = ServerProcess::withConfig(
      R"({"workers": 1, "reservedInteractiveWorkers": 0, "clientQueueDepth": 2,
          "heavyRequestMs": 2000})");
  const int port = server.port();
  const Headers flooder{{"Authorization", "Bearer flooder"}};
  const Headers other{{"Authorization", "Bearer other"}};
  std::future<Timed> busy = postAsync(port, heavyBody(), flooder);
  ASSERT_TRUE(waitForMetric(port, "limn_lane_running{lane=\"heavy\"}", 1));
  std::vector<std::future<Timed>> queued;
  for (int i = 0; i < 2; ++i) queued.push_back(postAsync(port, previewBody(), flooder));
  ASSERT_TRUE(waitForMetric(port, "limn_lane_queue_depth{lane=\"interactive\"}", 2));
  HttpResponse third = post(port, "/v1/render", smallBody(), flooder);
  EXPECT_EQ(third.status, 429) << third.body.substr(0, 300);
  EXPECT_TRUE(third.has("Retry-After"));
  EXPECT_STREQ(parseJson(third.body)["error"]["detail"]["limit"].GetString(), "clientQueueDepth");
  // The other client's request is taken, and served before the flooder's second one.
  std::future<Timed> theirs = postAsync(port, previewBody(), other);
  Timed mine = theirs.get();
  EXPECT_EQ(mine.response.status, 200);
  Timed firstQueued = queued[0].get(), secondQueued = queued[1].get();
  EXPECT_EQ(firstQueued.response.status, 200);
  EXPECT_EQ(secondQueued.response.status, 200);
  // (The two were sent at once: either may have arrived first.)
  EXPECT_LE(mine.done, std::max(firstQueued.done, secondQueued.done)) << "clients take turns";
  EXPECT_EQ(busy.get().response.status, 200);
  EXPECT_EQ(metric(port, "limn_admission_refusals_total{reason=\"client\"}"), 1);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

// The nice value of a process's main thread (/proc/PID/stat, field 19).
int niceOf(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), {});
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));  // after "pid (comm) "
  std::string field;
  for (int i = 3; i <= 19 && fields >> field; ++i) {
    if (i == 19) return std::stoi(field);
  }
  return -100;
}

TEST(Lanes, TheWorkerHeavyWorkRunsOnYieldsTheCpuToTheInteractiveOne) {
  ServerProcess server = ServerProcess::withConfig(R"({"workers": 2, "heavyWorkerNice": 7})");
  auto health = parseJson(get(server.port(), "/healthz").body);
  const auto& workers = health["workerStates"];
  ASSERT_EQ(workers.Size(), 2u);
  EXPECT_EQ(niceOf(workers[0]["pid"].GetInt()), 7) << "the worker heavy work may use";
  EXPECT_EQ(niceOf(workers[1]["pid"].GetInt()), niceOf(server.pid())) << "the reserved worker";
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(Lanes, BackgroundRequestsWaitForTheOthers) {
  // Previews, not tiny renders: two answers written a millisecond apart can be read by the
  // client in either order, so the one that runs second must finish well after the first.
  ServerProcess server = ServerProcess::withConfig(R"({"workers": 1, "heavyRequestMs": 2000})");
  const int port = server.port();
  std::future<Timed> busy = postAsync(port, heavyBody());
  ASSERT_TRUE(waitForMetric(port, "limn_lane_running{lane=\"heavy\"}", 1));
  std::future<Timed> background =
      postAsync(port, previewBody(), {{"Priority", "u=7"}, {"Authorization", "Bearer b"}});
  ASSERT_TRUE(waitForMetric(port, "limn_lane_queue_depth{lane=\"batch\"}", 1));
  std::future<Timed> interactive = postAsync(port, previewBody(), {{"Authorization", "Bearer i"}});
  ASSERT_TRUE(waitForMetric(port, "limn_lane_queue_depth{lane=\"interactive\"}", 1));
  Timed b = background.get(), i = interactive.get();
  EXPECT_EQ(b.response.status, 200);
  EXPECT_EQ(i.response.status, 200);
  EXPECT_LE(i.done, b.done) << "the background request went first";
  EXPECT_EQ(busy.get().response.status, 200);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

}  // namespace
}  // namespace limn::testing
