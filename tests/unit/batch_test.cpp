// The batch's pure parts: the spec and its sweeps, the views, the row list, shards, resume keys,
// the results files read back and the report's statistics. Meshes are read by the real OBJ
// reader; nothing here renders (tests/integration/batch_cli_test.cpp runs limn batch).
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "api/batch_plan.h"
#include "api/batch_results.h"
#include "api/batch_spec.h"
#include "api/jobs_api.h"
#include "api/json_util.h"
#include "batch/mesh_files.h"
#include "batch/progress.h"
#include "batch/report.h"

namespace limn {
namespace {

namespace fs = std::filesystem;
using api::ApiError;
using api::BatchSpec;

const render::pipeline::JobLimits kLimits;

const char* kCube =
    "v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
    "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n";
const char* kTetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

// The ApiError a call throws (status 0 when it throws none).
template <class F>
ApiError errorOf(F f) {
  try {
    f();
  } catch (const ApiError& e) {
    return e;
  }
  return {0, "", ""};
}

std::string fieldOf(const ApiError& e) {
  rapidjson::Document d;
  d.Parse(e.detailJson.c_str());
  return d.IsObject() && d.HasMember("field") ? d["field"].GetString() : "";
}

BatchSpec spec(const std::string& json) { return api::parseBatchSpec(json, kLimits); }

api::BatchPlan twoMeshPlan(const std::string& methods, int views) {
  BatchSpec s;
  s.methods = api::parseMethodList(methods, kLimits);
  s.views = api::seededViews(views, 1);
  s.size = 64;
  return api::BatchPlan(s, {api::meshFromObj("cube", "cube.obj", kCube, "catmull-clark", kLimits),
                            api::meshFromObj("tetra", "tetra.obj", kTetra, "loop", kLimits)});
}

TEST(BatchSpec, SweepsExpandToOneMethodPerCombination) {
  BatchSpec s = spec(R"({"meshes": ["a.obj"], "cameras": ["front"],
    "methods": ["coarse", {"method": "uniform", "params": {"level": [1, 2, 3]}, "shading": ["smooth", "flat"]},
                {"method": "adaptive", "params": {"dicingRate": [0.5, 2]}},
                {"method": "silhouette", "params": {"contour": ["exact", "pn"]}}]})");
  std::vector<std::string> labels;
  for (const auto& m : s.methods) labels.push_back(m.label);
  EXPECT_EQ(labels,
            (std::vector<std::string>{"coarse", "uniform:1", "uniform:1 shading=flat", "uniform:2",
                                      "uniform:2 shading=flat", "uniform:3",
                                      "uniform:3 shading=flat", "adaptive:0.5", "adaptive:2",
                                      "silhouette contour=exact", "silhouette contour=pn"}));
  EXPECT_EQ(s.methods[3].paramsJson, R"({"level":2})");
  EXPECT_EQ(s.size, 512);
  EXPECT_EQ(s.supersample, 4);
}

TEST(BatchSpec, MethodListTakesLevelsAndDicingRates) {
  auto methods = api::parseMethodList("coarse,uniform:3,adaptive:0.5,silhouette", kLimits);
  ASSERT_EQ(methods.size(), 4u);
  EXPECT_EQ(methods[1].paramsJson, R"({"level":3})");
  EXPECT_EQ(methods[2].paramsJson, R"({"dicingRate":0.5})");
  EXPECT_EQ(methods[3].label, "silhouette");
  // 1 and 1.0 are one method: its key does not depend on how the number was written.
  EXPECT_EQ(api::parseMethodList("adaptive:1", kLimits)[0].key(),
            api::parseMethodList("adaptive:1.0", kLimits)[0].key());
  EXPECT_EQ(fieldOf(errorOf([] { api::parseMethodList("coarse:2", kLimits); })), "--methods");
  EXPECT_EQ(fieldOf(errorOf([] { api::parseMethodList("uniform:x", kLimits); })), "--methods");
  EXPECT_EQ(errorOf([] { api::parseMethodList("magic", kLimits); }).status, 400);
  ApiError deep = errorOf([] { api::parseMethodList("uniform:9", kLimits); });
  EXPECT_EQ(deep.status, 413);
  EXPECT_NE(deep.message.find("maxLevel"), std::string::npos) << deep.message;
}

TEST(BatchSpec, ErrorsNameTheEntry) {
  const std::string head = R"({"meshes": ["a.obj"], "cameras": ["front"], )";
  ApiError level = errorOf([&] {
    spec(head + R"("methods": ["coarse", {"method": "uniform", "params": {"level": [2, 9]}}]})");
  });
  EXPECT_EQ(level.status, 413);
  EXPECT_EQ(fieldOf(level), "methods[1].params.level");
  EXPECT_EQ(fieldOf(errorOf([&] {
              spec(head + R"("methods": [{"method": "adaptive", "params": {"dicngRate": 1}}]})");
            })),
            "methods[0]");  // an unknown param is a mistake in a spec, not a warning
  EXPECT_EQ(fieldOf(errorOf([&] { spec(head + R"("methods": ["limit"]})"); })),
            "methods[0].method");
  EXPECT_EQ(fieldOf(errorOf([] {
              spec(R"({"meshes": ["a.obj"], "methods": ["coarse"], "cameras": ["sideways"]})");
            })),
            "cameras[0]");
  EXPECT_EQ(fieldOf(errorOf([] {
              spec(R"({"meshes": ["a.obj"], "methods": ["coarse"],
                       "cameras": ["front", {"camera": {"width": 10}}]})");
            })),
            "cameras[1].camera.width");
  EXPECT_EQ(fieldOf(errorOf([] {
              spec(R"({"meshes": ["a.obj"], "methods": ["coarse"],
                       "cameras": [{"camera": {"fovYDeg": "wide"}}]})");
            })),
            "cameras[0].camera.fovYDeg");
  EXPECT_EQ(fieldOf(errorOf([] { spec(R"({"methods": ["coarse"], "cameras": ["front"]})"); })),
            "meshes");
  EXPECT_EQ(fieldOf(errorOf([] {
              spec(R"({"meshes": ["a"], "methods": ["coarse"], "cameras": ["front"], "view": 3})");
            })),
            "view");
  EXPECT_EQ(
      fieldOf(errorOf([] { spec(R"({"meshes": ["a"], "methods": ["coarse"], "views": 0})"); })),
      "views");
  EXPECT_EQ(fieldOf(errorOf([] {
              spec(R"({"meshes": ["a"], "methods": ["coarse"], "cameras": ["front"], "seed": 2})");
            })),
            "seed");
  EXPECT_EQ(
      errorOf([] {
        spec(R"({"meshes": ["a"], "methods": ["coarse"], "cameras": ["front"], "size": 9000})");
      }).status,
      413);
}

TEST(BatchSpec, ViewsRingsAndSeededSetsExpand) {
  BatchSpec s = spec(R"({"meshes": ["a.obj"], "methods": ["coarse"], "cameras": [
      "three-quarter", {"orbitRing": {"count": 4, "elevationDeg": 20}},
      {"random": {"count": 5, "seed": 7}}, {"name": "hero", "camera": {"eye": [0, 0, 9]}},
      "front", {"orbitRing": {"count": 1}}]})");
  // The last ring (one view at azimuth 0, elevation 0) is "front" again: dropped.
  ASSERT_EQ(s.views.size(), 1u + 4u + 5u + 1u + 1u);
  EXPECT_EQ(s.views[0].label, "three-quarter");
  std::vector<std::string> ring;
  for (int i = 1; i <= 4; ++i) ring.push_back(s.views[i].label);
  EXPECT_EQ(ring, (std::vector<std::string>{"az0 el20", "az90 el20", "az180 el20", "az270 el20"}));
  EXPECT_EQ(s.views[10].label, "hero");
  EXPECT_EQ(s.views[10].compareJson(64), R"({"eye":[0,0,9],"height":64,"width":64})");
}

TEST(BatchSpec, ViewsIsTheSpecsViewsFlag) {
  // "views": N is what --views N makes, after any cameras; "seed" chooses its directions.
  BatchSpec s = spec(R"({"meshes": ["a.obj"], "methods": ["coarse"], "views": 3})");
  auto seeded = api::seededViews(3, 1);
  ASSERT_EQ(s.views.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(s.views[i].cameraJson, seeded[i].cameraJson);
  BatchSpec both = spec(
      R"({"meshes": ["a.obj"], "methods": ["coarse"], "cameras": ["top"], "views": 2, "seed": 9})");
  ASSERT_EQ(both.views.size(), 3u);
  EXPECT_EQ(both.views[0].label, "top");
  EXPECT_EQ(both.views[1].cameraJson, api::seededViews(2, 9)[0].cameraJson);
}

TEST(BatchSpec, SeededViewsAreReproducibleAndSpreadWithinTheBand) {
  auto a = api::seededViews(200, 42, -30, 50), b = api::seededViews(200, 42, -30, 50);
  auto c = api::seededViews(200, 43, -30, 50);
  std::set<std::string> distinct;
  int north = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].cameraJson, b[i].cameraJson);
    distinct.insert(a[i].cameraJson);
    rapidjson::Document d;
    d.Parse(a[i].cameraJson.c_str());
    const double az = d["orbit"]["azimuthDeg"].GetDouble(),
                 el = d["orbit"]["elevationDeg"].GetDouble();
    EXPECT_TRUE(az >= 0 && az < 360) << az;
    EXPECT_TRUE(el >= -30 && el <= 50) << el;
    north += el > 0;
  }
  EXPECT_EQ(distinct.size(), a.size());
  EXPECT_NE(a[0].cameraJson, c[0].cameraJson);
  // Uniform over the band's area: P(el > 0) = sin 50 / (sin 50 + sin 30) = 0.605.
  EXPECT_NEAR(north / 200.0, 0.605, 0.1);
}

TEST(BatchPlan, RowsAreNumberedMeshThenViewThenMethod) {
  api::BatchPlan plan = twoMeshPlan("coarse,uniform:2,adaptive:1", 2);
  ASSERT_EQ(plan.rows().size(), 2u * 2u * 3u);
  std::set<std::string> keys;
  for (const api::BatchRow& r : plan.rows()) {
    EXPECT_EQ(r.index, (r.mesh * 2 + r.view) * 3 + r.method);
    keys.insert(r.key);
  }
  EXPECT_EQ(keys.size(), plan.rows().size());
  EXPECT_EQ(plan.rows()[7].key.substr(0, 32), plan.meshes()[1].hash);
  // The body of a group is a /v1/compare request with the group's methods.
  auto groups = plan.pendingGroups({}, {}, 64);
  ASSERT_EQ(groups.size(), 4u);
  rapidjson::Document body;
  body.Parse(plan.compareBody(groups[3]).c_str());
  ASSERT_FALSE(body.HasParseError());
  EXPECT_EQ(body["methods"].Size(), 3u);
  EXPECT_EQ(body["camera"]["width"].GetInt(), 64);
  EXPECT_EQ(std::string(body["mesh"]["scheme"].GetString()), "loop");
}

TEST(BatchPlan, KeysNameMethodParamsViewAndSizeNotTheLabel) {
  const api::BatchMesh cube = api::meshFromObj("cube", "x.obj", kCube, "catmull-clark", kLimits);
  const api::BatchMesh moved =
      api::meshFromObj("renamed", "elsewhere/y.obj", kCube, "catmull-clark", kLimits);
  auto uniform = api::parseMethodList("uniform:2", kLimits)[0];
  auto relabelled = uniform;
  relabelled.label = "my uniform";
  const api::ViewSpec front = *api::namedView("front");
  EXPECT_EQ(api::rowKey(cube, uniform, front, 64, 4), api::rowKey(moved, relabelled, front, 64, 4));
  EXPECT_NE(api::rowKey(cube, uniform, front, 64, 4), api::rowKey(cube, uniform, front, 65, 4));
  EXPECT_NE(api::rowKey(cube, uniform, front, 64, 4), api::rowKey(cube, uniform, front, 64, 2));
  EXPECT_NE(api::rowKey(cube, uniform, front, 64, 4),
            api::rowKey(cube, api::parseMethodList("uniform:3", kLimits)[0], front, 64, 4));
  EXPECT_NE(api::rowKey(cube, uniform, front, 64, 4),
            api::rowKey(cube, uniform, *api::namedView("back"), 64, 4));
  // The same points with another scheme is another surface.
  EXPECT_NE(cube.hash, api::meshFromObj("cube", "x.obj", kCube, "bilinear", kLimits).hash);
}

TEST(BatchPlan, ShardsSplitTheRowsByIndexAndSkipWhatIsDone) {
  api::BatchPlan plan = twoMeshPlan("coarse,uniform:1,uniform:2,adaptive:1,silhouette", 3);
  const size_t n = 4;
  std::vector<int> owner(plan.rows().size(), -1);
  for (int k = 0; k < static_cast<int>(n); ++k) {
    for (const api::RowGroup& g : plan.pendingGroups({k, static_cast<int>(n)}, {}, 64)) {
      for (size_t r : g.rows) {
        EXPECT_EQ(owner[r], -1) << "row " << r << " in two shards";
        owner[r] = k;
        EXPECT_EQ(r % n, static_cast<size_t>(k));
        EXPECT_EQ(plan.rows()[r].mesh, g.mesh);
        EXPECT_EQ(plan.rows()[r].view, g.view);
      }
    }
  }
  for (size_t r = 0; r < owner.size(); ++r) EXPECT_NE(owner[r], -1) << "row " << r << " in none";

  std::set<std::string> done = {plan.rows()[0].key, plan.rows()[4].key};
  size_t pending = 0;
  for (const api::RowGroup& g : plan.pendingGroups({}, done, 2)) {
    EXPECT_LE(g.rows.size(), 2u);
    for (size_t r : g.rows) EXPECT_FALSE(done.count(plan.rows()[r].key));
    pending += g.rows.size();
  }
  EXPECT_EQ(pending, plan.rows().size() - 2);
}

class ResultsFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("limn-batch-unit-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  fs::path dir_;
};

// A line as resultLines writes it for one row: an answer for the group of row `r`.
std::vector<std::string> linesOf(const api::BatchPlan& plan, size_t r, const api::Answer& answer) {
  api::RowGroup group{plan.rows()[r].mesh, plan.rows()[r].view, {r}};
  return api::resultLines(plan, group, answer);
}

TEST_F(ResultsFolder, ResumeKeepsFinishedRowsAndRetriesTransientFailures) {
  api::BatchPlan plan = twoMeshPlan("coarse,uniform:2", 1);
  auto busy = api::errorAnswer({429, "busy", "full"});
  auto timeout = api::errorAnswer({504, "timeout", "too slow"});
  auto tooLarge = api::errorAnswer({413, "too_large", "maxTriangles"});
  // Row 0 timed out (computed again), row 1 is too large (its own error: kept), row 2 was busy
  // and then too large (the later line wins), row 3 is only in a file that is not a results file.
  std::string a = linesOf(plan, 0, timeout)[0] + "\n" + linesOf(plan, 1, tooLarge)[0] + "\n";
  std::string b = linesOf(plan, 2, busy)[0] + "\n" + linesOf(plan, 2, tooLarge)[0] + "\n" +
                  R"({"key": "cut sh)";
  write("results.jsonl", a);
  write("results-shard-1.jsonl", b);
  write("notes.txt", linesOf(plan, 3, tooLarge)[0] + "\n");  // not a results file
  size_t unreadable = 0;
  std::vector<api::ResultRow> rows = batch::readResults(dir_, &unreadable);
  EXPECT_EQ(unreadable, 1u);
  ASSERT_EQ(rows.size(), 3u);
  std::set<std::string> done = batch::finishedKeys(rows);
  EXPECT_EQ(done, (std::set<std::string>{plan.rows()[1].key, plan.rows()[2].key}));
  for (const api::ResultRow& r : rows) {
    ASSERT_TRUE(r.error);
    if (r.key == plan.rows()[0].key) {
      EXPECT_EQ(r.error->status, 504);
    }
    if (r.key == plan.rows()[2].key) {
      EXPECT_EQ(r.error->code, "too_large");
    }
  }
}

TEST_F(ResultsFolder, AnErrorNeverReplacesARowThatWasComputed) {
  api::BatchPlan plan = twoMeshPlan("coarse", 1);
  rapidjson::Document d;
  d.Parse(R"({"label":"coarse","method":"coarse","stats":{"triangles":12},)"
          R"("metrics":{"silhouette":{"outlineHausdorffPx":2.5}},"timings":{"approxMs":1}})");
  d.AddMember("key", rapidjson::Value(plan.rows()[0].key.c_str(), d.GetAllocator()),
              d.GetAllocator());
  const std::string ok = api::json::canonical(d);
  write("results.jsonl",
        ok + "\n" + linesOf(plan, 0, api::errorAnswer({504, "timeout", "x"}))[0] + "\n");
  std::vector<api::ResultRow> rows = batch::readResults(dir_);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_FALSE(rows[0].error);
  EXPECT_EQ(rows[0].triangles, 12);
  EXPECT_EQ(rows[0].metrics.at("silhouette.outlineHausdorffPx"), 2.5);
}

TEST_F(ResultsFolder, CsvHasAColumnPerFieldAndQuotesWhatNeedsIt) {
  api::BatchPlan plan = twoMeshPlan("coarse", 1);
  write("results.jsonl",
        linesOf(plan, 1, api::errorAnswer({422, "invalid_mesh", "face 1, \"odd\""}))[0] + "\n");
  batch::writeCsv(batch::readResults(dir_), dir_ / "results.csv");
  std::ifstream in(dir_ / "results.csv");
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  size_t columns = 1;
  for (char c : header) columns += c == ',';
  EXPECT_EQ(columns, batch::csvColumns().size());
  EXPECT_NE(line.find(R"("face 1, ""odd""")"), std::string::npos) << line;
}

TEST(BatchReport, PercentilesAreNearestRank) {
  std::vector<double> values;
  for (int i = 20; i >= 1; --i) values.push_back(i);
  EXPECT_EQ(batch::median(values), 10);
  EXPECT_EQ(batch::percentile(values, 95), 19);
  EXPECT_EQ(batch::percentile(values, 100), 20);
  EXPECT_EQ(batch::percentile({3.5}, 95), 3.5);
  EXPECT_EQ(batch::median({}), 0);
}

TEST(BatchReport, SummaryRanksEachLabelsErrors) {
  std::vector<api::ResultRow> rows;
  for (int i = 1; i <= 10; ++i) {
    api::ResultRow r;
    r.label = r.method = "coarse";
    r.mesh = "m" + std::to_string(i);
    r.view = "front";
    r.triangles = 10 * i;
    r.metrics["silhouette.outlineHausdorffPx"] = i;
    rows.push_back(r);
  }
  rows.back().error = api::ResultError{413, "too_large", "x"};  // m10 failed
  std::vector<batch::MethodSummary> s = batch::summarize(rows);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].rows, 10u);
  EXPECT_EQ(s[0].failed, 1u);
  EXPECT_EQ(s[0].medianError, 5);
  EXPECT_EQ(s[0].worstError, 9);
  EXPECT_EQ(s[0].worstRow, "m9, front");
  EXPECT_EQ(s[0].medianTriangles, 50);
}

TEST(BatchProgress, RateAndTimeLeft) {
  EXPECT_EQ(batch::Progress::rateAndTimeLeft(0, 10, 5), "starting");
  EXPECT_EQ(batch::Progress::rateAndTimeLeft(10, 40, 5), "2.00 rows/s, 15s left");
  EXPECT_EQ(batch::Progress::duration(3725), "1h02m");
  EXPECT_EQ(batch::Progress::duration(185), "3m05s");
}

TEST_F(ResultsFolder, MeshFilesFoldersAndGlobsResolveInNameOrderWithTheirSchemes) {
  fs::create_directories(dir_ / "shapes");
  write("shapes/b_cube.obj", kCube);
  write("shapes/loop_tetra.obj", kTetra);
  write("shapes/notes.txt", "not a mesh");
  write("shapes/examples.json", R"([{"file": "b_cube.obj", "scheme": "bilinear"}])");
  write("a_cube.obj", kCube);
  std::vector<std::string> warnings;
  auto meshes = batch::loadMeshes({{"shapes", {}, "", ""},
                                   {"*.obj", {}, "", ""},
                                   {"shapes/b_*.obj", std::string("catmull-clark"), "", ""}},
                                  dir_, kLimits, warnings);
  ASSERT_EQ(meshes.size(), 3u);         // the glob's cube is a_cube's surface again: kept once
  EXPECT_EQ(meshes[0].name, "b_cube");  // bilinear, from examples.json
  EXPECT_EQ(meshes[1].name, "loop_tetra");
  EXPECT_EQ(meshes[2].name, "a_cube");
  EXPECT_EQ(meshes[0].path, "shapes/b_cube.obj");
  EXPECT_EQ(batch::guessScheme(dir_ / "shapes/loop_tetra.obj"), "loop");
  EXPECT_EQ(warnings.size(), 1u);
  // A glob that matches nothing is an optional corpus; a missing file is a mistake.
  warnings.clear();
  EXPECT_EQ(batch::loadMeshes({{"a_cube.obj", {}, "", ""}, {"corpus/*.obj", {}, "", ""}}, dir_,
                              kLimits, warnings)
                .size(),
            1u);
  EXPECT_EQ(warnings.size(), 1u);
  EXPECT_THROW(batch::loadMeshes({{"nothing*.obj", {}, "", ""}}, dir_, kLimits, warnings),
               batch::MeshFileError);
  EXPECT_THROW(batch::loadMeshes({{"missing.obj", {}, "", ""}}, dir_, kLimits, warnings),
               batch::MeshFileError);
}

TEST(JobSpec, AServerReadsNoFilesAndBoundsTheRows) {
  ApiError file = errorOf([] {
    api::parseJobSpec(R"({"meshes": ["/etc/passwd"], "methods": ["coarse"], "cameras": ["front"]})",
                      kLimits, 100);
  });
  EXPECT_EQ(file.status, 400);
  EXPECT_EQ(fieldOf(file), "meshes[0]");
  const std::string inline_ =
      R"({"meshes": [{"name": "tri", "mesh": {"points": [[0,0,0],[1,0,0],[0,1,0]],
      "faceVertexCounts": [3], "faceVertexIndices": [0,1,2]}}], "methods": ["coarse", "uniform:1"],
      "cameras": [{"random": {"count": 3}}]})";
  EXPECT_EQ(api::parseJobSpec(inline_, kLimits, 6).rows().size(), 6u);
  ApiError rows = errorOf([&] { api::parseJobSpec(inline_, kLimits, 5); });
  EXPECT_EQ(rows.status, 413);
  EXPECT_NE(rows.message.find("maxJobRows"), std::string::npos);
}

}  // namespace
}  // namespace limn
