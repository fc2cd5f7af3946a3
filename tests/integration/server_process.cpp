#include "tests/integration/server_process.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <thread>

#ifndef LIMN_BINARY
#error "LIMN_BINARY must name the limn executable"
#endif

namespace limn::testing {

const char* limnBinary() { return LIMN_BINARY; }

ServerProcess::ServerProcess(const std::vector<std::string>& extraArgs,
                             std::chrono::seconds startTimeout, bool loopbackListen) {
  std::vector<std::string> args{limnBinary(), "serve"};
  if (loopbackListen) args.insert(args.end(), {"--listen", "127.0.0.1:0"});
  args.insert(args.end(), extraArgs.begin(), extraArgs.end());
  // Each server keeps its jobs to itself unless the test names a store to share.
  if (std::find(extraArgs.begin(), extraArgs.end(), "--job-store") == extraArgs.end()) {
    args.insert(args.end(), {"--job-store", "sqlite::memory:"});
  }

  // Everything the child needs is allocated before fork(): only exec-safe calls after it.
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int out[2];
  if (::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    // The server must not outlive a test binary that crashes or is killed.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::dup2(out[1], STDOUT_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(out[1]);

  // Read stdout until the announcement line; stderr stays the test's own.
  std::string text;
  std::smatch match;
  const std::regex announcement(R"(limn listening on http://([^\s:]+|\[[^\]]+\]):(\d+)\n)");
  auto deadline = std::chrono::steady_clock::now() + startTimeout;
  while (!std::regex_search(text, match, announcement)) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd p{out[0], POLLIN, 0};
    if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) {
      ::close(out[0]);
      terminate(SIGKILL);
      throw std::runtime_error("limn serve did not announce its port in time; stdout: " + text);
    }
    char chunk[256];
    ssize_t n = ::read(out[0], chunk, sizeof chunk);
    if (n <= 0) {
      ::close(out[0]);
      int status = terminate(SIGKILL);
      throw std::runtime_error("limn serve exited (status " + std::to_string(status) +
                               ") before listening; stdout: " + text);
    }
    text.append(chunk, static_cast<size_t>(n));
  }
  // The server prints nothing else on stdout; its writes would fail quietly (it ignores SIGPIPE).
  ::close(out[0]);
  port_ = std::stoi(match[2].str());
  host_ = match[1].str();
  if (host_.size() >= 2 && host_.front() == '[') host_ = host_.substr(1, host_.size() - 2);
}

ServerProcess ServerProcess::withConfig(const std::string& configJson,
                                        const std::vector<std::string>& extraArgs) {
  std::string path = writeTempFile(configJson, ".json");
  std::vector<std::string> args{"--config", path};
  args.insert(args.end(), extraArgs.begin(), extraArgs.end());
  try {
    ServerProcess server(args);
    server.configPath_ = path;
    return server;
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
}

ServerProcess::ServerProcess(ServerProcess&& other) noexcept
    : pid_(other.pid_),
      port_(other.port_),
      host_(std::move(other.host_)),
      configPath_(std::move(other.configPath_)) {
  other.pid_ = -1;
  other.configPath_.clear();
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) terminate(SIGKILL);
  if (!configPath_.empty()) std::remove(configPath_.c_str());
}

int ServerProcess::terminate(int signal, std::chrono::seconds timeout) {
  if (pid_ <= 0) return -1;
  ::kill(pid_, signal);
  auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  for (;;) {
    pid_t done = ::waitpid(pid_, &status, WNOHANG);
    if (done == pid_) break;
    if (done < 0 && errno != EINTR) {
      pid_ = -1;
      return -1;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  pid_ = -1;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

std::string writeTempFile(const std::string& contents, const std::string& suffix) {
  std::string pattern = "/tmp/limn-test-XXXXXX" + suffix;
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  int fd = ::mkstemps(name.data(), static_cast<int>(suffix.size()));
  if (fd < 0) throw std::runtime_error("mkstemps failed");
  ::close(fd);
  std::ofstream(name.data(), std::ios::binary) << contents;
  return name.data();
}

CommandResult runCommand(const std::string& commandLine) {
  CommandResult result;
  FILE* pipe = ::popen((commandLine + " 2>&1").c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed: " + commandLine);
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace limn::testing
