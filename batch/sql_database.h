// SqlDatabase: the few things the job store needs from a SQL database — statements with bound
// parameters, rows of text back, transactions — over SQLite (a file, one machine) or PostgreSQL
// (a server several replicas share). The store writes its SQL once, with `?` placeholders; each
// connection translates what differs (PostgreSQL numbers its placeholders $1, $2, ...).
//
// A connection is used by one thread at a time (the store holds a mutex around it). Every
// failure throws DatabaseError; `lost` says the database could not be reached at all (a server
// gone, a file that cannot be opened), as opposed to a statement it refused.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace limn::batch {

struct DatabaseError : std::runtime_error {
  DatabaseError(const std::string& message, bool lost) : std::runtime_error(message), lost(lost) {}
  bool lost;
};

using SqlParam = std::variant<int64_t, std::string>;
using SqlRow = std::vector<std::string>;  // NULL reads as ""

enum class SqlDialect { Sqlite, Postgres };

class SqlDatabase {
 public:
  virtual ~SqlDatabase() = default;
  virtual SqlDialect dialect() const = 0;
  // Where it is, for messages: the file, or the server and database (never a password).
  virtual std::string describe() const = 0;
  // Runs one statement; the rows it returns (SELECT, ... RETURNING), as text.
  virtual std::vector<SqlRow> query(const std::string& sql,
                                    const std::vector<SqlParam>& params = {}) = 0;
  // Opens a transaction that takes the write lock at once (SQLite: BEGIN IMMEDIATE, so two
  // processes never deadlock upgrading a read lock).
  virtual void begin() = 0;
  // Reconnects after a lost connection; throws DatabaseError(lost) while it stays lost.
  virtual void reconnect() = 0;
  void commit() { query("COMMIT"); }
  void rollback() noexcept {
    try {
      query("ROLLBACK");
    } catch (...) {
    }
  }
};

// `path`: a file (created when missing, with its folder), or ":memory:" (one connection's
// private database: for tests). WAL mode, and a busy timeout for the other processes on the file.
std::unique_ptr<SqlDatabase> openSqlite(const std::string& path);
// A libpq connection URI: postgresql://user:password@host:port/database?... or the socket form
// postgresql:///database?host=/run/postgresql.
std::unique_ptr<SqlDatabase> openPostgres(const std::string& uri);

// Runs `body` in a transaction: commits when it returns, rolls back when it throws.
template <typename Body>
auto inTransaction(SqlDatabase& db, Body&& body) {
  db.begin();
  try {
    if constexpr (std::is_void_v<decltype(body())>) {
      body();
      db.commit();
    } else {
      auto result = body();
      db.commit();
      return result;
    }
  } catch (...) {
    db.rollback();
    throw;
  }
}

}  // namespace limn::batch
