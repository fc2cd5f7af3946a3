// Mesh files through Assimp (formats/assimp_import.h), read the way the server reads them. The
// first byte picks the format; the rest is the file.
//
// limn's own checks of the declared sizes (formats/import_preflight.h) run in this process: a
// crash, a sanitizer report or an undocumented exception there is a finding. Assimp's import and
// the scene walk after it run in a child process, as they run in a worker process of the server
// (server/worker_pool.h), with a memory ceiling and a deadline of the child's own: Debian's
// Assimp 5.2, not instrumented, crashes, hangs or allocates without bound on many mutated files
// (docs/operations.md lists what this target found), and what the service promises is that such
// a file costs only its own request. So a child that dies of a signal, runs out of time or
// memory is contained, as in the server; a child that leaves with an exception limn does not
// document is a finding (the parent aborts, and libFuzzer keeps the input).
#include <sanitizer/common_interface_defs.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include "formats/assimp_import.h"
#include "formats/import_preflight.h"
#include "fuzz/fuzz_common.h"

namespace {

using limn::formats::ImportFormat;

constexpr int kUndocumentedError = 42;
constexpr int kOverCeiling = 43;
constexpr int kRefused = 44;
constexpr long kCeilingBytes = 2L << 30;             // 2 GiB, as the fuzz runs' -rss_limit_mb
constexpr auto kDeadline = std::chrono::seconds(5);  // within the run's -timeout=10

long residentBytes() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * sysconf(_SC_PAGESIZE);
}

// The child's ceiling and deadline, as a worker process has them; and its deaths its own, not
// libFuzzer's (whose handlers would save the input as a crash of this target).
void watchChild() {
  __sanitizer_set_death_callback(nullptr);
  for (int signal : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL}) std::signal(signal, SIG_DFL);
  std::thread([] {
    const auto start = std::chrono::steady_clock::now();
    while (residentBytes() < kCeilingBytes &&
           std::chrono::steady_clock::now() - start < kDeadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::_Exit(kOverCeiling);
  }).detach();
}

[[noreturn]] void importInChild(std::string_view file, ImportFormat format) {
  watchChild();
  const auto& limits = limn::fuzz::defaultLimits().mesh;
  try {
    limn::formats::ImportedMesh imported = limn::formats::importMesh(file, format, {}, limits);
    limn::render::mesh::validateMesh(imported.mesh, limits);
  } catch (const limn::render::InputError&) {
    std::_Exit(kRefused);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mesh_import: undocumented exception: %s\n", e.what());
    std::_Exit(kUndocumentedError);
  }
  std::_Exit(0);
}

// What happened to the files, printed when the run ends (docs/operations.md's table).
struct Outcomes {
  long refused = 0, read = 0, refusedByAssimp = 0, killedBySignal = 0, overCeiling = 0;
  ~Outcomes() {
    std::fprintf(stderr,
                 "mesh_import: %ld refused by limn's size checks; %ld read in a child: %ld whole, "
                 "%ld refused (422), %ld died of a signal, %ld over the ceiling or deadline\n",
                 refused, read, read - refusedByAssimp - killedBySignal - overCeiling,
                 refusedByAssimp, killedBySignal, overCeiling);
  }
} outcomes;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const ImportFormat formats[] = {ImportFormat::Gltf,    ImportFormat::Glb, ImportFormat::Ply,
                                  ImportFormat::Stl,     ImportFormat::Fbx, ImportFormat::Dae,
                                  ImportFormat::ThreeDs, ImportFormat::Off};
  const ImportFormat format = formats[data[0] % 8];
  const std::string_view file = limn::fuzz::asText(data + 1, size - 1);
  bool honest = false;
  limn::fuzz::expectOnlyDocumentedErrors([&] {
    limn::formats::checkDeclaredSizes(file, format, limn::fuzz::defaultLimits().mesh);
    honest = true;
  });
  if (!honest) {  // refused before Assimp saw it
    ++outcomes.refused;
    return 0;
  }

  const pid_t child = fork();
  if (child < 0) return 0;
  if (child == 0) importInChild(file, format);
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == kUndocumentedError) std::abort();
  ++outcomes.read;
  if (WIFSIGNALED(status)) ++outcomes.killedBySignal;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kOverCeiling) ++outcomes.overCeiling;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kRefused) ++outcomes.refusedByAssimp;
  return 0;
}
