// ServerProcess: the real `limn serve` binary, started for a test on an ephemeral port of
// 127.0.0.1 and stopped with SIGTERM. The constructor returns once the server has printed
// "limn listening on http://HOST:PORT"; terminate() reports how the process ended, so tests
// can check that a clean shutdown exits with status 0.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace limn::testing {

// The `limn` executable under test (set by CMake).
const char* limnBinary();

class ServerProcess {
 public:
  // Runs `limn serve --listen 127.0.0.1:0 <extraArgs...>` (without `--listen 127.0.0.1:0`
  // when `loopbackListen` is false: the address then comes from the environment or a
  // configuration file); throws std::runtime_error when the server exits or stays silent for
  // `startTimeout` instead of announcing its port. Its jobs are kept in a private in-memory
  // store (--job-store sqlite::memory:) unless `extraArgs` name a --job-store.
  explicit ServerProcess(const std::vector<std::string>& extraArgs = {},
                         std::chrono::seconds startTimeout = std::chrono::seconds(60),
                         bool loopbackListen = true);
  // Same, with a configuration file holding `configJson` (--config).
  static ServerProcess withConfig(const std::string& configJson,
                                  const std::vector<std::string>& extraArgs = {});
  ~ServerProcess();  // kills the server if it still runs
  ServerProcess(ServerProcess&& other) noexcept;
  ServerProcess& operator=(ServerProcess&&) = delete;
  ServerProcess(const ServerProcess&) = delete;

  int port() const { return port_; }
  // The address it announced (brackets removed from an IPv6 one).
  const std::string& host() const { return host_; }
  pid_t pid() const { return pid_; }

  // Sends `signal` and waits for the process to end: its exit status, 128 + the signal when a
  // signal killed it, or -1 when it did not end within `timeout` (it is then killed).
  int terminate(int signal = 15, std::chrono::seconds timeout = std::chrono::seconds(30));
  bool running() const { return pid_ > 0; }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  std::string host_;
  std::string configPath_;  // removed with the process
};

// A file in the temporary folder holding `contents`; the caller removes it.
std::string writeTempFile(const std::string& contents, const std::string& suffix);

// Runs a shell command line; its exit status and what it wrote (stdout and stderr together).
struct CommandResult {
  int status = -1;
  std::string output;
};
CommandResult runCommand(const std::string& commandLine);

}  // namespace limn::testing
