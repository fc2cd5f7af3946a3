// Jobs that survive (issue 24), with real stores and real servers: three `limn serve` processes
// sharing one throwaway PostgreSQL server compute one job together and finish it when one of
// them is killed; one process on a SQLite file is killed mid-job and its successor on the same
// file finishes it; Idempotency-Key, GET /v1/jobs, the results files, a store that cannot be
// opened or is lost while serving, and retention.
#include <gtest/gtest.h>
#include <rapidjson/document.h>
#include <rapidjson/stringbuffer.h>
#include <rapidjson/writer.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "tests/integration/http_client.h"
#include "tests/integration/server_process.h"
#include "tests/support/postgres_cluster.h"

namespace limn::testing {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

rapidjson::Document parse(const std::string& body) {
  rapidjson::Document doc;
  doc.Parse(body.c_str());
  return doc;
}

std::string jsonString(const std::string& text) {
  rapidjson::StringBuffer out;
  rapidjson::Writer<rapidjson::StringBuffer> writer(out);
  writer.String(text.c_str(), static_cast<rapidjson::SizeType>(text.size()));
  return out.GetString();
}

fs::path tempFolder() {
  static int n = 0;
  fs::path dir = fs::temp_directory_path() /
                 ("limn-jobs-test-" + std::to_string(::getpid()) + "-" + std::to_string(++n));
  fs::create_directories(dir);
  return dir;
}

// A spec of the example `mesh` from `views` random views x two methods at `size` pixels.
std::string jobSpec(int port, const std::string& mesh, int views, int size) {
  HttpResponse obj = get(port, "/examples/" + mesh);
  EXPECT_EQ(obj.status, 200);
  return R"({"meshes":[{"name":")" + mesh + R"(","mesh":{"format":"obj","data":)" +
         jsonString(obj.body) + R"(}}],"methods":["coarse","uniform:1"],"views":)" +
         std::to_string(views) + R"(,"size":)" + std::to_string(size) + "}";
}

// A server on `store` whose leases are short, so that a dead replica's work moves on quickly.
ServerProcess serverOn(const std::string& store, int workers = 1) {
  return ServerProcess::withConfig(
      R"({"workers": )" + std::to_string(workers) + R"(, "jobLeaseSeconds": 2})",
      {"--job-store", store});
}

rapidjson::Document jobOf(int port, const std::string& id) {
  HttpResponse r = get(port, "/v1/jobs/" + id);
  EXPECT_EQ(r.status, 200) << r.body.substr(0, 300);
  return parse(r.body);
}

bool finished(const rapidjson::Document& job) {
  const std::string state = job["state"].GetString();
  return state != "queued" && state != "running";
}

// Polls `port` until the job has finished (or `patience` passed).
rapidjson::Document waitForEnd(int port, const std::string& id, std::chrono::seconds patience) {
  const auto deadline = Clock::now() + patience;
  for (;;) {
    rapidjson::Document job = jobOf(port, id);
    if (finished(job) || Clock::now() > deadline) return job;
    std::this_thread::sleep_for(200ms);
  }
}

// Rows per replica.
std::map<std::string, int> replicasOf(const rapidjson::Document& job) {
  std::map<std::string, int> count;
  for (const auto& row : job["rows"].GetArray()) ++count[row["replica"].GetString()];
  return count;
}

// Every row of the plan once: as many rows as the job has, each key once, and every (view,
// method) pair of `views` x {coarse, uniform:1}.
void expectEveryRowOnce(const rapidjson::Document& job, int views) {
  const int total = job["progress"]["total"].GetInt();
  ASSERT_EQ(total, views * 2);
  ASSERT_EQ(static_cast<int>(job["rows"].Size()), total);
  std::set<std::string> keys, pairs;
  for (const auto& row : job["rows"].GetArray()) {
    keys.insert(row["key"].GetString());
    pairs.insert(std::string(row["view"].GetString()) + " " + row["label"].GetString());
    EXPECT_FALSE(row.HasMember("error")) << row["key"].GetString();
  }
  EXPECT_EQ(static_cast<int>(keys.size()), total) << "a row stored twice";
  EXPECT_EQ(static_cast<int>(pairs.size()), total);
}

TEST(DurableJobs, ThreeReplicasOnPostgresShareAJobAndFinishItWhenOneIsKilled) {
  PostgresCluster postgres;
  const std::string store = postgres.createDatabase();
  std::vector<ServerProcess> replicas;
  for (int i = 0; i < 3; ++i) replicas.push_back(serverOn(store));
  const int views = 90;
  HttpResponse created =
      post(replicas[0].port(), "/v1/jobs", jobSpec(replicas[0].port(), "torus_creased", views, 96));
  ASSERT_EQ(created.status, 202) << created.body.substr(0, 300);
  const std::string id = parse(created.body)["id"].GetString();

  // Any replica answers for it.
  for (ServerProcess& r : replicas) EXPECT_EQ(get(r.port(), "/v1/jobs/" + id).status, 200);
  // All three compute it: wait until each has made rows, then kill one in the middle.
  std::map<std::string, int> made;
  const auto deadline = Clock::now() + 120s;
  while (made.size() < 3 && Clock::now() < deadline) {
    std::this_thread::sleep_for(100ms);
    made = replicasOf(jobOf(replicas[2].port(), id));
  }
  ASSERT_EQ(made.size(), 3u) << "not every replica took a share of the job";
  rapidjson::Document before = jobOf(replicas[2].port(), id);
  ASSERT_FALSE(finished(before)) << "the job ended before a replica could be killed";
  EXPECT_EQ(replicas[1].terminate(SIGKILL), 128 + SIGKILL);

  rapidjson::Document done = waitForEnd(replicas[2].port(), id, 300s);
  ASSERT_STREQ(done["state"].GetString(), "done");
  expectEveryRowOnce(done, views);
  EXPECT_EQ(replicasOf(done).size(), 3u) << "the killed replica's rows are kept";
  // The survivors read the same job.
  EXPECT_EQ(jobOf(replicas[0].port(), id)["progress"]["done"].GetInt(), 2 * views);
  for (int i : {0, 2}) EXPECT_EQ(replicas[i].terminate(SIGTERM), 0);
}

TEST(DurableJobs, AJobOnSqliteOutlivesAKilledProcessAndIsDownloadable) {
  const std::string store = "sqlite:" + (tempFolder() / "jobs.sqlite").string();
  const int views = 40;
  std::string id;
  {
    ServerProcess first = serverOn(store, 2);
    HttpResponse created =
        post(first.port(), "/v1/jobs", jobSpec(first.port(), "torus_creased", views, 96));
    ASSERT_EQ(created.status, 202) << created.body.substr(0, 300);
    id = parse(created.body)["id"].GetString();
    const auto deadline = Clock::now() + 120s;
    while (jobOf(first.port(), id)["progress"]["done"].GetInt() == 0 && Clock::now() < deadline)
      std::this_thread::sleep_for(50ms);
    rapidjson::Document before = jobOf(first.port(), id);
    ASSERT_GT(before["progress"]["done"].GetInt(), 0);
    ASSERT_FALSE(finished(before)) << "the job ended before the process could be killed";
    EXPECT_EQ(first.terminate(SIGKILL), 128 + SIGKILL);
  }
  ServerProcess second = serverOn(store, 2);
  rapidjson::Document done = waitForEnd(second.port(), id, 300s);
  ASSERT_STREQ(done["state"].GetString(), "done");
  expectEveryRowOnce(done, views);
  EXPECT_EQ(replicasOf(done).size(), 2u) << "rows of the killed process and of its successor";

  HttpResponse csv = get(second.port(), "/v1/jobs/" + id + "/results.csv");
  ASSERT_EQ(csv.status, 200);
  EXPECT_NE(csv.header("Content-Type").find("text/csv"), std::string::npos);
  std::istringstream lines(csv.body);
  std::string header, line;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("key,mesh,", 0), 0u) << header;
  EXPECT_NE(header.find("silhouette.outlineHausdorffPx"), std::string::npos);
  int rows = 0;
  while (std::getline(lines, line)) rows += !line.empty();
  EXPECT_EQ(rows, 2 * views);
  HttpResponse jsonl = get(second.port(), "/v1/jobs/" + id + "/results.jsonl");
  ASSERT_EQ(jsonl.status, 200);
  std::istringstream jsonLines(jsonl.body);
  int parsed = 0;
  while (std::getline(jsonLines, line)) {
    EXPECT_FALSE(parse(line).HasParseError()) << line.substr(0, 200);
    ++parsed;
  }
  EXPECT_EQ(parsed, 2 * views);
  EXPECT_EQ(get(second.port(), "/v1/jobs/none/results.csv").status, 404);
  EXPECT_EQ(second.terminate(SIGTERM), 0);
}

TEST(DurableJobs, AnIdempotencyKeyReturnsTheSameJobAndTheListIsPaged) {
  ServerProcess server = serverOn("sqlite:" + (tempFolder() / "jobs.sqlite").string());
  const std::string spec = jobSpec(server.port(), "cube", 1, 32);
  HttpResponse first = post(server.port(), "/v1/jobs", spec, {{"Idempotency-Key", "batch-7"}});
  HttpResponse retry = post(server.port(), "/v1/jobs", spec, {{"Idempotency-Key", "batch-7"}});
  ASSERT_EQ(first.status, 202) << first.body.substr(0, 300);
  EXPECT_EQ(retry.status, 200);
  const std::string id = parse(first.body)["id"].GetString();
  EXPECT_EQ(parse(retry.body)["id"].GetString(), id);
  HttpResponse reused = post(server.port(), "/v1/jobs", jobSpec(server.port(), "cube", 2, 32),
                             {{"Idempotency-Key", "batch-7"}});
  EXPECT_EQ(reused.status, 422);
  EXPECT_NE(reused.body.find("Idempotency-Key"), std::string::npos) << reused.body;
  HttpResponse other = post(server.port(), "/v1/jobs", spec);
  ASSERT_EQ(other.status, 202);
  const std::string otherId = parse(other.body)["id"].GetString();

  // The caller's jobs, newest first, one per page.
  rapidjson::Document page = parse(get(server.port(), "/v1/jobs?limit=1").body);
  ASSERT_EQ(page["jobs"].Size(), 1u);
  EXPECT_EQ(page["jobs"][0]["id"].GetString(), otherId);
  EXPECT_FALSE(page["jobs"][0].HasMember("rows"));
  ASSERT_TRUE(page.HasMember("next"));
  rapidjson::Document next = parse(get(server.port(), page["next"].GetString()).body);
  ASSERT_EQ(next["jobs"].Size(), 1u);
  EXPECT_EQ(next["jobs"][0]["id"].GetString(), id);
  EXPECT_FALSE(next.HasMember("next"));
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(DurableJobs, AStoreThatCannotBeOpenedEndsTheStartNamingIt) {
  const std::string binary = limnBinary();
  CommandResult unreachable =
      runCommand(binary +
                 " serve --listen 127.0.0.1:0 --job-store "
                 "'postgresql:///limn?host=/nonexistent-limn-socket&user=postgres' 2>&1");
  EXPECT_EQ(unreachable.status, 1) << unreachable.output;
  EXPECT_NE(unreachable.output.find("/nonexistent-limn-socket"), std::string::npos)
      << unreachable.output;

  const fs::path notes = tempFolder() / "notes.sqlite";
  std::ofstream(notes) << "not a database, but someone's notes\n";
  CommandResult corrupt = runCommand(
      binary + " serve --listen 127.0.0.1:0 --job-store sqlite:" + notes.string() + " 2>&1");
  EXPECT_EQ(corrupt.status, 1) << corrupt.output;
  EXPECT_NE(corrupt.output.find("not a database"), std::string::npos) << corrupt.output;
  std::ifstream in(notes);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}),
            "not a database, but someone's notes\n");

  CommandResult unknown =
      runCommand("LIMN_JOB_STORE=redis://x " + binary + " serve --listen 127.0.0.1:0 2>&1");
  EXPECT_EQ(unknown.status, 1) << unknown.output;
  EXPECT_NE(unknown.output.find("sqlite:PATH"), std::string::npos) << unknown.output;
}

TEST(DurableJobs, AStoreLostWhileServingIs503ForJobsWhileRendersGoOn) {
  PostgresCluster postgres;
  ServerProcess server = serverOn(postgres.createDatabase());
  HttpResponse created = post(server.port(), "/v1/jobs", jobSpec(server.port(), "cube", 1, 32));
  ASSERT_EQ(created.status, 202);
  const std::string id = parse(created.body)["id"].GetString();
  postgres.stop();
  HttpResponse lost = get(server.port(), "/v1/jobs/" + id);
  EXPECT_EQ(lost.status, 503) << lost.body;
  EXPECT_TRUE(lost.has("Retry-After"));
  EXPECT_NE(lost.body.find("job store"), std::string::npos) << lost.body;
  // /readyz says why, with the store's own words (an operator reads it in the probe's log).
  HttpResponse notReady = get(server.port(), "/readyz");
  EXPECT_EQ(notReady.status, 503);
  EXPECT_NE(notReady.body.find("the job store cannot be reached: "), std::string::npos)
      << notReady.body;
  EXPECT_NE(notReady.body.find("PostgreSQL"), std::string::npos) << notReady.body;
  EXPECT_NE(get(server.port(), "/metrics").body.find("\nlimn_job_store_up 0\n"), std::string::npos);
  HttpResponse render =
      post(server.port(), "/v1/render",
           R"({"mesh":{"format":"obj","data":"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},)"
           R"("camera":{"width":32,"height":32}})");
  EXPECT_EQ(render.status, 200) << render.body.substr(0, 300);

  postgres.start();
  const auto deadline = Clock::now() + 60s;
  while (get(server.port(), "/readyz").status != 200 && Clock::now() < deadline)
    std::this_thread::sleep_for(200ms);
  EXPECT_EQ(get(server.port(), "/readyz").status, 200);
  EXPECT_STREQ(waitForEnd(server.port(), id, 120s)["state"].GetString(), "done");
  const std::string metrics = get(server.port(), "/metrics").body;
  EXPECT_NE(metrics.find("\nlimn_job_store_up 1\n"), std::string::npos);
  EXPECT_NE(metrics.find("\nlimn_job_groups_total{result=\"stored\"} 1\n"), std::string::npos)
      << metrics.substr(metrics.find("limn_job_groups_total"), 300);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

TEST(DurableJobs, AFinishedJobIsForgottenAfterItsRetention) {
  ServerProcess server = ServerProcess::withConfig(
      R"({"workers": 1, "jobLeaseSeconds": 1, "jobRetentionSeconds": 1})",
      {"--job-store", "sqlite:" + (tempFolder() / "jobs.sqlite").string()});
  HttpResponse created = post(server.port(), "/v1/jobs", jobSpec(server.port(), "cube", 1, 32));
  ASSERT_EQ(created.status, 202);
  const std::string id = parse(created.body)["id"].GetString();
  ASSERT_STREQ(waitForEnd(server.port(), id, 120s)["state"].GetString(), "done");
  const auto deadline = Clock::now() + 60s;
  while (get(server.port(), "/v1/jobs/" + id).status == 200 && Clock::now() < deadline)
    std::this_thread::sleep_for(200ms);
  EXPECT_EQ(get(server.port(), "/v1/jobs/" + id).status, 404);
  EXPECT_EQ(server.terminate(SIGTERM), 0);
}

}  // namespace
}  // namespace limn::testing
