#include "tests/support/postgres_cluster.h"

#include <pwd.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "batch/sql_database.h"

namespace fs = std::filesystem;

namespace limn::testing {
namespace {

// /usr/lib/postgresql/<version>/bin of the newest version installed.
std::string serverBinaries() {
  std::string best;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/usr/lib/postgresql", ec)) {
    const fs::path bin = entry.path() / "bin";
    if (fs::exists(bin / "initdb") && bin.string() > best) best = bin.string();
  }
  if (best.empty()) {
    throw std::runtime_error(
        "PostgreSQL's server is not installed (/usr/lib/postgresql/*/bin/initdb): run "
        "scripts/setup.sh");
  }
  return best;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

PostgresCluster::PostgresCluster() : bin_(serverBinaries()) {
  char templ[] = "/tmp/limn-pg-XXXXXX";
  if (!::mkdtemp(templ)) throw std::runtime_error("mkdtemp failed");
  dir_ = templ;
  if (::geteuid() == 0) {
    const passwd* user = ::getpwnam("postgres");
    if (!user) throw std::runtime_error("no postgres user (the postgresql package creates it)");
    if (::chown(dir_.c_str(), user->pw_uid, user->pw_gid) != 0)
      throw std::runtime_error("cannot hand " + dir_ + " to the postgres user");
  }
  run(bin_ + "/initdb -D " + dir_ + "/data -A trust -U postgres -E UTF8 --no-sync");
  start();
}

PostgresCluster::~PostgresCluster() {
  try {
    stop();
  } catch (...) {
  }
  std::error_code ignored;
  fs::remove_all(dir_, ignored);
}

std::string PostgresCluster::run(const std::string& command) const {
  const std::string log = dir_ + "/command.log";
  const std::string asUser = ::geteuid() == 0 ? "runuser -u postgres -- " : "";
  const std::string line = asUser + command + " >" + log + " 2>&1";
  if (std::system(line.c_str()) != 0) {
    throw std::runtime_error("PostgreSQL: `" + command + "` failed:\n" + readFile(log) +
                             readFile(dir_ + "/server.log"));
  }
  return readFile(log);
}

void PostgresCluster::start() {
  // No TCP at all: the socket in the folder is the only way in. fsync off: a test's data need
  // not survive the machine.
  run(bin_ + "/pg_ctl -D " + dir_ + "/data -l " + dir_ + "/server.log -w -o \"-k " + dir_ +
      " -c listen_addresses='' -c fsync=off -c max_connections=60\" start");
  running_ = true;
}

void PostgresCluster::stop() {
  if (!running_) return;
  running_ = false;
  run(bin_ + "/pg_ctl -D " + dir_ + "/data -m immediate -w stop");
}

std::string PostgresCluster::uri(const std::string& database) const {
  return "postgresql:///" + database + "?host=" + dir_ + "&user=postgres";
}

std::string PostgresCluster::createDatabase() {
  const std::string name = "limn_test_" + std::to_string(++databases_);
  batch::openPostgres(uri("postgres"))->query("CREATE DATABASE " + name);
  return uri(name);
}

}  // namespace limn::testing
