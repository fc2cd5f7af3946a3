// SqlDatabase over libpq (Debian's libpq-dev): one connection, reset when it is lost.
#include <libpq-fe.h>

#include "batch/sql_database.h"

namespace limn::batch {
namespace {

// "PostgreSQL database limn on /run/postgresql:5432" from a URI, without its password.
std::string describeUri(const std::string& uri) {
  char* error = nullptr;
  PQconninfoOption* options = PQconninfoParse(uri.c_str(), &error);
  if (!options) {
    std::string message = error ? error : "unreadable";
    PQfreemem(error);
    throw DatabaseError("jobStore: not a PostgreSQL connection URI: " + message, false);
  }
  std::string db, host, port;
  for (PQconninfoOption* o = options; o->keyword; ++o) {
    const std::string keyword = o->keyword;
    const std::string value = o->val ? o->val : "";
    if (keyword == "dbname") db = value;
    if (keyword == "host") host = value;
    if (keyword == "port") port = value;
  }
  PQconninfoFree(options);
  return "PostgreSQL database " + (db.empty() ? "(default)" : db) + " on " +
         (host.empty() ? "the default socket" : host) + (port.empty() ? "" : ":" + port);
}

// The `?` placeholders as $1, $2, ... (none of the store's statements has a `?` in a literal,
// but quoted text is skipped all the same).
std::string numberedPlaceholders(const std::string& sql) {
  std::string out;
  out.reserve(sql.size() + 16);
  int next = 1;
  bool quoted = false;
  for (char c : sql) {
    if (c == '\'') quoted = !quoted;
    if (c == '?' && !quoted) {
      out += '$' + std::to_string(next++);
    } else {
      out += c;
    }
  }
  return out;
}

class PostgresDatabase : public SqlDatabase {
 public:
  explicit PostgresDatabase(std::string uri) : uri_(std::move(uri)), where_(describeUri(uri_)) {
    connection_ = PQconnectdb(uri_.c_str());
    if (PQstatus(connection_) != CONNECTION_OK) {
      std::string message = PQerrorMessage(connection_);
      PQfinish(connection_);
      connection_ = nullptr;
      throw DatabaseError("cannot connect to " + where_ + ": " + trimmed(message), true);
    }
    // Notices (e.g. "relation already exists, skipping") are not the service's log.
    PQsetNoticeProcessor(
        connection_, [](void*, const char*) {}, nullptr);
  }
  ~PostgresDatabase() override { PQfinish(connection_); }

  SqlDialect dialect() const override { return SqlDialect::Postgres; }
  std::string describe() const override { return where_; }

  std::vector<SqlRow> query(const std::string& sql, const std::vector<SqlParam>& params) override {
    std::vector<std::string> texts;
    texts.reserve(params.size());
    for (const SqlParam& p : params) {
      texts.push_back(std::holds_alternative<int64_t>(p) ? std::to_string(std::get<int64_t>(p))
                                                         : std::get<std::string>(p));
    }
    std::vector<const char*> values;
    for (const std::string& t : texts) values.push_back(t.c_str());
    std::unique_ptr<PGresult, void (*)(PGresult*)> result(
        PQexecParams(connection_, numberedPlaceholders(sql).c_str(),
                     static_cast<int>(values.size()), nullptr, values.data(), nullptr, nullptr, 0),
        PQclear);
    const ExecStatusType status = PQresultStatus(result.get());
    if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) {
      const char* state = PQresultErrorField(result.get(), PG_DIAG_SQLSTATE);
      // Class 08 (connection exception), 57P (the server shutting down), or no answer at all.
      const bool lost = PQstatus(connection_) != CONNECTION_OK || !state ||
                        std::string(state).rfind("08", 0) == 0 ||
                        std::string(state).rfind("57P", 0) == 0;
      throw DatabaseError(where_ + ": " + trimmed(PQresultErrorMessage(result.get())), lost);
    }
    std::vector<SqlRow> rows(static_cast<size_t>(PQntuples(result.get())));
    const int columns = PQnfields(result.get());
    for (size_t r = 0; r < rows.size(); ++r) {
      rows[r].resize(static_cast<size_t>(columns));
      for (int c = 0; c < columns; ++c) {
        rows[r][static_cast<size_t>(c)].assign(
            PQgetvalue(result.get(), static_cast<int>(r), c),
            static_cast<size_t>(PQgetlength(result.get(), static_cast<int>(r), c)));
      }
    }
    return rows;
  }

  void begin() override { query("BEGIN", {}); }

  void reconnect() override {
    PQreset(connection_);
    if (PQstatus(connection_) != CONNECTION_OK) {
      throw DatabaseError(
          "cannot connect to " + where_ + ": " + trimmed(PQerrorMessage(connection_)), true);
    }
  }

 private:
  static std::string trimmed(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    return text;
  }

  std::string uri_, where_;
  PGconn* connection_ = nullptr;
};

}  // namespace

std::unique_ptr<SqlDatabase> openPostgres(const std::string& uri) {
  return std::make_unique<PostgresDatabase>(uri);
}

}  // namespace limn::batch
