// What the job store costs per row: a 1,000-row job stored and claimed group by group on SQLite
// (a file) and PostgreSQL (a throwaway server on a Unix socket), with result lines of the size
// limn's rows have (about 1.5 kB). Prints one table: per group size, the time to create the job,
// to claim a group, to store a group's rows, and the store's time per row — to set beside a
// row's own compute time (tens to hundreds of ms: bench/load_results.md, "Jobs").
//
//   build/bin/job_store_bench [rows]      (default 1000)
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "batch/job_store.h"
#include "tests/support/postgres_cluster.h"

namespace {

using namespace limn::batch;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Timing {
  double createMs = 0, claimMs = 0, completeMs = 0, perRowUs = 0;
};

Timing measure(const std::string& location, size_t rows, size_t groupSize) {
  auto store = JobStore::open(location, "bench");
  NewJob job;
  job.client = "bench";
  job.requestHash = "h";
  job.spec = std::string(2000, 's');
  job.totalRows = rows;
  for (size_t r = 0; r < rows; r += groupSize) {
    std::vector<size_t> group;
    for (size_t k = r; k < std::min(rows, r + groupSize); ++k) group.push_back(k);
    job.groups.push_back(group);
  }
  Timing t;
  auto start = Clock::now();
  store->create(job, 1000000, std::chrono::hours(1));
  t.createMs = msSince(start);
  const std::string line = "{\"row\":\"" + std::string(1500, 'x') + "\"}";
  double claimMs = 0, completeMs = 0;
  size_t groups = 0;
  for (;;) {
    auto c = Clock::now();
    std::optional<ClaimedGroup> group = store->claim();
    claimMs += msSince(c);
    if (!group) break;
    std::vector<StoredRow> stored;
    for (size_t r : group->rows) stored.push_back({r, "key " + std::to_string(r), line, false});
    auto d = Clock::now();
    store->complete(*group, stored);
    completeMs += msSince(d);
    ++groups;
  }
  t.claimMs = claimMs / static_cast<double>(groups);
  t.completeMs = completeMs / static_cast<double>(groups);
  t.perRowUs = (claimMs + completeMs) * 1000.0 / static_cast<double>(rows);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const size_t rows = argc > 1 ? std::stoul(argv[1]) : 1000;
  namespace fs = std::filesystem;
  const fs::path folder =
      fs::temp_directory_path() / ("limn-store-bench-" + std::to_string(::getpid()));
  fs::create_directories(folder);
  limn::testing::PostgresCluster postgres;
  std::printf(
      "| store | rows per group | create job (ms) | claim a group (ms) | store a group (ms) | "
      "store time per row (µs) |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  int n = 0;
  for (size_t groupSize : {1, 2, 8, 32}) {
    for (const char* backend : {"sqlite", "postgresql"}) {
      const std::string location =
          std::string(backend) == "sqlite"
              ? "sqlite:" + (folder / ("jobs" + std::to_string(++n) + ".sqlite")).string()
              : postgres.createDatabase();
      Timing t = measure(location, rows, groupSize);
      std::printf("| %s | %zu | %.1f | %.2f | %.2f | %.0f |\n", backend, groupSize, t.createMs,
                  t.claimMs, t.completeMs, t.perRowUs);
      std::fflush(stdout);
    }
  }
  fs::remove_all(folder);
  return 0;
}
