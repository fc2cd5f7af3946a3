// The messages between the server and its render worker processes (server/worker_process.h),
// over one Unix stream socket per worker. Both ends are the same executable, so the encoding is
// plain native-endian bytes with no versioning; each message is one frame: its payload's length
// (8 bytes) then the payload, whose first byte is the message kind.
//
//   server -> worker   Config (once, first), Run (one task), Cancel (the running task)
//   worker -> server   Ready (once: the GL context made or not), Answer (the task's answer)
//
// An answer is two frames: its head (status, headers, stage times, ...) and its body as raw
// bytes, so that a large body (a 4096^2 image set, an animation) goes from the worker's string
// through the socket straight into the server's: one copy between processes.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "api/answer.h"
#include "render/mesh/control_mesh.h"
#include "render/oracle/reference_scene.h"
#include "render/pipeline/render_job.h"
#include "render/raster/rasterizer.h"
#include "server/tasks.h"

namespace limn::server::wire {

enum class Kind : uint8_t { Config = 1, Ready, Run, Cancel, Answer };

// A frame that cannot be decoded: the other end is not a limn of this build, or is broken.
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a worker needs before its first task.
struct WorkerConfig {
  render::pipeline::JobLimits limits;
  size_t referenceCacheBytes = 0;
};

struct Ready {
  bool ok = false;
  std::string error;  // why the Rasterizer could not be made, when !ok
  render::raster::DeviceInfo device;
};

struct Run {
  uint64_t requestId = 0;
  Task task;
  render::CancelToken::Clock::time_point deadline;
  // The uploaded mesh the task's body names by id, looked up by the server (null: none).
  std::shared_ptr<const render::mesh::ControlMesh> mesh;
};

struct AnswerMessage {
  api::Answer answer;
  render::oracle::ReferenceSceneCache::Counters referenceCache;  // the worker's, after the task
};

std::string encode(const WorkerConfig& config);
std::string encode(const Ready& ready);
std::string encode(const Run& run);
std::string encodeCancel();

Kind kindOf(std::string_view frame);
WorkerConfig decodeConfig(std::string_view frame);
Ready decodeReady(std::string_view frame);
Run decodeRun(std::string_view frame);
// The Answer frame's head and the body frame that follows it.
AnswerMessage decodeAnswer(std::string_view head, std::string body);

// Blocking frame I/O on a socket; false / nothing when the other end has gone (EOF, EPIPE).
bool writeFrame(int fd, std::string_view payload);
bool writeAnswer(int fd, const AnswerMessage& message);  // both frames, the body not copied
std::optional<std::string> readFrame(int fd);

}  // namespace limn::server::wire
