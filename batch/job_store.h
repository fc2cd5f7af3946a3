// JobStore: the batch jobs of a server (POST /v1/jobs) kept in a database, so that they outlive
// the process that took them and any replica sharing the database can read them and compute
// their rows.
//
// A job is its spec (self-contained: every mesh inline), its row groups (one /v1/compare each,
// numbered when the job is created) and the rows made so far. Replicas share the work by
// leases: claim() takes the oldest job's next free group for `lease`, heartbeat() extends the
// leases a replica holds, and a group whose lease ran out (its replica died) is claimed again.
// Rows are keyed by (job, row index) and stored once: a group computed twice adds nothing.
//
// Two backends behind one set of SQL statements (batch/sql_database.h): "sqlite:PATH" (the
// default: a file, shared by the processes of one machine through SQLite's lock) and
// "postgresql://..." (several machines; claims use SELECT ... FOR UPDATE SKIP LOCKED). The
// schema is created and migrated by open(), versioned in limn_schema; docs/deploy.md has it.
//
// Times are wall-clock milliseconds of the replica that writes them: replicas of a cluster must
// keep their clocks within a fraction of the lease (NTP does). Thread-safe: one connection
// behind a mutex. Every failure throws DatabaseError; `lost` ones mean "try again later".
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "batch/sql_database.h"

namespace limn::batch {

struct StoreOptions {
  std::chrono::milliseconds lease{30'000};  // a claimed group's, renewed by heartbeat()
};

struct NewJob {
  std::string client;          // who created it: GET /v1/jobs lists a client's own jobs
  std::string idempotencyKey;  // "" for none
  std::string requestHash;     // of the POST body: a reused key with another body is refused
  std::string spec;            // the job's spec, every mesh inline
  size_t totalRows = 0;
  std::vector<std::vector<size_t>> groups;  // the row indices of each group
};

struct JobRecord {
  std::string id, client, state, error;  // state: queued, running, done, cancelled, failed
  size_t totalRows = 0, rowsDone = 0, rowsFailed = 0;
  int64_t createdMs = 0, finishedMs = 0;  // wall clock; finishedMs 0 while unfinished
  int64_t sequence = 0;                   // creation order in the store
  bool finished() const { return finishedMs != 0; }
};

struct CreateOutcome {
  enum class Kind {
    Created,
    Existing,   // the client's Idempotency-Key named this job already (same body)
    KeyReused,  // ... with another body
    Full,       // maxJobs jobs are held and none is finished
  };
  Kind kind;
  JobRecord job;  // Created, Existing, KeyReused: the job
};

struct ClaimedGroup {
  std::string jobId;
  size_t group = 0;
  std::vector<size_t> rows;
  int attempts = 0;  // claims of this group so far, this one included
};

struct StoredRow {
  size_t index = 0;
  std::string key, line;
  bool failed = false;
};

struct JobPage {
  std::vector<JobRecord> jobs;  // newest first
  std::string next;             // the cursor of the next page ("" on the last)
};

class JobStore {
 public:
  // "sqlite:PATH" (":memory:" for a private one), or a postgresql:// (postgres://) URI. Creates
  // or migrates the schema; refuses a file that is not a database, a database whose tables are
  // another program's, and a schema from a newer limn (DatabaseError naming the store).
  static std::unique_ptr<JobStore> open(const std::string& location, std::string replica,
                                        StoreOptions options = {});
  JobStore(std::unique_ptr<SqlDatabase> db, std::string replica, StoreOptions options);

  const std::string& replica() const { return replica_; }
  std::chrono::milliseconds lease() const { return options_.lease; }
  std::string describe() const;
  static constexpr int kSchemaVersion = 2;

  // Drops the jobs finished before `retention`, makes room (the oldest finished job goes while
  // `maxJobs` are held), and inserts the job; or finds the client's job of the same key.
  CreateOutcome create(const NewJob& job, size_t maxJobs, std::chrono::milliseconds retention);
  std::optional<JobRecord> find(const std::string& id);
  std::optional<std::string> spec(const std::string& id);
  // The stored row lines from `offset`, in row order (at most `limit`).
  std::vector<StoredRow> rows(const std::string& id, size_t offset, size_t limit);
  // A client's jobs, newest first, from the cursor `after` ("" for the first page).
  JobPage list(const std::string& client, const std::string& after, size_t limit);
  // Cancels a queued or running job; the record after (nothing for an unknown id).
  std::optional<JobRecord> cancel(const std::string& id);
  // Deletes a job and its rows.
  void forget(const std::string& id);
  // Ends a job that cannot run (its spec unreadable here) with `error`.
  void fail(const std::string& id, const std::string& error);
  // Deletes the jobs finished before `retention`; how many.
  size_t expire(std::chrono::milliseconds retention);

  // The next group to compute (its lease this replica's), or nothing.
  std::optional<ClaimedGroup> claim();
  // Stores a group's rows (those stored already stay as they are) and ends its lease; the job
  // is done when every group is.
  void complete(const ClaimedGroup& group, const std::vector<StoredRow>& rows);
  // Gives a group back to be claimed after `delay`; `counted` false: this claim does not count
  // as an attempt (a shutdown, not the group's fault).
  void release(const ClaimedGroup& group, std::chrono::milliseconds delay, bool counted);
  // Renews the leases of the groups this replica is computing (`held`: job id and group) and
  // hands back, uncounted, any other lease it holds (a group whose rows could not be stored
  // while the store was lost); the jobs among `held` that are no longer running (cancelled,
  // forgotten elsewhere).
  std::vector<std::string> heartbeat(const std::vector<std::pair<std::string, size_t>>& held);
  // Gives back every lease this replica holds, uncounted (a clean shutdown).
  void releaseAll();
  // A round trip, reconnecting when the connection was lost; throws while it stays lost.
  void ping();

 private:
  void migrate();
  template <typename Fn>
  auto locked(Fn&& fn);
  std::optional<JobRecord> findLocked(const std::string& id);
  void deleteJobsLocked(const std::string& where, const std::vector<SqlParam>& params);
  size_t expireLocked(int64_t before);

  std::mutex mutex_;
  std::unique_ptr<SqlDatabase> db_;
  std::string replica_;
  StoreOptions options_;
};

// A job id nobody can guess: 32 hex digits.
std::string newJobId();

}  // namespace limn::batch
