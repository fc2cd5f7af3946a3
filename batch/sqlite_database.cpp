// SqlDatabase over SQLite's C API (Debian's libsqlite3).
#include <sqlite3.h>

#include <filesystem>

#include "batch/sql_database.h"

namespace limn::batch {
namespace {

// A database that is busy (another process holds the lock past the timeout) or that the disk
// refuses is "lost" for the moment: the caller answers 503 and tries again later. A file that is
// not a database, or a statement SQLite refuses, is not.
bool isLost(int code) {
  switch (code & 0xff) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
    case SQLITE_IOERR:
    case SQLITE_CANTOPEN:
    case SQLITE_FULL:
    case SQLITE_PROTOCOL:
      return true;
    default:
      return false;
  }
}

class SqliteDatabase : public SqlDatabase {
 public:
  explicit SqliteDatabase(std::string path) : path_(std::move(path)) { open(); }
  ~SqliteDatabase() override { sqlite3_close_v2(db_); }

  SqlDialect dialect() const override { return SqlDialect::Sqlite; }
  std::string describe() const override { return "SQLite database " + path_; }

  std::vector<SqlRow> query(const std::string& sql, const std::vector<SqlParam>& params) override {
    sqlite3_stmt* statement = nullptr;
    check(sqlite3_prepare_v2(db_, sql.c_str(), static_cast<int>(sql.size()), &statement, nullptr));
    std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> owned(statement, sqlite3_finalize);
    for (size_t i = 0; i < params.size(); ++i) {
      const int at = static_cast<int>(i) + 1;
      if (const auto* number = std::get_if<int64_t>(&params[i])) {
        check(sqlite3_bind_int64(statement, at, *number));
      } else {
        const std::string& text = std::get<std::string>(params[i]);
        check(sqlite3_bind_text(statement, at, text.data(), static_cast<int>(text.size()),
                                SQLITE_TRANSIENT));
      }
    }
    std::vector<SqlRow> rows;
    for (;;) {
      const int step = sqlite3_step(statement);
      if (step == SQLITE_DONE) break;
      if (step != SQLITE_ROW) check(step);
      SqlRow row(static_cast<size_t>(sqlite3_column_count(statement)));
      for (size_t c = 0; c < row.size(); ++c) {
        const auto* text = sqlite3_column_text(statement, static_cast<int>(c));
        if (text) {
          row[c].assign(reinterpret_cast<const char*>(text),
                        static_cast<size_t>(sqlite3_column_bytes(statement, static_cast<int>(c))));
        }
      }
      rows.push_back(std::move(row));
    }
    return rows;
  }

  void begin() override { query("BEGIN IMMEDIATE", {}); }

  // The file stays open: a busy or full disk passes without a new handle (and a ":memory:"
  // database would be lost with its handle).
  void reconnect() override {
    if (!db_) open();
  }

 private:
  void open() {
    if (path_ != ":memory:") {
      std::error_code ignored;
      const std::filesystem::path parent = std::filesystem::path(path_).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent, ignored);
    }
    const int opened =
        sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
    if (opened != SQLITE_OK) {
      std::string message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(opened);
      sqlite3_close_v2(db_);
      db_ = nullptr;
      throw DatabaseError("cannot open " + describe() + ": " + message, true);
    }
    // Other processes on the same file wait this long for its lock before a statement fails.
    sqlite3_busy_timeout(db_, 10'000);
    // WAL: readers never wait for the writer; a commit survives a killed process.
    query("PRAGMA journal_mode=WAL", {});
    query("PRAGMA synchronous=NORMAL", {});
  }

  void check(int code) const {
    if (code == SQLITE_OK || code == SQLITE_ROW || code == SQLITE_DONE) return;
    throw DatabaseError(describe() + ": " + sqlite3_errmsg(db_), isLost(code));
  }

  std::string path_;
  sqlite3* db_ = nullptr;
};

}  // namespace

std::unique_ptr<SqlDatabase> openSqlite(const std::string& path) {
  return std::make_unique<SqliteDatabase>(path);
}

}  // namespace limn::batch
