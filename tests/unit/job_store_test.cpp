// batch::JobStore on both backends — SQLite on a temporary file and a throwaway PostgreSQL
// server — and what only one of them has (a file that is not limn's, a server that goes away).
#include "batch/job_store.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "tests/support/postgres_cluster.h"

namespace limn::batch {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Kind = CreateOutcome::Kind;

// One PostgreSQL server for the whole program (initdb takes seconds); a database per test.
testing::PostgresCluster& cluster() {
  static testing::PostgresCluster instance;
  return instance;
}

fs::path tempFolder() {
  static int n = 0;
  fs::path dir = fs::temp_directory_path() /
                 ("limn-store-test-" + std::to_string(::getpid()) + "-" + std::to_string(++n));
  fs::create_directories(dir);
  return dir;
}

// A job of `groups` groups of 3 rows each.
NewJob jobOf(size_t groups, const std::string& client = "peer:127.0.0.1",
             const std::string& key = "") {
  NewJob job;
  job.client = client;
  job.idempotencyKey = key;
  job.requestHash = "hash-" + std::to_string(groups);
  job.spec = "{\"spec\":" + std::to_string(groups) + "}";
  for (size_t g = 0; g < groups; ++g) job.groups.push_back({3 * g, 3 * g + 1, 3 * g + 2});
  job.totalRows = 3 * groups;
  return job;
}

std::vector<StoredRow> rowsOf(const ClaimedGroup& group, const std::string& tag) {
  std::vector<StoredRow> rows;
  for (size_t r : group.rows) {
    rows.push_back({r, "key" + std::to_string(r), "{\"tag\":\"" + tag + "\"}", r % 3 == 2});
  }
  return rows;
}

class JobStoreTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    location_ = GetParam() == "sqlite" ? "sqlite:" + (tempFolder() / "jobs.sqlite").string()
                                       : cluster().createDatabase();
  }
  // Another replica on the same database (its own connection).
  std::unique_ptr<JobStore> replica(const std::string& name,
                                    std::chrono::milliseconds lease = 30s) {
    return JobStore::open(location_, name, {lease});
  }
  std::string location_;
};

TEST_P(JobStoreTest, JobsAreReadFromEveryReplicaAndListedPerClient) {
  auto a = replica("a"), b = replica("b");
  CreateOutcome first = a->create(jobOf(2, "peer:1"), 8, 1h);
  ASSERT_EQ(first.kind, Kind::Created);
  EXPECT_EQ(first.job.state, "queued");
  EXPECT_EQ(first.job.totalRows, 6u);
  CreateOutcome second = a->create(jobOf(1, "peer:1"), 8, 1h);
  a->create(jobOf(1, "peer:2"), 8, 1h);
  std::optional<JobRecord> seen = b->find(first.job.id);
  ASSERT_TRUE(seen);
  EXPECT_EQ(seen->client, "peer:1");
  EXPECT_EQ(b->spec(first.job.id), "{\"spec\":2}");
  EXPECT_FALSE(b->find("no-such-job"));
  // Newest first, a page at a time.
  JobPage page = b->list("peer:1", "", 1);
  ASSERT_EQ(page.jobs.size(), 1u);
  EXPECT_EQ(page.jobs[0].id, second.job.id);
  ASSERT_FALSE(page.next.empty());
  JobPage rest = b->list("peer:1", page.next, 1);
  ASSERT_EQ(rest.jobs.size(), 1u);
  EXPECT_EQ(rest.jobs[0].id, first.job.id);
  EXPECT_TRUE(rest.next.empty());
  EXPECT_EQ(b->list("peer:2", "", 10).jobs.size(), 1u);
}

TEST_P(JobStoreTest, AnIdempotencyKeyNamesOneJobPerClient) {
  auto store = replica("a");
  CreateOutcome first = store->create(jobOf(2, "peer:1", "k"), 8, 1h);
  CreateOutcome again = store->create(jobOf(2, "peer:1", "k"), 8, 1h);
  EXPECT_EQ(again.kind, Kind::Existing);
  EXPECT_EQ(again.job.id, first.job.id);
  EXPECT_EQ(store->create(jobOf(3, "peer:1", "k"), 8, 1h).kind, Kind::KeyReused);
  // Another client's key is its own.
  EXPECT_EQ(store->create(jobOf(2, "peer:2", "k"), 8, 1h).kind, Kind::Created);
}

TEST_P(JobStoreTest, GroupsAreClaimedOnceAndTheirRowsStoredOnce) {
  auto a = replica("a"), b = replica("b");
  const std::string id = a->create(jobOf(3), 8, 1h).job.id;
  std::optional<ClaimedGroup> g0 = a->claim(), g1 = b->claim(), g2 = a->claim();
  ASSERT_TRUE(g0 && g1 && g2);
  EXPECT_FALSE(b->claim());
  EXPECT_EQ(std::set<size_t>({g0->group, g1->group, g2->group}), std::set<size_t>({0, 1, 2}));
  EXPECT_EQ(a->find(id)->state, "running");
  a->complete(*g0, rowsOf(*g0, "a"));
  a->complete(*g0, rowsOf(*g0, "again"));  // a group done twice adds nothing
  b->complete(*g1, rowsOf(*g1, "b"));
  EXPECT_EQ(a->find(id)->state, "running");
  a->complete(*g2, rowsOf(*g2, "a"));
  JobRecord done = *b->find(id);
  EXPECT_EQ(done.state, "done");
  EXPECT_EQ(done.rowsDone, 9u);
  EXPECT_EQ(done.rowsFailed, 3u);
  EXPECT_TRUE(done.finished());
  std::vector<StoredRow> rows = b->rows(id, 0, 100);
  ASSERT_EQ(rows.size(), 9u);
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].index, i);
    EXPECT_NE(rows[i].line, "{\"tag\":\"again\"}");
  }
  EXPECT_EQ(b->rows(id, 7, 100).size(), 2u);
}

TEST_P(JobStoreTest, ALeaseThatRunsOutIsClaimedByAnotherReplica) {
  auto dead = replica("dead", 300ms), alive = replica("alive", 300ms);
  const std::string id = dead->create(jobOf(1), 8, 1h).job.id;
  std::optional<ClaimedGroup> lost = dead->claim();
  ASSERT_TRUE(lost);
  EXPECT_FALSE(alive->claim());  // leased
  std::this_thread::sleep_for(400ms);
  std::optional<ClaimedGroup> again = alive->claim();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->group, lost->group);
  EXPECT_EQ(again->attempts, 2);
  alive->complete(*again, rowsOf(*again, "alive"));
  dead->complete(*lost, rowsOf(*lost, "dead"));  // the late one stores nothing new
  for (const StoredRow& row : alive->rows(id, 0, 10)) EXPECT_EQ(row.line, "{\"tag\":\"alive\"}");
}

TEST_P(JobStoreTest, HeartbeatsKeepALeaseAndNameCancelledJobs) {
  // Renewed every 300 ms, a 1 s lease outlives itself (a stall of 0.7 s would break this).
  auto a = replica("a", 1s), b = replica("b", 1s);
  const std::string id = a->create(jobOf(2), 8, 1h).job.id;
  std::optional<ClaimedGroup> mine = a->claim();
  ASSERT_TRUE(mine);
  const std::vector<std::pair<std::string, size_t>> held{{id, mine->group}};
  for (int i = 0; i < 5; ++i) {
    std::this_thread::sleep_for(300ms);
    EXPECT_TRUE(a->heartbeat(held).empty());
  }
  std::optional<ClaimedGroup> other = b->claim();
  ASSERT_TRUE(other);  // the second group, not the renewed first
  EXPECT_NE(other->group, mine->group);
  EXPECT_FALSE(b->claim());
  EXPECT_EQ(a->cancel(id)->state, "cancelled");
  EXPECT_EQ(a->heartbeat(held), std::vector<std::string>{id});
  b->releaseAll();
  EXPECT_FALSE(b->claim());  // a cancelled job gives nothing more
}

// A lease the replica no longer works on (its rows could not be stored while the store was
// lost) is handed back by the next heartbeat, not renewed forever.
TEST_P(JobStoreTest, AHeartbeatHandsBackTheLeasesItNoLongerWorksOn) {
  auto a = replica("a"), b = replica("b");
  a->create(jobOf(1), 8, 1h);
  std::optional<ClaimedGroup> lost = a->claim();
  ASSERT_TRUE(lost);
  EXPECT_FALSE(b->claim());
  EXPECT_TRUE(a->heartbeat({}).empty());
  std::optional<ClaimedGroup> again = b->claim();
  ASSERT_TRUE(again);
  EXPECT_EQ(again->group, lost->group);
  EXPECT_EQ(again->attempts, 1) << "handing it back is not the group's fault";
}

TEST_P(JobStoreTest, AReleasedGroupWaitsItsDelayAndAShutdownDoesNotCountAsAnAttempt) {
  auto store = replica("a");
  store->create(jobOf(1), 8, 1h);
  ClaimedGroup first = *store->claim();
  EXPECT_EQ(first.attempts, 1);
  store->release(first, 1500ms, true);
  EXPECT_FALSE(store->claim());
  std::this_thread::sleep_for(1600ms);
  ClaimedGroup second = *store->claim();
  EXPECT_EQ(second.attempts, 2);
  store->releaseAll();
  EXPECT_EQ(store->claim()->attempts, 2);
}

TEST_P(JobStoreTest, MaxJobsEvictsTheOldestFinishedJobAndRetentionExpiresJobs) {
  auto store = replica("a");
  const std::string done = store->create(jobOf(1), 2, 1h).job.id;
  ClaimedGroup g = *store->claim();
  store->complete(g, rowsOf(g, "x"));
  const std::string waiting = store->create(jobOf(1), 2, 1h).job.id;
  // Full: the finished job makes room; then only unfinished jobs are held.
  EXPECT_EQ(store->create(jobOf(1), 2, 1h).kind, Kind::Created);
  EXPECT_FALSE(store->find(done));
  EXPECT_EQ(store->create(jobOf(1), 2, 1h).kind, Kind::Full);
  // Retention: a job finished longer ago than it is gone, with its rows.
  store->cancel(waiting);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(store->expire(10ms), 1u);
  EXPECT_FALSE(store->find(waiting));
  EXPECT_EQ(store->expire(10ms), 0u);
}

TEST_P(JobStoreTest, ConcurrentReplicasNeverComputeAGroupTwice) {
  const std::string id = replica("creator")->create(jobOf(60), 8, 1h).job.id;
  std::mutex mutex;
  std::vector<size_t> claimed;
  std::vector<std::thread> threads;
  for (int r = 0; r < 4; ++r) {
    threads.emplace_back([&, r] {
      auto store = replica("r" + std::to_string(r));
      while (std::optional<ClaimedGroup> g = store->claim()) {
        store->complete(*g, rowsOf(*g, "r"));
        std::lock_guard lock(mutex);
        claimed.push_back(g->group);
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(claimed.size(), 60u);
  EXPECT_EQ(std::set<size_t>(claimed.begin(), claimed.end()).size(), 60u);
  EXPECT_EQ(replica("reader")->find(id)->state, "done");
}

// The first published layout (schema version 1, before jobs had a creation sequence), as a
// store made by that limn holds it: two jobs made in the same millisecond, one group each.
void writeFirstLayout(SqlDatabase& db) {
  for (const char* statement : {
           "CREATE TABLE limn_schema (version BIGINT NOT NULL)",
           "INSERT INTO limn_schema (version) VALUES (1)",
           "CREATE TABLE limn_jobs (id TEXT PRIMARY KEY, client TEXT NOT NULL,"
           " idempotency_key TEXT NOT NULL, request_hash TEXT NOT NULL, spec TEXT NOT NULL,"
           " state TEXT NOT NULL, total_rows BIGINT NOT NULL, error TEXT NOT NULL,"
           " created_ms BIGINT NOT NULL, finished_ms BIGINT NOT NULL)",
           "CREATE INDEX limn_jobs_by_client ON limn_jobs (client, created_ms)",
           "CREATE TABLE limn_job_groups (job_id TEXT NOT NULL, group_index BIGINT NOT NULL,"
           " row_indices TEXT NOT NULL, state TEXT NOT NULL, lease_owner TEXT NOT NULL,"
           " lease_until_ms BIGINT NOT NULL, attempts BIGINT NOT NULL,"
           " available_ms BIGINT NOT NULL, PRIMARY KEY (job_id, group_index))",
           "CREATE TABLE limn_job_rows (job_id TEXT NOT NULL, row_index BIGINT NOT NULL,"
           " row_key TEXT NOT NULL, replica TEXT NOT NULL, failed BIGINT NOT NULL,"
           " line TEXT NOT NULL, PRIMARY KEY (job_id, row_index))",
           "INSERT INTO limn_jobs VALUES ('job-a', 'peer:1', '', 'h', '{}', 'queued', 3, '',"
           " 5000, 0)",
           "INSERT INTO limn_jobs VALUES ('job-b', 'peer:1', '', 'h', '{}', 'queued', 3, '',"
           " 5000, 0)",
           "INSERT INTO limn_job_groups VALUES ('job-a', 0, '0,1,2', 'pending', '', 0, 0, 0)",
           "INSERT INTO limn_job_groups VALUES ('job-b', 0, '0,1,2', 'pending', '', 0, 0, 0)",
       }) {
    db.query(statement);
  }
}

TEST_P(JobStoreTest, AStoreOfTheFirstLayoutIsMigratedWithItsJobs) {
  {
    auto db = GetParam() == "sqlite" ? openSqlite(location_.substr(7)) : openPostgres(location_);
    writeFirstLayout(*db);
  }
  auto store = replica("a");
  const std::string newest = store->create(jobOf(1, "peer:1"), 8, 1h).job.id;
  JobPage page = store->list("peer:1", "", 10);
  ASSERT_EQ(page.jobs.size(), 3u);
  EXPECT_EQ(page.jobs[0].id, newest);
  EXPECT_EQ(page.jobs[1].id, "job-b");
  EXPECT_EQ(page.jobs[2].id, "job-a");
  // Work goes on where the old limn left it: the oldest job's group first.
  std::optional<ClaimedGroup> group = store->claim();
  ASSERT_TRUE(group);
  EXPECT_EQ(group->jobId, "job-a");
  store->complete(*group, rowsOf(*group, "a"));
  EXPECT_EQ(store->rows("job-a", 0, 100).size(), 3u);
  // Opened again, it is the current layout: nothing migrates twice.
  EXPECT_EQ(replica("b")->list("peer:1", "", 10).jobs.size(), 3u);
}

INSTANTIATE_TEST_SUITE_P(Backends, JobStoreTest, ::testing::Values("sqlite", "postgresql"),
                         [](const auto& info) { return info.param; });

std::string fileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(JobStoreFiles, AFileThatIsNotADatabaseIsRefusedAndLeftAsItWas) {
  const fs::path file = tempFolder() / "notes.txt";
  std::ofstream(file) << std::string(5000, 'x');
  try {
    JobStore::open("sqlite:" + file.string(), "a");
    FAIL() << "opened a text file as a job store";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a database"), std::string::npos) << e.what();
  }
  EXPECT_EQ(fileBytes(file), std::string(5000, 'x'));
}

TEST(JobStoreFiles, AnotherProgramsDatabaseIsRefused) {
  const fs::path file = tempFolder() / "theirs.sqlite";
  openSqlite(file.string())->query("CREATE TABLE invoices (id INTEGER)");
  try {
    JobStore::open("sqlite:" + file.string(), "a");
    FAIL() << "wrote into another program's database";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("did not make"), std::string::npos) << e.what();
  }
  EXPECT_EQ(openSqlite(file.string())
                ->query("SELECT COUNT(*) FROM sqlite_master WHERE name LIKE 'limn_%'")[0][0],
            "0");
}

TEST(JobStoreFiles, ASchemaFromANewerLimnIsRefused) {
  const std::string location = "sqlite:" + (tempFolder() / "jobs.sqlite").string();
  JobStore::open(location, "a")->create(jobOf(1), 8, 1h);
  openSqlite(location.substr(7))->query("UPDATE limn_schema SET version = 99");
  try {
    JobStore::open(location, "a");
    FAIL() << "opened a newer schema";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("newer limn"), std::string::npos) << e.what();
  }
  EXPECT_EQ(openSqlite(location.substr(7))->query("SELECT COUNT(*) FROM limn_jobs")[0][0], "1");
}

TEST(JobStoreLocations, AnUnknownLocationOrAnUnreachableServerIsNamed) {
  try {
    JobStore::open("mysql://db/limn", "a");
    FAIL();
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("sqlite:PATH"), std::string::npos) << e.what();
  }
  try {
    JobStore::open("postgresql:///limn?host=/nonexistent-limn-socket&user=postgres", "a");
    FAIL();
  } catch (const DatabaseError& e) {
    EXPECT_TRUE(e.lost);
    EXPECT_NE(std::string(e.what()).find("/nonexistent-limn-socket"), std::string::npos)
        << e.what();
  }
}

// A role that may connect but not create tables (PostgreSQL 15 grants no CREATE on the public
// schema to other roles than its owner) is told so at start, naming the store.
TEST(JobStorePostgres, ARoleWithoutRightsIsToldSoAtStart) {
  const std::string uri = cluster().createDatabase();
  openPostgres(uri)->query("CREATE ROLE limn_no_rights LOGIN");
  std::string other = uri;
  other.replace(other.find("user=postgres"), 13, "user=limn_no_rights");
  try {
    JobStore::open(other, "a");
    FAIL() << "created tables without the right to";
  } catch (const DatabaseError& e) {
    EXPECT_FALSE(e.lost);
    EXPECT_NE(std::string(e.what()).find("permission denied"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("PostgreSQL database"), std::string::npos) << e.what();
  }
}

// A PostgreSQL server that goes away and comes back: calls fail as "lost" meanwhile, and the
// same store object works again once ping() reconnects.
TEST(JobStorePostgres, AServerThatGoesAwayIsLostUntilItComesBack) {
  testing::PostgresCluster own;  // not the shared one: this test stops it
  auto store = JobStore::open(own.createDatabase(), "a");
  const std::string id = store->create(jobOf(1), 8, 1h).job.id;
  own.stop();
  try {
    store->find(id);
    FAIL() << "read from a stopped server";
  } catch (const DatabaseError& e) {
    EXPECT_TRUE(e.lost) << e.what();
  }
  own.start();
  store->ping();
  EXPECT_EQ(store->find(id)->state, "queued");
}

}  // namespace
}  // namespace limn::batch
