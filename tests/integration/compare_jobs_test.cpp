// POST /v1/compare and POST/GET/DELETE /v1/jobs through the real server: the reference is built
// once per camera (its time appears once, the reference cache sees one miss per camera), every
// row equals a separate /v1/render of the same method and camera, errors name the list entry,
// the row limit and the deadline hold; jobs run through the worker pool, report progress and
// partial rows, cancel, and are bounded; the real answers match the OpenAPI document.
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <set>
#include <string>
#include <thread>

#include "tests/integration/http_client.h"
#include "tests/integration/openapi_check.h"
#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

using Clock = std::chrono::steady_clock;

std::string jsonString(const std::string& text) {
  rapidjson::StringBuffer out;
  rapidjson::Writer<rapidjson::StringBuffer> writer(out);
  writer.String(text.c_str(), static_cast<rapidjson::SizeType>(text.size()));
  return out.GetString();
}

std::string text(const rapidjson::Value& value) {
  rapidjson::StringBuffer out;
  rapidjson::Writer<rapidjson::StringBuffer> writer(out);
  value.Accept(writer);
  return out.GetString();
}

rapidjson::Document parse(const std::string& body) {
  rapidjson::Document doc;
  doc.Parse(body.c_str());
  return doc;
}

std::string fieldOf(const HttpResponse& r) {
  rapidjson::Document d = parse(r.body);
  return d.HasMember("error") && d["error"]["detail"].HasMember("field")
             ? d["error"]["detail"]["field"].GetString()
             : "";
}

// A value of the /metrics text ("name{labels} value").
double metric(int port, const std::string& series) {
  const std::string body = get(port, "/metrics").body;
  const size_t at = body.find("\n" + series + " ");
  return at == std::string::npos ? NAN : std::stod(body.substr(at + series.size() + 2));
}

class CompareServer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A small triangle budget so that a row can fail on its own, a row limit and a deadline a
    // test can reach, and a small job table.
    server_ = new ServerProcess(ServerProcess::withConfig(
        R"({"workers": 2, "requestTimeoutMs": 8000, "jobRetentionSeconds": 600,
            "limits": {"maxTriangles": 150000, "maxCompareRows": 12, "maxJobs": 2,
                       "maxJobRows": 40}})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0);
    delete server_;
    server_ = nullptr;
  }
  static int port() { return server_->port(); }
  static std::string mesh(const std::string& example, const std::string& scheme = "catmull-clark") {
    HttpResponse r = get(port(), "/examples/" + example);
    EXPECT_EQ(r.status, 200);
    return R"({"format":"obj","scheme":")" + scheme + R"(","data":)" + jsonString(r.body) + "}";
  }
  static rapidjson::Document job(const std::string& id, const std::string& query = "") {
    HttpResponse r = get(port(), "/v1/jobs/" + id + query);
    EXPECT_EQ(r.status, 200) << r.body.substr(0, 300);
    return parse(r.body);
  }
  // Polls until the job has finished (or 120 s passed).
  static rapidjson::Document finished(const std::string& id) {
    const auto deadline = Clock::now() + std::chrono::seconds(120);
    for (;;) {
      rapidjson::Document d = job(id);
      const std::string state = d["state"].GetString();
      if (state != "queued" && state != "running") return d;
      if (Clock::now() > deadline) return d;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }

  static rapidjson::Document health() { return parse(get(port(), "/healthz").body); }
  // /healthz once every worker is ready and none is busy (or after 60 s).
  static rapidjson::Document wholePool() {
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    for (;;) {
      rapidjson::Document h = health();
      const bool whole =
          h["busyWorkers"].GetInt() == 0 && h["readyWorkers"].GetInt() == h["workers"].GetInt();
      if (whole || Clock::now() > deadline) return h;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  static ServerProcess* server_;
};
ServerProcess* CompareServer::server_ = nullptr;

const char* kCameras =
    R"([{"width":112,"height":112},
        {"orbit":{"azimuthDeg":40,"elevationDeg":25},"width":112,"height":112}])";
const char* kMethods[] = {R"({"method":"coarse"})", R"({"method":"uniform","params":{"level":2}})",
                          R"({"method":"adaptive","params":{"dicingRate":2}})",
                          R"({"method":"silhouette"})"};

TEST_F(CompareServer, BuildsTheReferenceOncePerCameraAndEveryRowEqualsItsOwnRender) {
  const std::string torus = mesh("torus_creased");
  std::string methods;
  for (const char* m : kMethods) methods += (methods.empty() ? "" : ",") + std::string(m);
  const double missesBefore = metric(port(), "limn_reference_cache_lookups_total{result=\"miss\"}");
  const double hitsBefore = metric(port(), "limn_reference_cache_lookups_total{result=\"hit\"}");
  HttpResponse r = post(
      port(), "/v1/compare",
      R"({"mesh":)" + torus + R"(,"cameras":)" + kCameras + R"(,"methods":[)" + methods + "]}");
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 500);
  rapidjson::Document table = parse(r.body);

  // Two cameras: two references, each timed once; the rows carry their own stages only.
  EXPECT_EQ(metric(port(), "limn_reference_cache_lookups_total{result=\"miss\"}") - missesBefore,
            2);
  EXPECT_EQ(metric(port(), "limn_reference_cache_lookups_total{result=\"hit\"}") - hitsBefore, 0);
  const auto& refs = table["reference"]["cameras"];
  ASSERT_EQ(refs.Size(), 2u);
  double sum = 0;
  for (const auto& ref : refs.GetArray()) {
    EXPECT_GT(ref["timings"]["referenceMs"].GetDouble(), 0);
    EXPECT_FALSE(ref["timings"]["referenceStages"]["sceneCached"].GetBool());
    sum += ref["timings"]["referenceMs"].GetDouble();
  }
  EXPECT_DOUBLE_EQ(table["reference"]["timings"]["referenceMs"].GetDouble(), sum);
  ASSERT_EQ(table["rows"].Size(), 8u);
  for (const auto& row : table["rows"].GetArray()) {
    std::set<std::string> stages;
    for (auto it = row["timings"].MemberBegin(); it != row["timings"].MemberEnd(); ++it) {
      stages.insert(it->name.GetString());
    }
    EXPECT_EQ(stages, (std::set<std::string>{"approxMs", "rasterMs", "metricsMs", "totalMs"}));
    EXPECT_NEAR(row["timings"]["totalMs"].GetDouble(),
                row["timings"]["approxMs"].GetDouble() + row["timings"]["rasterMs"].GetDouble() +
                    row["timings"]["metricsMs"].GetDouble(),
                1e-6);
  }

  // Each row against the same method and camera rendered alone (its reference now from the cache).
  rapidjson::Document cameras = parse(kCameras);
  for (const auto& row : table["rows"].GetArray()) {
    const int c = row["camera"].GetInt();
    const std::string method = row["method"].GetString();
    HttpResponse alone = post(port(), "/v1/render",
                              R"({"mesh":)" + torus + R"(,"camera":)" + text(cameras[c]) +
                                  R"(,"method":")" + method + R"(","params":)" +
                                  text(row["params"]) + R"(,"outputs":[],"reference":true})");
    ASSERT_EQ(alone.status, 200) << alone.body.substr(0, 300);
    rapidjson::Document a = parse(alone.body);
    const std::string what = method + " camera " + std::to_string(c);
    EXPECT_EQ(a["stats"]["triangles"].GetInt64(), row["stats"]["triangles"].GetInt64()) << what;
    const rapidjson::Value& metrics = a["metrics"];
    for (const auto& group : metrics.GetObject()) {
      const auto& mine = row["metrics"][group.name.GetString()];
      for (const auto& m : group.value.GetObject()) {
        const double expected = m.value.GetDouble(), got = mine[m.name.GetString()].GetDouble();
        EXPECT_NEAR(got, expected, 1e-9 * std::max(1.0, std::fabs(expected)))
            << what << " " << group.name.GetString() << "." << m.name.GetString();
      }
    }
  }
}

TEST_F(CompareServer, ARowThatCannotBeMadeCarriesItsErrorAndTheOthersGoOn) {
  // uniform level 5 on the 96-face torus is 196608 triangles: over maxTriangles (150000).
  HttpResponse r = post(port(), "/v1/compare",
                        R"({"mesh":)" + mesh("torus_creased") +
                            R"(,"camera":{"width":64,"height":64},"methods":["coarse",)"
                            R"({"method":"uniform","params":{"level":5}},"adaptive"],)"
                            R"("outputs":["color"]})");
  ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
  rapidjson::Document table = parse(r.body);
  const auto& rows = table["rows"];
  ASSERT_EQ(rows.Size(), 3u);
  EXPECT_FALSE(rows[0].HasMember("error"));
  ASSERT_TRUE(rows[1].HasMember("error"));
  EXPECT_EQ(rows[1]["error"]["status"].GetInt(), 413);
  EXPECT_STREQ(rows[1]["error"]["detail"]["limit"].GetString(), "maxTriangles");
  EXPECT_FALSE(rows[1].HasMember("metrics"));
  EXPECT_TRUE(rows[2]["metrics"].HasMember("silhouette"));
  EXPECT_EQ(table["stats"]["failedRows"].GetInt(), 1);
  // Images only because outputs asked: base64 PNG of the row and of its camera's reference.
  EXPECT_TRUE(rows[0]["images"]["color"].HasMember("data"));
  EXPECT_TRUE(table["reference"]["cameras"][0]["images"]["color"].HasMember("data"));
  EXPECT_STREQ(rows[0]["label"].GetString(), "coarse");
  EXPECT_STREQ(rows[1]["label"].GetString(), "uniform:5");
}

TEST_F(CompareServer, BadInputIsA4xxNamingTheField) {
  const std::string cube = mesh("cube");
  auto compare = [&](const std::string& rest) {
    return post(port(), "/v1/compare", R"({"mesh":)" + cube + "," + rest + "}");
  };
  HttpResponse width = compare(R"("cameras":[{},{"width":"wide"}],"methods":["coarse"])");
  EXPECT_EQ(width.status, 400);
  EXPECT_EQ(fieldOf(width), "cameras[1].width");
  HttpResponse level =
      compare(R"("methods":["coarse",{"method":"uniform","params":{"level":-1}}])");
  EXPECT_EQ(level.status, 400);
  EXPECT_EQ(fieldOf(level), "methods[1].params.level");
  EXPECT_EQ(fieldOf(compare(R"("methods":["limit"])")), "methods[0].method");
  EXPECT_EQ(fieldOf(compare(R"("methods":[])")), "methods");
  EXPECT_EQ(fieldOf(compare(R"("camera":{},"cameras":[{}],"methods":["coarse"])")), "cameras");
  EXPECT_EQ(
      fieldOf(compare(R"("methods":[{"method":"adaptive","params":{"metricSupersample":2}}])")),
      "methods[0].params.metricSupersample");
  HttpResponse rows =
      compare(R"("cameras":[{},{},{},{},{}],"methods":["coarse","uniform","adaptive"])");
  EXPECT_EQ(rows.status, 413);
  EXPECT_NE(rows.body.find("maxCompareRows"), std::string::npos) << rows.body;
  EXPECT_EQ(post(port(), "/v1/compare", R"({"mesh":{"id":"feed"},"methods":["coarse"]})").status,
            404);
  EXPECT_EQ(post(port(), "/v1/compare", R"({"methods":["coarse"]})").status, 400);
  EXPECT_EQ(get(port(), "/v1/compare").status, 405);
}

TEST_F(CompareServer, TheDeadlineCoversAllRows) {
  // Twelve rows at 1024^2 with the metrics' masks at S = 8 take far longer than
  // requestTimeoutMs (8 s): the comparison is answered 504, not after its last row.
  const int crashesBefore = health()["workerCrashes"].GetInt();
  const auto start = Clock::now();
  HttpResponse r = post(port(), "/v1/compare",
                        R"({"mesh":)" + mesh("pawn") +
                            R"(,"cameras":[{"width":1024,"height":1024},)"
                            R"({"orbit":{"azimuthDeg":90},"width":1024,"height":1024}],)"
                            R"("metricSupersample":8,"methods":["coarse","silhouette",)"
                            R"({"method":"uniform","params":{"level":1}},)"
                            R"({"method":"uniform","params":{"level":2}},)"
                            R"({"method":"uniform","params":{"level":3}},)"
                            R"({"method":"adaptive","params":{"dicingRate":8}}]})");
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(r.status, 504) << r.body.substr(0, 300);
  EXPECT_LT(seconds, 20);
  // The worker is free again soon after.
  EXPECT_EQ(post(port(), "/v1/compare",
                 R"({"mesh":)" + mesh("cube") +
                     R"(,"camera":{"width":32,"height":32},"methods":["coarse"]})")
                .status,
            200);
  // The timed-out worker stops at its cancellation (it is killed only when it does not, after
  // a grace of seconds) and the pool is whole again for the next requests.
  rapidjson::Document settled = wholePool();
  EXPECT_EQ(settled["busyWorkers"].GetInt(), 0);
  EXPECT_EQ(settled["readyWorkers"].GetInt(), settled["workers"].GetInt());
  EXPECT_EQ(settled["workerCrashes"].GetInt(), crashesBefore)
      << "the timed-out worker was killed instead of stopping at its cancellation";
}

std::string jobSpec(const std::string& meshJson, const std::string& methods, int views, int size) {
  return R"({"meshes":[{"name":"torus","mesh":)" + meshJson + R"(}],"methods":)" + methods +
         R"(,"cameras":[{"random":{"count":)" + std::to_string(views) + R"(,"seed":5}}],"size":)" +
         std::to_string(size) + "}";
}

TEST_F(CompareServer, AJobComputesItsRowsAsComparisonsWouldAndCanBeReadInParts) {
  const std::string torus = mesh("torus_creased");
  HttpResponse created =
      post(port(), "/v1/jobs",
           jobSpec(torus, R"(["coarse",{"method":"uniform","params":{"level":[1,2]}}])", 2, 64));
  ASSERT_EQ(created.status, 202) << created.body.substr(0, 300);
  rapidjson::Document c = parse(created.body);
  const std::string id = c["id"].GetString();
  EXPECT_EQ(created.header("Location"), "/v1/jobs/" + id);
  EXPECT_EQ(c["progress"]["total"].GetInt(), 6);
  rapidjson::Document done = finished(id);
  ASSERT_STREQ(done["state"].GetString(), "done");
  EXPECT_EQ(done["progress"]["done"].GetInt(), 6);
  EXPECT_EQ(done["progress"]["failed"].GetInt(), 0);
  ASSERT_EQ(done["rows"].Size(), 6u);
  // The first row's view compared directly, its camera given as the row resolved it.
  const auto& first = done["rows"][0];
  const auto& cam = first["camera"];
  const std::string camera =
      R"({"eye":)" + text(cam["eye"]) + R"(,"target":)" + text(cam["target"]) + R"(,"up":)" +
      text(cam["up"]) + R"(,"fovYDeg":)" + text(cam["fovYDeg"]) + R"(,"width":64,"height":64})";
  HttpResponse direct =
      post(port(), "/v1/compare",
           R"({"mesh":)" + torus + R"(,"camera":)" + camera +
               R"(,"methods":["coarse",{"method":"uniform","params":{"level":1}},)"
               R"({"method":"uniform","params":{"level":2}}]})");
  ASSERT_EQ(direct.status, 200) << direct.body.substr(0, 300);
  rapidjson::Document table = parse(direct.body);
  for (const auto& row : done["rows"].GetArray()) {
    if (std::string(row["view"].GetString()) != first["view"].GetString()) continue;
    for (const auto& other : table["rows"].GetArray()) {
      if (std::string(other["label"].GetString()) != row["label"].GetString()) continue;
      EXPECT_EQ(row["stats"]["triangles"].GetInt64(), other["stats"]["triangles"].GetInt64());
      EXPECT_NEAR(row["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble(),
                  other["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble(), 1e-9)
          << row["label"].GetString();
    }
  }
  std::set<std::string> labels;
  for (const auto& row : done["rows"].GetArray()) labels.insert(row["label"].GetString());
  EXPECT_EQ(labels, (std::set<std::string>{"coarse", "uniform:1", "uniform:2"}));
  EXPECT_EQ(first["stats"]["controlFaces"].GetInt(), 96);
  EXPECT_EQ(first["camera"]["width"].GetInt(), 64);
  // Rows of the same view share one reference, timed once for them.
  EXPECT_EQ(first["reference"]["sharedBy"].GetInt(), 3);
  EXPECT_EQ(job(id, "?offset=4")["rows"].Size(), 2u);
  EXPECT_EQ(job(id, "?offset=4")["offset"].GetInt(), 4);

  HttpResponse forget = HttpClient(port()).request("DELETE", "/v1/jobs/" + id);
  EXPECT_EQ(forget.status, 200);
  EXPECT_EQ(get(port(), "/v1/jobs/" + id).status, 404);
}

TEST_F(CompareServer, JobsAreCancelledBoundedAndRunOnTheWorkers) {
  const int crashesBefore = health()["workerCrashes"].GetInt();
  const std::string torus = mesh("torus_creased");
  const std::string slow = jobSpec(torus, R"(["coarse","uniform:3","silhouette"])", 12, 256);
  HttpResponse a = post(port(), "/v1/jobs", slow), b = post(port(), "/v1/jobs", slow);
  ASSERT_EQ(a.status, 202) << a.body.substr(0, 300);
  ASSERT_EQ(b.status, 202);
  const std::string first = parse(a.body)["id"].GetString();
  const std::string second = parse(b.body)["id"].GetString();
  // limits.maxJobs = 2, both unfinished: a third is refused.
  HttpResponse full = post(port(), "/v1/jobs", slow);
  EXPECT_EQ(full.status, 429);
  EXPECT_NE(full.body.find("maxJobs"), std::string::npos);
  EXPECT_TRUE(full.has("Retry-After"));

  // The first runs on the render workers, one group (camera) at a time per worker. The job's
  // driver hands its first group to the pool a moment after the 202 (later on a loaded
  // machine), so the busy workers are read until one is seen and the first rows are in.
  bool sawBusyWorker = false;
  const auto deadline = Clock::now() + std::chrono::seconds(120);
  while (Clock::now() < deadline && (!sawBusyWorker || job(first)["rows"].Size() == 0)) {
    sawBusyWorker |= health()["busyWorkers"].GetInt() > 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(sawBusyWorker) << "the job's rows are made on the render workers";
  EXPECT_STREQ(job(second)["state"].GetString(), "queued") << "jobs run one at a time";

  HttpResponse cancelled = HttpClient(port()).request("DELETE", "/v1/jobs/" + first);
  ASSERT_EQ(cancelled.status, 200);
  rapidjson::Document c = parse(cancelled.body);
  EXPECT_STREQ(c["state"].GetString(), "cancelled");
  EXPECT_LT(c["progress"]["done"].GetInt(), c["progress"]["total"].GetInt());
  EXPECT_GT(c["rows"].Size(), 0u) << "the rows made before the cancel are kept";
  EXPECT_STREQ(job(first)["state"].GetString(), "cancelled");
  EXPECT_STREQ(
      parse(HttpClient(port()).request("DELETE", "/v1/jobs/" + second).body)["state"].GetString(),
      "cancelled");

  // Both finished now: a new job evicts the oldest finished one.
  HttpResponse next = post(port(), "/v1/jobs", jobSpec(torus, R"(["coarse"])", 1, 32));
  EXPECT_EQ(next.status, 202);
  EXPECT_STREQ(finished(parse(next.body)["id"].GetString())["state"].GetString(), "done");
  EXPECT_EQ(get(port(), "/v1/jobs/" + first).status, 404);
  EXPECT_EQ(wholePool()["workerCrashes"].GetInt(), crashesBefore)
      << "a cancelled job's worker was killed instead of stopping";
}

TEST_F(CompareServer, AJobSpecIsCheckedBeforeItIsQueued) {
  HttpResponse file = post(
      port(), "/v1/jobs", R"({"meshes":["/etc/passwd"],"methods":["coarse"],"cameras":["front"]})");
  EXPECT_EQ(file.status, 400);
  EXPECT_EQ(fieldOf(file), "meshes[0]");
  HttpResponse rows =
      post(port(), "/v1/jobs", jobSpec(mesh("cube"), R"(["coarse","uniform:1"])", 21, 32));
  EXPECT_EQ(rows.status, 413);
  EXPECT_NE(rows.body.find("maxJobRows"), std::string::npos) << rows.body;
  HttpResponse level =
      post(port(), "/v1/jobs",
           jobSpec(mesh("cube"), R"([{"method":"uniform","params":{"level":[1,-2]}}])", 1, 32));
  EXPECT_EQ(level.status, 400);
  EXPECT_EQ(fieldOf(level), "methods[0].params.level");
  HttpResponse bad = post(port(), "/v1/jobs",
                          R"({"meshes":[{"mesh":{"format":"obj","data":"v 0 0 0\nf 1 2 3\n"}}],)"
                          R"("methods":["coarse"],"cameras":["front"]})");
  EXPECT_EQ(bad.status, 422) << bad.body;
  EXPECT_EQ(get(port(), "/v1/jobs/0123").status, 404);
  EXPECT_EQ(HttpClient(port()).request("DELETE", "/v1/jobs/0123").status, 404);
  EXPECT_EQ(HttpClient(port()).request("PUT", "/v1/jobs").status, 405);
}

TEST_F(CompareServer, RealAnswersMatchTheOpenApiDocument) {
  const std::string cube = mesh("cube");
  HttpResponse created =
      post(port(), "/v1/jobs", jobSpec(cube, R"(["coarse","uniform:1"])", 1, 32));
  ASSERT_EQ(created.status, 202);
  const std::string id = parse(created.body)["id"].GetString();
  finished(id);
  const std::vector<ApiExchange> exchanges = {
      {"POST", "/v1/compare", "",
       R"({"mesh":)" + cube +
           R"(,"cameras":[{"width":40,"height":40},{"orbit":{"azimuthDeg":10},"width":40,"height":40}],)"
           R"("methods":["coarse",{"method":"uniform","params":{"level":3}},{"method":"silhouette","label":"s"}],)"
           R"("outputs":["color","diff"],"imageFormat":"png"})"},
      {"POST", "/v1/compare", "", R"({"mesh":)" + cube + R"(,"methods":["limit"]})"},
      {"POST", "/v1/compare", "",
       R"({"mesh":)" + cube + R"(,"methods":["coarse"],"metricSupersample":99})"},
      {"POST", "/v1/compare", "", R"({"mesh":{"id":"feed"},"methods":["coarse"]})"},
      {"POST", "/v1/compare", "",
       R"({"mesh":{"format":"obj","data":"v 0 0 0\nf 1 2 3\n"},"methods":["coarse"]})"},
      {"GET", "/v1/compare", "", ""},
      {"POST", "/v1/jobs", "", jobSpec(cube, R"(["coarse"])", 1, 24)},
      {"POST", "/v1/jobs", "", R"({"meshes":["x.obj"],"methods":["coarse"],"cameras":["front"]})"},
      {"POST", "/v1/jobs", "", jobSpec(cube, R"(["coarse","uniform:1"])", 30, 32)},
      {"GET", "/v1/jobs/" + id, "/v1/jobs/{id}", ""},
      {"GET", "/v1/jobs/" + id + "?offset=1", "/v1/jobs/{id}", ""},
      {"GET", "/v1/jobs/none", "/v1/jobs/{id}", ""},
      {"GET", "/v1/jobs?limit=2", "/v1/jobs", ""},
      {"GET", "/v1/jobs/" + id + "/results.csv", "/v1/jobs/{id}/results.csv", ""},
      {"GET", "/v1/jobs/" + id + "/results.jsonl", "/v1/jobs/{id}/results.jsonl", ""},
      {"GET", "/v1/jobs/none/results.csv", "/v1/jobs/{id}/results.csv", ""},
      {"DELETE", "/v1/jobs/" + id, "/v1/jobs/{id}", ""},
      {"DELETE", "/v1/jobs/" + id, "/v1/jobs/{id}", ""},
  };
  OpenApiCheck check = checkAgainstOpenApi(port(), exchanges);
  EXPECT_EQ(check.status, 0) << check.output;
  EXPECT_EQ(check.statuses, (std::set<int>{200, 202, 400, 404, 405, 413, 422})) << check.output;
}

}  // namespace
}  // namespace limn::testing
