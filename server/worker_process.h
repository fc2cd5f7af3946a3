// WorkerProcess: one render worker as a child process — `limn worker --fd N`, the same
// executable as the server — holding its own EGL context and reference cache, and running one
// task at a time sent over a Unix socket (server/worker_protocol.h). Whatever the task does to
// that process (a segfault or abort inside OpenSubdiv, Embree, Mesa or limn, the OOM killer,
// memory past its ceiling, a hang past its deadline), the server loses that task only.
//
// The server's WorkerPool owns one per worker slot and calls it from that slot's thread only.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "server/worker_protocol.h"

namespace limn::server {

struct WorkerProcessOptions {
  std::string executable = "/proc/self/exe";  // a limn binary (it has the `worker` command)
  wire::WorkerConfig config;
  // Resident memory the worker may use; past it, it is killed and its task answered as a
  // crash. 0: no ceiling.
  size_t maxMemoryBytes = 0;
  // How long a task may run on after its deadline (or cancellation) before its worker is
  // killed: every stage checks its cancel token well within this. The longest step between
  // checks (a 1024^2 comparison's first framebuffers and masks, before its first tile) took
  // 1.5 s on the 2-core VM loaded three times over; a kill then would cost a restart.
  std::chrono::milliseconds cancelGrace{5'000};
  std::chrono::milliseconds startTimeout{30'000};  // to make the GL context and say Ready
  // When set and true, a start still waiting for its Ready gives up (the pool is stopping).
  const std::atomic<bool>* abandonStart = nullptr;
};

class WorkerProcess {
 public:
  // Starts the process and waits for its Ready. Throws std::runtime_error when it cannot be
  // started or does not answer within startTimeout; a worker without a GL context is started
  // (ready().ok false) so that /healthz can say why.
  explicit WorkerProcess(const WorkerProcessOptions& options);
  ~WorkerProcess();  // kills and reaps the process (it holds nothing that needs a clean exit)
  WorkerProcess(const WorkerProcess&) = delete;
  WorkerProcess& operator=(const WorkerProcess&) = delete;

  pid_t pid() const { return pid_; }
  const wire::Ready& ready() const { return ready_; }

  struct Outcome {
    std::optional<wire::AnswerMessage> answer;  // the task's answer, when the worker gave one
    // Otherwise why it did not: the worker died, was killed for its memory or for ignoring its
    // cancellation. The process is gone then; the pool replaces it.
    std::string crash;
    std::string signal;  // "SIGSEGV", "SIGKILL", ... ; "" for an exit without a signal
  };
  // Runs one task; returns when it is answered or the worker is gone. `cancel` is watched
  // throughout: when it expires the worker is told to stop, and killed after cancelGrace.
  Outcome run(const wire::Run& run, const render::CancelToken& cancel);

  // When the worker has died while it had no task (it never writes then, so a readable or
  // closed socket means its end), how it ended; the process is reaped.
  std::optional<Outcome> exitedWhileIdle();

  // Resident memory of the process now (from /proc), 0 when unknown.
  size_t residentBytes() const;

 private:
  // Until the worker's Ready can be read; false after startTimeout or when abandoned.
  bool waitForReady() const;
  // Kills the process (when `why` is set), reaps it and says how it ended.
  Outcome reap(std::string why, bool kill);

  WorkerProcessOptions options_;
  pid_t pid_ = -1;
  int socket_ = -1;
  wire::Ready ready_;
  bool exited_ = false;
};

// The signal's name ("SIGSEGV"), or "signal N".
std::string signalName(int signal);

// limn worker: the child's side. Reads the Config from `fd`, makes its GL context, says Ready,
// then runs Run messages one at a time until the socket closes. Returns the exit status.
int workerMain(int fd);

}  // namespace limn::server
