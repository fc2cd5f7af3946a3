// `limn batch` as a user runs it: two examples x two methods x two views at a small size on the
// local workers; the files it writes and their shape; a second run that computes nothing; a run
// that resumes a cut-short file; shards taken by JOB_COMPLETION_INDEX and merged by --report;
// the same rows through a running server (--server, one server for the program).
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <unistd.h>

#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/integration/server_process.h"

namespace limn::testing {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<std::string> lines(const fs::path& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

// key -> the row's triangles and outline error, from every line of a results file.
std::map<std::string, std::pair<long, double>> rowsOf(const fs::path& file) {
  std::map<std::string, std::pair<long, double>> rows;
  for (const std::string& line : lines(file)) {
    rapidjson::Document d;
    d.Parse(line.c_str());
    EXPECT_FALSE(d.HasParseError()) << line;
    if (d.HasParseError()) continue;
    for (const char* field : {"key", "mesh", "meshHash", "label", "method", "params", "view",
                              "camera", "stats", "metrics", "timings", "reference"}) {
      EXPECT_TRUE(d.HasMember(field)) << field << " in " << line.substr(0, 200);
    }
    if (!d.HasMember("metrics")) continue;
    rows[d["key"].GetString()] = {d["stats"]["triangles"].GetInt64(),
                                  d["metrics"]["silhouette"]["outlineHausdorffPx"].GetDouble()};
  }
  return rows;
}

const std::string kMeshes = std::string(LIMN_SOURCE_DIR) + "/examples/torus_creased.obj," +
                            LIMN_SOURCE_DIR + "/examples/icosahedron.obj";
const std::string kFlags =
    "--meshes '" + kMeshes + "' --methods coarse,uniform:2 --views 2 --size 80";

class BatchCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess(ServerProcess::withConfig(R"({"workers": 2})"));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server_->terminate(SIGTERM), 0);
    delete server_;
    server_ = nullptr;
  }
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("limn-batch-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `limn batch ARGS` (shell-quoted already), its exit status and what it said.
  static CommandResult batch(const std::string& args, const std::string& environment = "") {
    return runCommand(environment + " '" + std::string(limnBinary()) + "' batch " + args);
  }
  static std::string out(const fs::path& dir) { return " --out '" + dir.string() + "'"; }

  static ServerProcess* server_;
  fs::path dir_;
};
ServerProcess* BatchCli::server_ = nullptr;

TEST_F(BatchCli, WritesResultsAndReportAndASecondRunComputesNothing) {
  CommandResult first = batch(kFlags + out(dir_));
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_NE(first.output.find("0 done already (skipped), 8 to compute"), std::string::npos)
      << first.output;
  // Not a terminal: plain progress lines, no bar redrawn with \r.
  EXPECT_EQ(first.output.find('\r'), std::string::npos);

  const auto rows = rowsOf(dir_ / "results.jsonl");
  EXPECT_EQ(rows.size(), 8u);
  std::set<std::string> labels;
  for (const std::string& line : lines(dir_ / "results.jsonl")) {
    rapidjson::Document d;
    d.Parse(line.c_str());
    labels.insert(d["label"].GetString());
    EXPECT_EQ(d["camera"]["width"].GetInt(), 80);
    EXPECT_EQ(d["reference"]["sharedBy"].GetInt(), 2) << "one reference per mesh and view";
  }
  EXPECT_EQ(labels, (std::set<std::string>{"coarse", "uniform:2"}));

  // results.csv: a header and one line per row; summary.md: a table row per method.
  std::vector<std::string> csv = lines(dir_ / "results.csv");
  ASSERT_EQ(csv.size(), 9u);
  EXPECT_EQ(csv[0].rfind("key,mesh,meshPath,meshHash,label,method,", 0), 0u) << csv[0];
  const std::string summary = slurp(dir_ / "summary.md");
  EXPECT_NE(summary.find("8 rows (0 failed): 2 meshes x 2 views x 2 methods at 80 x 80 px"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("\n| coarse | 4 | 0 |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\n| uniform:2 | 4 | 0 |"), std::string::npos) << summary;
  for (const char* plot : {"error_vs_triangles", "time_vs_triangles", "error_by_shape"}) {
    const std::string svg = slurp(dir_ / "plots" / (std::string(plot) + ".svg"));
    EXPECT_NE(svg.find("<svg"), std::string::npos) << plot;
    const std::string png = slurp(dir_ / "plots" / (std::string(plot) + ".png"));
    EXPECT_EQ(png.substr(0, 8), "\x89PNG\r\n\x1a\n") << plot;
  }
  const std::string html = slurp(dir_ / "report.html");
  EXPECT_NE(html.find("<table>"), std::string::npos);
  EXPECT_NE(html.find("src=\"plots/error_vs_triangles.svg\""), std::string::npos);
  EXPECT_NE(html.find("--line"), std::string::npos) << "the page's style sheet";

  const std::string before = slurp(dir_ / "results.jsonl");
  CommandResult second = batch(kFlags + out(dir_) + " --no-plots");
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_NE(second.output.find("8 done already (skipped), 0 to compute"), std::string::npos)
      << second.output;
  EXPECT_EQ(slurp(dir_ / "results.jsonl"), before) << "nothing was computed again";
}

// A folder of mesh files of several formats: each is read (OFF's quads as Catmull-Clark, a
// binary STL's triangles as Loop, welded), and its rows are computed like an OBJ's.
TEST_F(BatchCli, AFolderOfMeshFilesOfOtherFormatsIsReadByExtension) {
  const fs::path meshes = dir_ / "meshes";
  fs::create_directories(meshes);
  std::ofstream(meshes / "cube.off")
      << "OFF\n8 6 0\n-1 -1 1\n1 -1 1\n-1 1 1\n1 1 1\n-1 1 -1\n1 1 -1\n-1 -1 -1\n1 -1 -1\n"
         "4 0 1 3 2\n4 2 3 5 4\n4 4 5 7 6\n4 6 7 1 0\n4 1 7 5 3\n4 6 0 2 4\n";
  const float corners[4][3] = {{1, 1, 1}, {-1, -1, 1}, {-1, 1, -1}, {1, -1, -1}};
  const int faces[4][3] = {{0, 1, 3}, {0, 2, 1}, {0, 3, 2}, {1, 2, 3}};
  std::string stl(80, ' ');
  const uint32_t count = 4;
  stl.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& face : faces) {
    const float normal[3] = {0, 0, 0};
    stl.append(reinterpret_cast<const char*>(normal), sizeof normal);
    for (int v : face) stl.append(reinterpret_cast<const char*>(corners[v]), sizeof corners[v]);
    stl.append(2, '\0');
  }
  std::ofstream(meshes / "tetra.stl", std::ios::binary) << stl;
  std::ofstream(meshes / "notes.txt") << "not a mesh";  // left out: not a mesh file's extension

  CommandResult run = batch("--meshes '" + meshes.string() +
                            "' --methods coarse,uniform:2 --views 1 --size 48" + out(dir_ / "out"));
  ASSERT_EQ(run.status, 0) << run.output;
  std::set<std::string> names;
  for (const std::string& line : lines(dir_ / "out" / "results.jsonl")) {
    rapidjson::Document d;
    d.Parse(line.c_str());
    names.insert(d["mesh"].GetString());
    EXPECT_TRUE(d.HasMember("metrics")) << line.substr(0, 300);
    if (std::string(d["mesh"].GetString()) == "tetra") {
      EXPECT_EQ(d["stats"]["controlVertices"].GetInt(), 4) << "the STL's corners welded";
    }
  }
  EXPECT_EQ(names, (std::set<std::string>{"cube", "tetra"}));
}

TEST_F(BatchCli, ResumesAFileCutShort) {
  ASSERT_EQ(batch(kFlags + out(dir_) + " --no-plots --quiet").status, 0);
  std::vector<std::string> all = lines(dir_ / "results.jsonl");
  ASSERT_EQ(all.size(), 8u);
  const auto complete = rowsOf(dir_ / "results.jsonl");
  {
    // Five whole rows and half of the sixth, as a killed run leaves it.
    std::ofstream cut(dir_ / "results.jsonl", std::ios::trunc);
    for (int i = 0; i < 5; ++i) cut << all[i] << "\n";
    cut << all[5].substr(0, all[5].size() / 2);
  }
  CommandResult resumed = batch(kFlags + out(dir_) + " --no-plots");
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("5 done already (skipped), 3 to compute"), std::string::npos)
      << resumed.output;
  EXPECT_EQ(lines(dir_ / "results.jsonl").size(), 8u) << "the half line is gone";
  EXPECT_EQ(rowsOf(dir_ / "results.jsonl"), complete) << "the same rows as the run not cut short";
}

TEST_F(BatchCli, ShardsByJobCompletionIndexMergeIntoTheSameRows) {
  const fs::path whole = dir_ / "whole", shards = dir_ / "shards";
  ASSERT_EQ(batch(kFlags + out(whole) + " --no-plots --quiet").status, 0);
  for (int k = 0; k < 3; ++k) {
    CommandResult shard = batch(kFlags + out(shards) + " --shard-count 3 --quiet",
                                "JOB_COMPLETION_INDEX=" + std::to_string(k));
    ASSERT_EQ(shard.status, 0) << shard.output;
    EXPECT_TRUE(fs::exists(shards / ("results-shard-" + std::to_string(k) + ".jsonl")));
    EXPECT_FALSE(fs::exists(shards / "summary.md")) << "a shard writes no report";
  }
  // Rows 0..7 by index % 3: 3, 3 and 2 rows.
  EXPECT_EQ(lines(shards / "results-shard-0.jsonl").size(), 3u);
  EXPECT_EQ(lines(shards / "results-shard-1.jsonl").size(), 3u);
  EXPECT_EQ(lines(shards / "results-shard-2.jsonl").size(), 2u);
  CommandResult report = batch("--report '" + shards.string() + "' --no-plots");
  ASSERT_EQ(report.status, 0) << report.output;
  EXPECT_EQ(lines(shards / "results.csv").size(), 9u);
  std::map<std::string, std::pair<long, double>> merged;
  for (int k = 0; k < 3; ++k) {
    for (const auto& row : rowsOf(shards / ("results-shard-" + std::to_string(k) + ".jsonl"))) {
      merged.insert(row);
    }
  }
  EXPECT_EQ(merged, rowsOf(whole / "results.jsonl"));
  EXPECT_NE(batch(kFlags + out(shards) + " --shard-count 3").status, 0)
      << "without JOB_COMPLETION_INDEX a shard count needs --shard-index";
  EXPECT_NE(batch(kFlags + out(shards) + " --shard-count 3 --shard-index 3").status, 0);
}

TEST_F(BatchCli, AServerComputesTheSameRows) {
  const fs::path local = dir_ / "local", remote = dir_ / "remote";
  ASSERT_EQ(batch(kFlags + out(local) + " --no-plots --quiet").status, 0);
  CommandResult viaServer = batch(kFlags + out(remote) + " --no-plots --server http://127.0.0.1:" +
                                  std::to_string(server_->port()));
  ASSERT_EQ(viaServer.status, 0) << viaServer.output;
  EXPECT_EQ(rowsOf(remote / "results.jsonl"), rowsOf(local / "results.jsonl"));
  CommandResult nobody = batch(kFlags + out(dir_ / "nobody") + " --server http://127.0.0.1:1");
  EXPECT_EQ(nobody.status, 3) << nobody.output;
}

TEST_F(BatchCli, ASpecFileSweepsAndBadInputIsNamed) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "spec.json") << R"({
    "meshes": [")" << LIMN_SOURCE_DIR
                                    << R"(/examples/cube.obj"],
    "methods": [{"method": "uniform", "params": {"level": [1, 2]}}, "coarse"],
    "cameras": ["front", {"orbitRing": {"count": 2, "elevationDeg": 30}}],
    "size": 48, "supersample": 2})";
  CommandResult run =
      batch("'" + (dir_ / "spec.json").string() + "'" + out(dir_ / "out") + " --no-plots");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("9 rows (1 meshes x 3 views x 3 methods, 48 px)"), std::string::npos)
      << run.output;
  std::ofstream(dir_ / "bad.json")
      << R"({"meshes": ["x.obj"], "methods": [{"method": "uniform", "params": {"level": [1, 99]}}], "cameras": ["front"]})";
  CommandResult bad = batch("'" + (dir_ / "bad.json").string() + "'" + out(dir_ / "bad"));
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("methods[0].params.level"), std::string::npos) << bad.output;
  CommandResult missing =
      batch("--meshes '" + (dir_ / "none.obj").string() + "' --methods coarse" + out(dir_ / "m"));
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("no mesh file matches"), std::string::npos) << missing.output;
  EXPECT_EQ(batch("--methods coarse" + out(dir_ / "m")).status, 1);
  // The configuration comes from --config, else LIMN_CONFIG, as for limn serve.
  std::ofstream(dir_ / "limn.json") << R"({"wrokers": 2})";
  CommandResult config =
      batch(kFlags + out(dir_ / "c"), "LIMN_CONFIG='" + (dir_ / "limn.json").string() + "'");
  EXPECT_EQ(config.status, 1);
  EXPECT_NE(config.output.find("wrokers"), std::string::npos) << config.output;
}

}  // namespace
}  // namespace limn::testing
