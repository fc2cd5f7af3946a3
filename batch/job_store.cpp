#include "batch/job_store.h"

#include <cstdio>
#include <random>
#include <sstream>

namespace limn::batch {
namespace {

int64_t nowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t toInt(const std::string& text) { return text.empty() ? 0 : std::stoll(text); }

std::string joinIndices(const std::vector<size_t>& indices) {
  std::string out;
  for (size_t i : indices) out += (out.empty() ? "" : ",") + std::to_string(i);
  return out;
}

std::vector<size_t> splitIndices(const std::string& text) {
  std::vector<size_t> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(static_cast<size_t>(std::stoull(item)));
  return out;
}

// The current layout (version 2): jobs, their groups (the unit of a lease) and their rows.
const char* const kSchema[] = {
    "CREATE TABLE limn_jobs ("
    " id TEXT PRIMARY KEY, seq BIGINT NOT NULL, client TEXT NOT NULL,"
    " idempotency_key TEXT NOT NULL,"
    " request_hash TEXT NOT NULL, spec TEXT NOT NULL, state TEXT NOT NULL,"
    " total_rows BIGINT NOT NULL, error TEXT NOT NULL, created_ms BIGINT NOT NULL,"
    " finished_ms BIGINT NOT NULL)",
    "CREATE UNIQUE INDEX limn_jobs_idempotency ON limn_jobs (client, idempotency_key)"
    " WHERE idempotency_key <> ''",
    "CREATE INDEX limn_jobs_by_client ON limn_jobs (client, seq)",
    "CREATE TABLE limn_job_groups ("
    " job_id TEXT NOT NULL, group_index BIGINT NOT NULL, row_indices TEXT NOT NULL,"
    " state TEXT NOT NULL, lease_owner TEXT NOT NULL, lease_until_ms BIGINT NOT NULL,"
    " attempts BIGINT NOT NULL, available_ms BIGINT NOT NULL,"
    " PRIMARY KEY (job_id, group_index))",
    // The groups still to do, in order: a claim reads only these, however many are done.
    "CREATE INDEX limn_job_groups_open ON limn_job_groups (job_id, group_index)"
    " WHERE state <> 'done'",
    "CREATE TABLE limn_job_rows ("
    " job_id TEXT NOT NULL, row_index BIGINT NOT NULL, row_key TEXT NOT NULL,"
    " replica TEXT NOT NULL, failed BIGINT NOT NULL, line TEXT NOT NULL,"
    " PRIMARY KEY (job_id, row_index))",
};

// What a job's record is read from (the row counts come from its rows).
const char* const kJobColumns =
    "SELECT j.id, j.client, j.state, j.error, j.total_rows, j.created_ms, j.finished_ms, j.seq,"
    " (SELECT COUNT(*) FROM limn_job_rows r WHERE r.job_id = j.id),"
    " (SELECT COALESCE(SUM(r.failed), 0) FROM limn_job_rows r WHERE r.job_id = j.id)"
    " FROM limn_jobs j ";

JobRecord readRecord(const SqlRow& row) {
  JobRecord job;
  job.id = row[0];
  job.client = row[1];
  job.state = row[2];
  job.error = row[3];
  job.totalRows = static_cast<size_t>(toInt(row[4]));
  job.createdMs = toInt(row[5]);
  job.finishedMs = toInt(row[6]);
  job.sequence = toInt(row[7]);
  job.rowsDone = static_cast<size_t>(toInt(row[8]));
  job.rowsFailed = static_cast<size_t>(toInt(row[9]));
  return job;
}

// Inserts `rows` with `head` ("INSERT INTO t (a, b, c)"), each as `rowTemplate` ("(?, ?, 0)",
// one ? per value of a row), at most 200 rows a statement: on a networked database every
// statement is a round trip. `tail` ends each statement ("ON CONFLICT ...").
void insertMany(SqlDatabase& db, const std::string& head, const std::string& rowTemplate,
                const std::vector<std::vector<SqlParam>>& rows, const std::string& tail = "") {
  constexpr size_t perStatement = 200;
  for (size_t start = 0; start < rows.size(); start += perStatement) {
    const size_t end = std::min(rows.size(), start + perStatement);
    std::string sql = head + " VALUES ";
    std::vector<SqlParam> params;
    for (size_t r = start; r < end; ++r) {
      sql += (r == start ? "" : ",") + rowTemplate;
      params.insert(params.end(), rows[r].begin(), rows[r].end());
    }
    db.query(sql + tail, params);
  }
}

// Version 2 numbers jobs in creation order (limn_jobs.seq: two jobs made in the same
// millisecond still list in order). Version-1 stores made before the column existed gain it,
// numbered by creation time; the ones made after it already have it (the column went in before
// the version was raised, so both layouts are called 1).
void addCreationSequence(SqlDatabase& db) {
  const bool postgres = db.dialect() == SqlDialect::Postgres;
  const std::string columns =
      postgres ? "SELECT COUNT(*) FROM information_schema.columns WHERE table_schema ="
                 " current_schema() AND table_name = 'limn_jobs' AND column_name = 'seq'"
               : "SELECT COUNT(*) FROM pragma_table_info('limn_jobs') WHERE name = 'seq'";
  if (toInt(db.query(columns)[0][0]) != 0) return;
  db.query("ALTER TABLE limn_jobs ADD COLUMN seq BIGINT NOT NULL DEFAULT 0");
  db.query(
      "UPDATE limn_jobs SET seq = (SELECT COUNT(*) FROM limn_jobs o WHERE o.created_ms <"
      " limn_jobs.created_ms OR (o.created_ms = limn_jobs.created_ms AND o.id <= limn_jobs.id))");
  db.query("DROP INDEX limn_jobs_by_client");
  db.query("CREATE INDEX limn_jobs_by_client ON limn_jobs (client, seq)");
}

}  // namespace

std::string newJobId() {
  static std::mutex mutex;
  static std::random_device device;
  std::lock_guard lock(mutex);
  char text[33];
  std::snprintf(text, sizeof text, "%08x%08x%08x%08x", device(), device(), device(), device());
  return text;
}

std::unique_ptr<JobStore> JobStore::open(const std::string& location, std::string replica,
                                         StoreOptions options) {
  std::unique_ptr<SqlDatabase> db;
  if (location.rfind("sqlite:", 0) == 0) {
    const std::string path = location.substr(7);
    if (path.empty()) throw DatabaseError("jobStore \"sqlite:\" names no file", false);
    db = openSqlite(path);
  } else if (location.rfind("postgresql://", 0) == 0 || location.rfind("postgres://", 0) == 0) {
    db = openPostgres(location);
  } else {
    throw DatabaseError("jobStore must be sqlite:PATH or a postgresql:// URI, not \"" +
                            location.substr(0, 80) + "\"",
                        false);
  }
  return std::make_unique<JobStore>(std::move(db), std::move(replica), options);
}

JobStore::JobStore(std::unique_ptr<SqlDatabase> db, std::string replica, StoreOptions options)
    : db_(std::move(db)), replica_(std::move(replica)), options_(options) {
  migrate();
}

std::string JobStore::describe() const { return db_->describe(); }

template <typename Fn>
auto JobStore::locked(Fn&& fn) {
  std::lock_guard lock(mutex_);
  return fn(*db_);
}

void JobStore::migrate() {
  locked([&](SqlDatabase& db) {
    inTransaction(db, [&] {
      const bool postgres = db.dialect() == SqlDialect::Postgres;
      // Replicas starting together: one migrates, the others wait and find it done.
      if (postgres) db.query("SELECT pg_advisory_xact_lock(7236041)");
      const std::vector<SqlRow> tables =
          postgres ? db.query("SELECT tablename FROM pg_tables WHERE schemaname = current_schema()")
                   : db.query("SELECT name FROM sqlite_master WHERE type = 'table'");
      bool hasSchema = false, hasOurs = false, hasOthers = false;
      for (const SqlRow& t : tables) {
        if (t[0] == "limn_schema")
          hasSchema = true;
        else if (t[0].rfind("limn_", 0) == 0)
          hasOurs = true;
        else
          hasOthers = true;
      }
      // A file is limn's alone; a PostgreSQL database may hold other programs' tables too.
      if (!hasSchema && (hasOurs || (hasOthers && !postgres))) {
        throw DatabaseError(describe() +
                                " holds tables that limn did not make (no limn_schema): "
                                "refusing to write into another program's database",
                            false);
      }
      int version = 0;
      if (hasSchema) {
        const auto rows = db.query("SELECT version FROM limn_schema");
        version = rows.empty() ? 0 : static_cast<int>(toInt(rows[0][0]));
      } else {
        db.query("CREATE TABLE limn_schema (version BIGINT NOT NULL)");
        db.query("INSERT INTO limn_schema (version) VALUES (0)");
      }
      if (version > kSchemaVersion) {
        throw DatabaseError(describe() + " has job schema version " + std::to_string(version) +
                                ", written by a newer limn (this one knows up to " +
                                std::to_string(kSchemaVersion) + "): refusing to touch it",
                            false);
      }
      if (version < 1) {
        for (const char* statement : kSchema) db.query(statement);
      } else if (version < 2) {
        addCreationSequence(db);
      }
      db.query("UPDATE limn_schema SET version = ?", {int64_t{kSchemaVersion}});
    });
  });
}

CreateOutcome JobStore::create(const NewJob& job, size_t maxJobs,
                               std::chrono::milliseconds retention) {
  return locked([&](SqlDatabase& db) {
    return inTransaction(db, [&]() -> CreateOutcome {
      // Creations are serialised, so that maxJobs and Idempotency-Key hold across replicas.
      if (db.dialect() == SqlDialect::Postgres)
        db.query("LOCK TABLE limn_jobs IN SHARE ROW EXCLUSIVE MODE");
      if (!job.idempotencyKey.empty()) {
        const auto same = db.query(
            "SELECT id, request_hash FROM limn_jobs WHERE client = ? AND idempotency_key = ?",
            {job.client, job.idempotencyKey});
        if (!same.empty()) {
          auto kind = same[0][1] == job.requestHash ? CreateOutcome::Kind::Existing
                                                    : CreateOutcome::Kind::KeyReused;
          return {kind, *findLocked(same[0][0])};
        }
      }
      const int64_t now = nowMs();
      expireLocked(now - retention.count());
      for (;;) {
        if (static_cast<size_t>(toInt(db.query("SELECT COUNT(*) FROM limn_jobs")[0][0])) < maxJobs)
          break;
        const auto oldest = db.query(
            "SELECT id FROM limn_jobs WHERE finished_ms <> 0 ORDER BY finished_ms LIMIT 1");
        if (oldest.empty()) return {CreateOutcome::Kind::Full, {}};
        deleteJobsLocked("id = ?", {oldest[0][0]});
      }
      const std::string id = newJobId();
      // Creations are serialised (above): the next number is the creation order, which
      // milliseconds alone are not.
      const int64_t seq = toInt(db.query("SELECT COALESCE(MAX(seq), 0) + 1 FROM limn_jobs")[0][0]);
      db.query(
          "INSERT INTO limn_jobs (id, seq, client, idempotency_key, request_hash, spec, state,"
          " total_rows, error, created_ms, finished_ms) VALUES (?, ?, ?, ?, ?, ?, 'queued', ?, '',"
          " ?, 0)",
          {id, seq, job.client, job.idempotencyKey, job.requestHash, job.spec,
           static_cast<int64_t>(job.totalRows), now});
      std::vector<std::vector<SqlParam>> groups;
      for (size_t g = 0; g < job.groups.size(); ++g) {
        groups.push_back({id, static_cast<int64_t>(g), joinIndices(job.groups[g])});
      }
      insertMany(db,
                 "INSERT INTO limn_job_groups (job_id, group_index, row_indices, state,"
                 " lease_owner, lease_until_ms, attempts, available_ms)",
                 "(?, ?, ?, 'pending', '', 0, 0, 0)", groups);
      return {CreateOutcome::Kind::Created, *findLocked(id)};
    });
  });
}

std::optional<JobRecord> JobStore::findLocked(const std::string& id) {
  const auto rows = db_->query(std::string(kJobColumns) + "WHERE j.id = ?", {id});
  if (rows.empty()) return std::nullopt;
  return readRecord(rows[0]);
}

std::optional<JobRecord> JobStore::find(const std::string& id) {
  return locked([&](SqlDatabase&) { return findLocked(id); });
}

std::optional<std::string> JobStore::spec(const std::string& id) {
  return locked([&](SqlDatabase& db) -> std::optional<std::string> {
    const auto rows = db.query("SELECT spec FROM limn_jobs WHERE id = ?", {id});
    if (rows.empty()) return std::nullopt;
    return rows[0][0];
  });
}

std::vector<StoredRow> JobStore::rows(const std::string& id, size_t offset, size_t limit) {
  return locked([&](SqlDatabase& db) {
    std::vector<StoredRow> out;
    for (const SqlRow& row :
         db.query("SELECT row_index, row_key, line, failed FROM limn_job_rows WHERE job_id = ?"
                  " ORDER BY row_index LIMIT ? OFFSET ?",
                  {id, static_cast<int64_t>(limit), static_cast<int64_t>(offset)})) {
      out.push_back({static_cast<size_t>(toInt(row[0])), row[1], row[2], row[3] != "0"});
    }
    return out;
  });
}

JobPage JobStore::list(const std::string& client, const std::string& after, size_t limit) {
  // The cursor is the creation number of the last job of the page before.
  int64_t before = INT64_MAX;
  if (!after.empty() && after.find_first_not_of("0123456789") == std::string::npos &&
      after.size() < 19) {
    before = std::stoll(after);
  }
  return locked([&](SqlDatabase& db) {
    JobPage page;
    for (const SqlRow& row :
         db.query(std::string(kJobColumns) +
                      "WHERE j.client = ? AND j.seq < ? ORDER BY j.seq DESC LIMIT ?",
                  {client, before, static_cast<int64_t>(limit + 1)})) {
      page.jobs.push_back(readRecord(row));
    }
    if (page.jobs.size() > limit) {
      page.jobs.pop_back();
      page.next = std::to_string(page.jobs.back().sequence);
    }
    return page;
  });
}

std::optional<JobRecord> JobStore::cancel(const std::string& id) {
  return locked([&](SqlDatabase& db) {
    db.query(
        "UPDATE limn_jobs SET state = 'cancelled', finished_ms = ?"
        " WHERE id = ? AND state IN ('queued', 'running')",
        {nowMs(), id});
    return findLocked(id);
  });
}

void JobStore::forget(const std::string& id) {
  locked([&](SqlDatabase& db) { inTransaction(db, [&] { deleteJobsLocked("id = ?", {id}); }); });
}

void JobStore::fail(const std::string& id, const std::string& error) {
  locked([&](SqlDatabase& db) {
    db.query(
        "UPDATE limn_jobs SET state = 'failed', error = ?, finished_ms = ?"
        " WHERE id = ? AND state IN ('queued', 'running')",
        {error, nowMs(), id});
  });
}

void JobStore::deleteJobsLocked(const std::string& where, const std::vector<SqlParam>& params) {
  const std::string jobs = "(SELECT id FROM limn_jobs WHERE " + where + ")";
  db_->query("DELETE FROM limn_job_rows WHERE job_id IN " + jobs, params);
  db_->query("DELETE FROM limn_job_groups WHERE job_id IN " + jobs, params);
  db_->query("DELETE FROM limn_jobs WHERE " + where, params);
}

size_t JobStore::expireLocked(int64_t before) {
  const size_t count = static_cast<size_t>(
      toInt(db_->query("SELECT COUNT(*) FROM limn_jobs WHERE finished_ms <> 0 AND finished_ms < ?",
                       {before})[0][0]));
  if (count) deleteJobsLocked("finished_ms <> 0 AND finished_ms < ?", {before});
  return count;
}

size_t JobStore::expire(std::chrono::milliseconds retention) {
  return locked([&](SqlDatabase& db) {
    return inTransaction(db, [&] { return expireLocked(nowMs() - retention.count()); });
  });
}

std::optional<ClaimedGroup> JobStore::claim() {
  return locked([&](SqlDatabase& db) {
    return inTransaction(db, [&]() -> std::optional<ClaimedGroup> {
      const int64_t now = nowMs();
      const bool postgres = db.dialect() == SqlDialect::Postgres;
      // The oldest unfinished job first (there are at most maxJobs), its groups in order.
      for (const SqlRow& job :
           db.query("SELECT id FROM limn_jobs WHERE state IN ('queued', 'running')"
                    " ORDER BY seq")) {
        // Free: pending and due, or leased by a replica that stopped renewing it.
        const std::string freeGroup =
            "SELECT job_id, group_index FROM limn_job_groups WHERE job_id = ? AND state <> 'done'"
            " AND ((state = 'pending' AND available_ms <= ?) OR (state = 'leased' AND "
            "lease_until_ms < ?)) ORDER BY group_index LIMIT 1";
        std::vector<SqlRow> claimed;
        if (postgres) {
          // Replicas claiming at once skip each other's locked rows instead of waiting on them.
          claimed =
              db.query("WITH next AS (" + freeGroup +
                           " FOR UPDATE SKIP LOCKED)"
                           " UPDATE limn_job_groups AS u SET state = 'leased', lease_owner = ?,"
                           " lease_until_ms = ?, attempts = u.attempts + 1 FROM next"
                           " WHERE u.job_id = next.job_id AND u.group_index = next.group_index"
                           " RETURNING u.job_id, u.group_index, u.row_indices, u.attempts",
                       {job[0], now, now, replica_, now + options_.lease.count()});
        } else {
          // BEGIN IMMEDIATE holds the file's write lock: one claim at a time.
          claimed = db.query(
              "UPDATE limn_job_groups SET state = 'leased', lease_owner = ?, lease_until_ms = ?,"
              " attempts = attempts + 1 WHERE (job_id, group_index) IN (" +
                  freeGroup +
                  ")"
                  " RETURNING job_id, group_index, row_indices, attempts",
              {replica_, now + options_.lease.count(), job[0], now, now});
        }
        if (claimed.empty()) continue;
        ClaimedGroup group{claimed[0][0], static_cast<size_t>(toInt(claimed[0][1])),
                           splitIndices(claimed[0][2]), static_cast<int>(toInt(claimed[0][3]))};
        db.query("UPDATE limn_jobs SET state = 'running' WHERE id = ? AND state = 'queued'",
                 {group.jobId});
        return group;
      }
      return std::nullopt;
    });
  });
}

void JobStore::complete(const ClaimedGroup& group, const std::vector<StoredRow>& rows) {
  locked([&](SqlDatabase& db) {
    inTransaction(db, [&] {
      // The job's row is locked first: two replicas finishing its last groups see each other's
      // commits, so one of them marks it done; a job forgotten meanwhile takes no rows.
      const char* lock = db.dialect() == SqlDialect::Postgres ? " FOR UPDATE" : "";
      if (db.query(std::string("SELECT state FROM limn_jobs WHERE id = ?") + lock, {group.jobId})
              .empty())
        return;
      std::vector<std::vector<SqlParam>> values;
      for (const StoredRow& row : rows) {
        values.push_back({group.jobId, static_cast<int64_t>(row.index), row.key, replica_,
                          int64_t{row.failed ? 1 : 0}, row.line});
      }
      insertMany(db,
                 "INSERT INTO limn_job_rows (job_id, row_index, row_key, replica, failed, line)",
                 "(?, ?, ?, ?, ?, ?)", values, " ON CONFLICT (job_id, row_index) DO NOTHING");
      db.query(
          "UPDATE limn_job_groups SET state = 'done', lease_owner = ''"
          " WHERE job_id = ? AND group_index = ?",
          {group.jobId, static_cast<int64_t>(group.group)});
      db.query(
          "UPDATE limn_jobs SET state = 'done', finished_ms = ? WHERE id = ? AND state = 'running'"
          " AND NOT EXISTS (SELECT 1 FROM limn_job_groups WHERE job_id = ? AND state <> 'done')",
          {nowMs(), group.jobId, group.jobId});
    });
  });
}

void JobStore::release(const ClaimedGroup& group, std::chrono::milliseconds delay, bool counted) {
  locked([&](SqlDatabase& db) {
    db.query(
        "UPDATE limn_job_groups SET state = 'pending', lease_owner = '', available_ms = ?,"
        " attempts = attempts - ? WHERE job_id = ? AND group_index = ? AND lease_owner = ?"
        " AND state = 'leased'",
        {nowMs() + delay.count(), int64_t{counted ? 0 : 1}, group.jobId,
         static_cast<int64_t>(group.group), replica_});
  });
}

std::vector<std::string> JobStore::heartbeat(
    const std::vector<std::pair<std::string, size_t>>& held) {
  return locked([&](SqlDatabase& db) {
    return inTransaction(db, [&] {
      const int64_t until = nowMs() + options_.lease.count();
      for (const auto& [job, group] : held) {
        db.query(
            "UPDATE limn_job_groups SET lease_until_ms = ? WHERE job_id = ? AND group_index = ?"
            " AND lease_owner = ? AND state = 'leased'",
            {until, job, static_cast<int64_t>(group), replica_});
      }
      std::string notHeld;
      std::vector<SqlParam> params{replica_};
      for (const auto& [job, group] : held) {
        // The cast: PostgreSQL reads an untyped parameter in VALUES as text.
        notHeld += notHeld.empty()
                       ? " AND (job_id, group_index) NOT IN (VALUES (?, CAST(? AS BIGINT))"
                       : ", (?, CAST(? AS BIGINT))";
        params.push_back(job);
        params.push_back(static_cast<int64_t>(group));
      }
      if (!notHeld.empty()) notHeld += ")";
      db.query(
          "UPDATE limn_job_groups SET state = 'pending', lease_owner = '', attempts = attempts - 1"
          " WHERE lease_owner = ? AND state = 'leased'" +
              notHeld,
          params);
      std::vector<std::string> stopped;
      for (const SqlRow& row :
           db.query("SELECT DISTINCT g.job_id FROM limn_job_groups g LEFT JOIN limn_jobs j"
                    " ON j.id = g.job_id WHERE g.lease_owner = ? AND g.state = 'leased'"
                    " AND (j.id IS NULL OR j.state NOT IN ('queued', 'running'))",
                    {replica_})) {
        stopped.push_back(row[0]);
      }
      return stopped;
    });
  });
}

void JobStore::releaseAll() {
  locked([&](SqlDatabase& db) {
    db.query(
        "UPDATE limn_job_groups SET state = 'pending', lease_owner = '', attempts = attempts - 1"
        " WHERE lease_owner = ? AND state = 'leased'",
        {replica_});
  });
}

void JobStore::ping() {
  locked([&](SqlDatabase& db) {
    try {
      db.query("SELECT 1");
    } catch (const DatabaseError& e) {
      if (!e.lost) throw;
      db.reconnect();
      db.query("SELECT 1");
    }
  });
}

}  // namespace limn::batch
