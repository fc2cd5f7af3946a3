// PostgresCluster: a throwaway PostgreSQL server for a test — initdb and pg_ctl from Debian's
// `postgresql` package on a temporary folder, reachable only on a Unix socket in that folder,
// stopped and removed with the object. initdb refuses to run as root, so as root the server runs
// as the `postgres` user the package creates. Throws std::runtime_error (with the server's log)
// when it cannot be set up: the tests that need it fail rather than skip.
#pragma once

#include <string>

namespace limn::testing {

class PostgresCluster {
 public:
  PostgresCluster();
  ~PostgresCluster();
  PostgresCluster(const PostgresCluster&) = delete;
  PostgresCluster& operator=(const PostgresCluster&) = delete;

  // A new, empty database; its libpq URI.
  std::string createDatabase();
  // The URI of an existing database.
  std::string uri(const std::string& database) const;
  // Stops (immediately, as a crash would) and starts the server again on the same data.
  void stop();
  void start();

 private:
  std::string run(const std::string& command) const;  // as the server's user
  std::string dir_, bin_;
  int databases_ = 0;
  bool running_ = false;
};

}  // namespace limn::testing
