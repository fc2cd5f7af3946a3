#include "server/worker_process.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <condition_variable>
#include <csignal>
#include <cstring>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "render/raster/rasterizer.h"
#include "server/tasks.h"

namespace limn::server {

namespace {

using Clock = std::chrono::steady_clock;

// The worker's end of the socket, at a fixed number in the child.
constexpr int kChildFd = 3;
// How often a running task's worker is looked at (memory, cancellation) while it computes.
constexpr std::chrono::milliseconds kWatchInterval{20};

// Waits until `fd` is readable or `timeout` passes; true when readable (or hung up).
bool waitReadable(int fd, std::chrono::milliseconds timeout) {
  pollfd p{fd, POLLIN, 0};
  for (;;) {
    const int n = ::poll(&p, 1, static_cast<int>(timeout.count()));
    if (n < 0 && errno == EINTR) continue;
    return n > 0;
  }
}

// In the child between fork and exec: only system calls. The socket goes to kChildFd, every
// other descriptor the server holds (its listening socket, clients' connections) is closed, and
// the kernel kills the worker if the server dies first.
[[noreturn]] void execWorker(pid_t parent, int fd, const char* executable, char* const argv[]) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(126);
  if (fd == kChildFd) {
    ::fcntl(fd, F_SETFD, 0);
  } else if (::dup2(fd, kChildFd) < 0) {
    ::_exit(126);
  }
  ::close_range(kChildFd + 1, ~0U, 0);
  ::execv(executable, argv);
  ::_exit(127);
}

}  // namespace

std::string signalName(int signal) {
  const char* abbrev = ::sigabbrev_np(signal);
  return abbrev ? std::string("SIG") + abbrev : "signal " + std::to_string(signal);
}

WorkerProcess::WorkerProcess(const WorkerProcessOptions& options) : options_(options) {
  int pair[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, pair) != 0) {
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
  }
  std::string fdText = std::to_string(kChildFd);
  char* argv[] = {options_.executable.data(), const_cast<char*>("worker"),
                  const_cast<char*>("--fd"), fdText.data(), nullptr};
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ == 0) execWorker(parent, pair[1], options_.executable.c_str(), argv);
  ::close(pair[1]);
  socket_ = pair[0];
  if (pid_ < 0) {
    ::close(socket_);
    throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  }
  std::optional<std::string> frame;
  if (wire::writeFrame(socket_, wire::encode(options_.config)) && waitForReady()) {
    frame = wire::readFrame(socket_);
  }
  if (!frame) {
    Outcome gone = reap("did not start", true);
    ::close(socket_);
    throw std::runtime_error("render worker " + options_.executable + ": " + gone.crash);
  }
  ready_ = wire::decodeReady(*frame);
}

bool WorkerProcess::waitForReady() const {
  const auto giveUp = Clock::now() + options_.startTimeout;
  while (Clock::now() < giveUp) {
    if (waitReadable(socket_, std::chrono::milliseconds(50))) return true;
    if (options_.abandonStart && options_.abandonStart->load()) return false;
  }
  return false;
}

// A killed process can take seconds to be torn down on a loaded machine (its threads must each
// be scheduled to exit): a thread of its own waits for it, so that neither a replacement nor
// the server's shutdown waits too.
static void reapInBackground(pid_t pid) {
  std::thread([pid] {
    while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
  }).detach();
}

WorkerProcess::~WorkerProcess() {
  ::close(socket_);
  if (exited_) return;
  ::kill(pid_, SIGKILL);
  reapInBackground(pid_);
}

std::optional<WorkerProcess::Outcome> WorkerProcess::exitedWhileIdle() {
  if (exited_ || !waitReadable(socket_, std::chrono::milliseconds(0))) return std::nullopt;
  return reap("", false);
}

size_t WorkerProcess::residentBytes() const { return residentBytesOf(std::to_string(pid_)); }

WorkerProcess::Outcome WorkerProcess::reap(std::string why, bool kill) {
  exited_ = true;
  if (kill) {
    ::kill(pid_, SIGKILL);
    reapInBackground(pid_);
    return {std::nullopt, std::move(why), "SIGKILL"};
  }
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  Outcome out;
  if (WIFSIGNALED(status)) {
    out.signal = signalName(WTERMSIG(status));
    if (why.empty()) why = "died of " + out.signal + " (" + ::strsignal(WTERMSIG(status)) + ")";
  } else if (why.empty()) {
    why = "exited with status " + std::to_string(WEXITSTATUS(status));
  }
  out.crash = std::move(why);
  return out;
}

WorkerProcess::Outcome WorkerProcess::run(const wire::Run& run, const render::CancelToken& cancel) {
  if (!wire::writeFrame(socket_, wire::encode(run))) return reap("", false);
  std::optional<Clock::time_point> cancelledAt;
  for (;;) {
    if (waitReadable(socket_, kWatchInterval)) {
      std::optional<std::string> head = wire::readFrame(socket_);
      std::optional<std::string> body = head ? wire::readFrame(socket_) : std::nullopt;
      if (!body) return reap("", false);
      Outcome out;
      out.answer = wire::decodeAnswer(*head, std::move(*body));
      return out;
    }
    if (options_.maxMemoryBytes > 0) {
      const size_t resident = residentBytes();
      if (resident > options_.maxMemoryBytes) {
        return reap("used " + std::to_string(resident >> 20) +
                        " MiB, more than limits.maxWorkerMemoryBytes (" +
                        std::to_string(options_.maxMemoryBytes >> 20) + " MiB), and was killed",
                    true);
      }
    }
    if (cancel.expired()) {
      if (!cancelledAt) {
        cancelledAt = Clock::now();
        if (!wire::writeFrame(socket_, wire::encodeCancel())) return reap("", false);
      } else if (Clock::now() - *cancelledAt > options_.cancelGrace) {
        return reap("did not stop within " + std::to_string(options_.cancelGrace.count()) +
                        " ms of its cancellation, and was killed",
                    true);
      }
    }
  }
}

// ---- The worker's side ----

namespace {

// The task the worker is running, for the socket's reader to cancel.
class CurrentTask {
 public:
  void post(wire::Run run) {
    std::lock_guard lock(mutex_);
    pending_ = std::move(run);
    changed_.notify_one();
  }
  // Waits for the next task and makes it current with a fresh token.
  std::pair<wire::Run, std::shared_ptr<render::CancelToken>> take() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return pending_.has_value(); });
    wire::Run run = std::move(*pending_);
    pending_.reset();
    token_ = std::make_shared<render::CancelToken>(run.deadline);
    return {std::move(run), token_};
  }
  void finished() {
    std::lock_guard lock(mutex_);
    token_.reset();
  }
  void cancel() {
    std::lock_guard lock(mutex_);
    if (token_) token_->cancel();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<wire::Run> pending_;
  std::shared_ptr<render::CancelToken> token_;
};

}  // namespace

int workerMain(int fd) {
  keepFreedMemoryForReuse();
  std::optional<std::string> frame = wire::readFrame(fd);
  if (!frame) return 1;
  const wire::WorkerConfig config = wire::decodeConfig(*frame);
  render::oracle::ReferenceSceneCache referenceCache(config.referenceCacheBytes);

  std::unique_ptr<render::raster::Rasterizer> rasterizer;
  wire::Ready ready;
  try {
    rasterizer = startRasterizer();
    ready.ok = true;
    ready.device = rasterizer->device();
  } catch (const std::exception& e) {
    ready.error = e.what();
  }
  if (!wire::writeFrame(fd, wire::encode(ready))) return 1;

  // The socket's reader: tasks go to the render loop, cancellations to the running task, and
  // the socket's end (the server closed it or died) ends the process at once.
  CurrentTask current;
  std::thread reader([&] {
    try {
      while (std::optional<std::string> message = wire::readFrame(fd)) {
        const wire::Kind kind = wire::kindOf(*message);
        if (kind == wire::Kind::Run) current.post(wire::decodeRun(*message));
        if (kind == wire::Kind::Cancel) current.cancel();
      }
    } catch (const std::exception& e) {
      std::cerr << "limn worker: " << e.what() << "\n";
    }
    std::_Exit(0);
  });
  reader.detach();

  render::pipeline::RenderContext context;
  context.rasterizer = rasterizer.get();
  context.referenceCache = &referenceCache;
  for (;;) {
    auto [run, token] = current.take();
    wire::AnswerMessage message;
    if (!rasterizer) {
      message.answer = api::errorAnswer({503, "unavailable", "no OpenGL context: " + ready.error});
    } else {
      // An uploaded mesh the body names travels with the task; the handler finds it by id.
      render::mesh::MeshCache meshes(run.mesh ? SIZE_MAX : 0);
      if (run.mesh) meshes.put(*run.mesh);
      message.answer = runTask(run.task, config.limits, context, *token, &meshes);
    }
    current.finished();
    message.referenceCache = referenceCache.counters();
    if (!wire::writeAnswer(fd, message)) return 0;
    trimFreedMemoryAbove(keptWorkerMemoryBytes(config.limits.maxWorkerMemoryBytes));
  }
}

}  // namespace limn::server
