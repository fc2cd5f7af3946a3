// Render workers as supervised processes, through the real server: a worker that dies (a signal,
// its memory ceiling) costs the request it held and nothing else — concurrent requests and a
// running job finish, the worker is replaced within seconds, /metrics counts it — and the mesh
// that used to take the whole server down (OpenSubdiv's limit masks on an edge shared by 100
// quads) renders.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
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

// `quads` quads around one edge (from (0,0,0) to (0,1,0)), like OpenSubdiv's regression shape
// catmark_nonman_edge100: one non-manifold edge shared by every face. JSON-escaped newlines.
std::string edgeFanObj(int quads) {
  std::string obj = "v 0 0 0\\nv 0 1 0\\n";
  for (int i = 0; i < quads; ++i) {
    const double a = 2 * M_PI * i / quads;
    const std::string x = std::to_string(std::cos(a)), z = std::to_string(std::sin(a));
    obj += "v " + x + " 0 " + z + "\\nv " + x + " 1 " + z + "\\n";
  }
  for (int i = 0; i < quads; ++i) {
    const int b = 3 + 2 * i;
    obj += "f 1 " + std::to_string(b) + " " + std::to_string(b + 1) + " 2\\n";
  }
  return obj;
}

const char* kCubeObj =
    "v -1 -1 1\\nv 1 -1 1\\nv -1 1 1\\nv 1 1 1\\nv -1 1 -1\\nv 1 1 -1\\nv -1 -1 -1\\nv 1 -1 -1\\n"
    "f 1 2 4 3\\nf 3 4 6 5\\nf 5 6 8 7\\nf 7 8 2 1\\nf 2 8 6 4\\nf 7 1 3 5\\n";

std::string meshBody(const std::string& obj, const std::string& method, int size,
                     const std::string& extra = "") {
  return R"({"mesh": {"format": "obj", "data": ")" + obj + R"("}, "camera": {"width": )" +
         std::to_string(size) + ", \"height\": " + std::to_string(size) + R"(}, "method": ")" +
         method + "\"" + extra + "}";
}

std::string errorCode(const HttpResponse& r) {
  auto doc = parseJson(r.body);
  if (doc.HasParseError() || !doc.IsObject() || !doc.HasMember("error")) return "<not JSON>";
  return doc["error"]["code"].GetString();
}

rapidjson::Document health(int port) { return parseJson(get(port, "/healthz").body); }

// The value of one sample in /metrics (0 when the series is absent).
double metric(int port, const std::string& series) {
  const std::string text = get(port, "/metrics").body;
  const size_t at = text.find("\n" + series + " ");
  if (at == std::string::npos) return 0;
  return std::stod(text.substr(at + series.size() + 2));
}

// Until the server's spare worker (the next replacement) has started: a GL context's time.
bool spareReady(int port) {
  for (int i = 0; i < 3000 && !health(port)["spareWorkerReady"].GetBool(); ++i) {
    std::this_thread::sleep_for(10ms);
  }
  return health(port)["spareWorkerReady"].GetBool();
}

// Until every worker is ready again; how long that took (or `limit` when it did not happen).
Clock::duration waitAllReady(int port, Clock::duration limit) {
  const auto start = Clock::now();
  while (Clock::now() - start < limit) {
    auto h = health(port);
    if (h["readyWorkers"].GetInt() == h["workers"].GetInt()) return Clock::now() - start;
    std::this_thread::sleep_for(10ms);
  }
  return limit;
}

TEST(WorkerIsolation, UniformRefinementOfAnEdgeSharedByAHundredQuadsRenders) {
  ServerProcess server;
  const std::string fan = edgeFanObj(100);
  for (int level : {1, 3}) {
    const std::string params =
        R"(, "reference": true, "params": {"level": )" + std::to_string(level) + "}";
    HttpResponse r = post(server.port(), "/v1/render", meshBody(fan, "uniform", 128, params));
    ASSERT_EQ(r.status, 200) << "level " << level << ": " << r.body.substr(0, 300);
    auto answer = parseJson(r.body);
    // 100 quads, 4^level quads each, 2 triangles per quad.
    EXPECT_EQ(answer["stats"]["triangles"].GetInt(), 200 * static_cast<int>(std::pow(4, level)));
    // The fins' limit (the reference's picture) is approached as uniform refinement does on
    // any open mesh: level 3 is within a pixel at this size.
    if (level == 3) {
      EXPECT_LT(answer["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble(), 1.0);
    }
    HttpResponse mesh = post(server.port(), "/v1/tessellate",
                             meshBody(fan, "uniform", 128, R"(, "params": {"level": 2})"),
                             {{"Accept", "application/x-ply"}});
    EXPECT_EQ(mesh.status, 200) << mesh.body.substr(0, 300);
  }
  auto h = health(server.port());
  EXPECT_EQ(h["workerCrashes"].GetInt(), 0);
  for (const auto& w : h["workerStates"].GetArray()) EXPECT_EQ(w["starts"].GetInt(), 1);
}

// An implicit scene heavy enough to be caught running; rendered again until it is.
std::string heavyImplicit() {
  return R"({"field": {"iso": 0.5, "primitives": [
      {"type": "metaball", "center": [0, 0, 0], "radius": 1.0},
      {"type": "metaball", "center": [0.7, 0.2, 0], "radius": 0.8},
      {"type": "torus", "center": [0, 0, 0], "radius": 1.2, "tube": 0.3}]},
    "polygonizer": {"method": "marching-cubes", "resolution": 160},
    "camera": {"width": 1024, "height": 1024}, "reference": true})";
}

std::string jobSpec() {
  return R"({"meshes": [{"name": "cube", "mesh": {"format": "obj", "data": ")" +
         std::string(kCubeObj) +
         R"("}}], "methods": ["coarse", "uniform:1"], "cameras": [{"random": {"count": 6,
         "seed": 3}}], "size": 96})";
}

class KilledWorker : public ::testing::TestWithParam<int> {};

TEST_P(KilledWorker, CostsOnlyItsRequestAndIsReplaced) {
  const int signal = GetParam();
  const std::string signalName = signal == SIGKILL ? "SIGKILL" : "SIGSEGV";
  auto server = ServerProcess::withConfig(R"({"workers": 2, "queueDepth": 64})");
  const int port = server.port();

  // The server keeps a spare worker started to replace a lost one at once.
  ASSERT_TRUE(spareReady(port));

  HttpResponse created = post(port, "/v1/jobs", jobSpec());
  ASSERT_EQ(created.status, 202) << created.body.substr(0, 300);
  const std::string job = parseJson(created.body)["id"].GetString();

  // The victim: heavy implicit renders until one is caught running and its worker killed.
  std::atomic<bool> victimDone{false};
  HttpResponse victim;
  std::thread victimThread([&] {
    for (int attempt = 0; attempt < 30; ++attempt) {
      victim = post(port, "/v1/implicit", heavyImplicit());
      if (victim.status != 200) break;
    }
    victimDone = true;
  });
  // Bystanders: small renders all along.
  std::vector<int> bystanders;
  std::thread bystanderThread([&] {
    while (!victimDone) {
      bystanders.push_back(post(port, "/v1/render", meshBody(kCubeObj, "adaptive", 96)).status);
    }
  });

  int killedPid = 0;
  uint64_t killedRequest = 0;
  const auto giveUp = Clock::now() + 120s;
  while (!killedPid && !victimDone && Clock::now() < giveUp) {
    auto h = health(port);
    for (const auto& w : h["workerStates"].GetArray()) {
      if (std::string(w["state"].GetString()) == "busy" &&
          std::string(w["endpoint"].GetString()) == "/v1/implicit") {
        killedPid = w["pid"].GetInt();
        killedRequest = w["requestId"].GetUint64();
        break;
      }
    }
    if (!killedPid) std::this_thread::sleep_for(2ms);
  }
  ASSERT_NE(killedPid, 0) << "no implicit render was seen running";
  ASSERT_EQ(::kill(killedPid, signal), 0);
  const auto killedAt = Clock::now();
  // The server learns of the death when the kernel has torn the process down (its socket
  // closes): milliseconds on a quiet machine, seconds on a loaded one. From then on the
  // replacement is the server's own work.
  while (!victimDone) std::this_thread::sleep_for(1ms);
  const auto teardown = Clock::now() - killedAt;
  const auto readyAfter = waitAllReady(port, 10s);
  victimThread.join();
  bystanderThread.join();

  EXPECT_EQ(victim.status, 500) << victim.body.substr(0, 300);
  EXPECT_EQ(errorCode(victim), "worker_crashed");
  EXPECT_NE(victim.body.find(signalName), std::string::npos) << victim.body;
  auto error = parseJson(victim.body);
  EXPECT_EQ(error["error"]["detail"]["requestId"].GetUint64(), killedRequest);
  EXPECT_EQ(victim.header("X-Request-Id"), std::to_string(killedRequest));
  EXPECT_EQ(error["error"]["detail"]["pid"].GetInt(), killedPid);

  EXPECT_LT(readyAfter, 2s) << "the worker is replaced at once";
  EXPECT_LT(teardown, 10s);
  ASSERT_FALSE(bystanders.empty());
  for (int status : bystanders) EXPECT_EQ(status, 200);

  // The job's comparisons ran beside it and all finished.
  std::string state;
  for (int i = 0; i < 600; ++i) {
    auto j = parseJson(get(port, "/v1/jobs/" + job).body);
    state = j["state"].GetString();
    if (state != "queued" && state != "running") {
      EXPECT_EQ(j["progress"]["failed"].GetInt(), 0);
      break;
    }
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(state, "done");

  EXPECT_EQ(metric(port, "limn_worker_crashes_total{signal=\"" + signalName + "\"}"), 1);
  // Two workers, one replacement (plus the spare the server keeps started for the next one).
  EXPECT_GE(metric(port, "limn_worker_starts_total"), 3);
  auto h = health(port);
  int replacedSlots = 0;
  for (const auto& w : h["workerStates"].GetArray()) {
    replacedSlots += w["starts"].GetInt() == 2;
    EXPECT_NE(w["pid"].GetInt(), killedPid);
  }
  EXPECT_EQ(replacedSlots, 1);
  EXPECT_EQ(h["workerCrashes"].GetInt(), 1);
  EXPECT_STREQ(h["status"].GetString(), "ok");
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

INSTANTIATE_TEST_SUITE_P(Signals, KilledWorker, ::testing::Values(SIGKILL, SIGSEGV),
                         [](const auto& info) {
                           return info.param == SIGKILL ? "Sigkill" : "Sigsegv";
                         });

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LIMN_UNDER_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(LIMN_UNDER_ASAN)
constexpr bool kUnderAddressSanitizer = true;
#else
constexpr bool kUnderAddressSanitizer = false;
#endif

// The worker's memory ceiling: a render that grows past it is answered as its own crash;
// small renders next to it are not affected. The ceiling is set from the idle workers' own
// size, measured here, so that it holds on any machine.
TEST(WorkerIsolation, ARequestPastTheMemoryCeilingCostsOnlyItself) {
  size_t idleBytes = 0;
  {
    ServerProcess probe;
    const rapidjson::Document states = health(probe.port());  // outlives the loop over it
    for (const auto& w : states["workerStates"].GetArray()) {
      const int pid = w["pid"].GetInt();
      CommandResult statm = runCommand("cat /proc/" + std::to_string(pid) + "/statm");
      size_t pages = 0, resident = 0;
      ASSERT_EQ(std::sscanf(statm.output.c_str(), "%zu %zu", &pages, &resident), 2);
      idleBytes = std::max(idleBytes, resident * 4096);
    }
  }
  // Room for small renders (a few MB each), none for a 4096^2 reference with masks at S = 4
  // (over a gigabyte of passes and masks). Under AddressSanitizer every allocation is larger and
  // freed memory waits in its quarantine, so a small render there needs a few hundred MB.
  const size_t ceiling = idleBytes + (kUnderAddressSanitizer ? 640u << 20 : 192u << 20);
  auto server = ServerProcess::withConfig(R"({"workers": 2, "limits": {"maxWorkerMemoryBytes": )" +
                                          std::to_string(ceiling) + "}}");
  const int port = server.port();
  ASSERT_TRUE(spareReady(port));

  std::atomic<bool> bigDone{false};
  HttpResponse big;
  std::thread bigThread([&] {
    big = post(port, "/v1/render",
               meshBody(kCubeObj, "adaptive", 4096,
                        R"(, "reference": true, "outputs": ["color", "depth", "normal"])"));
    bigDone = true;
  });
  std::vector<int> small;
  while (!bigDone)
    small.push_back(post(port, "/v1/render", meshBody(kCubeObj, "coarse", 64)).status);
  bigThread.join();

  EXPECT_EQ(big.status, 500) << big.body.substr(0, 300);
  EXPECT_EQ(errorCode(big), "worker_crashed");
  EXPECT_NE(big.body.find("maxWorkerMemoryBytes"), std::string::npos) << big.body;
  for (int status : small) EXPECT_EQ(status, 200);
  EXPECT_LT(waitAllReady(port, 10s), 2s);
  EXPECT_EQ(post(port, "/v1/render", meshBody(kCubeObj, "adaptive", 256)).status, 200);
}

// Nothing to draw is an answer: a surface that does not exist is a 422 naming why, a camera
// that sees nothing is a 200 with empty pictures — never a 500, for any method.
TEST(EmptySurfaces, AreAnswersNotInternalErrors) {
  ServerProcess server;
  const int port = server.port();
  HttpResponse noField = post(port, "/v1/implicit", R"({"field": {"iso": 1e308, "primitives":
      [{"type": "blobby", "center": [0, 0, 0], "radius": 1}]}, "reference": true,
      "camera": {"width": 64, "height": 64}})");
  EXPECT_EQ(noField.status, 422) << noField.body;
  EXPECT_EQ(errorCode(noField), "empty_surface");
  EXPECT_NE(noField.body.find("field.iso"), std::string::npos);

  std::string allHoles = kCubeObj;
  for (int f = 0; f < 6; ++f) allHoles += "t hole 1/0/0 " + std::to_string(f) + "\\n";
  auto lookingAway = [](const char* method) {
    return R"({"mesh": {"format": "obj", "data": ")" + std::string(kCubeObj) +
           R"("}, "method": ")" + method + R"(", "reference": true, "camera": {"width": 64,
           "height": 64, "eye": [0, 0, 5], "target": [0, 0, 10]}})";
  };
  for (const char* method : {"coarse", "uniform", "adaptive", "silhouette", "patches", "limit"}) {
    HttpResponse holes = post(port, "/v1/render", meshBody(allHoles, method, 64));
    EXPECT_EQ(holes.status, 422) << method << ": " << holes.body;
    EXPECT_EQ(errorCode(holes), "empty_surface") << method;
    HttpResponse nothing = post(port, "/v1/render", lookingAway(method));
    ASSERT_EQ(nothing.status, 200) << method << ": " << nothing.body.substr(0, 300);
    auto answer = parseJson(nothing.body);
    if (std::string(method) == "limit") continue;  // the reference itself: nothing to measure
    EXPECT_EQ(answer["metrics"]["silhouette"]["iou"].GetDouble(), 1.0) << method;
  }
}

TEST(WorkerIsolation, ThreadWorkersRemainAnOptionForDebugging) {
  auto server = ServerProcess::withConfig(R"({"workers": 1, "workerIsolation": "thread"})");
  auto h = health(server.port());
  EXPECT_STREQ(h["workerIsolation"].GetString(), "thread");
  EXPECT_EQ(h["workerStates"][0]["pid"].GetInt(), 0);
  HttpResponse r = post(server.port(), "/v1/render", meshBody(kCubeObj, "adaptive", 64));
  EXPECT_EQ(r.status, 200) << r.body.substr(0, 300);
}

}  // namespace
}  // namespace limn::testing
