#include "server/worker_protocol.h"

#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <type_traits>

namespace limn::server::wire {

namespace {

// The limits travel as their bytes: both ends are the same build.
static_assert(std::is_trivially_copyable_v<render::pipeline::JobLimits>);

class Writer {
 public:
  explicit Writer(Kind kind) { pod(kind); }
  template <typename T>
  Writer& pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof value);
    return *this;
  }
  Writer& str(std::string_view text) {
    pod(static_cast<uint64_t>(text.size()));
    bytes_.append(text);
    return *this;
  }
  template <typename T>
  Writer& array(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod(static_cast<uint64_t>(values.size()));
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    return *this;
  }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

class Reader {
 public:
  Reader(std::string_view frame, Kind expected) : rest_(frame) {
    if (pod<Kind>() != expected) throw ProtocolError("unexpected worker message");
  }
  template <typename T>
  T pod() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof value).data(), sizeof value);
    return value;
  }
  std::string str() { return std::string(take(pod<uint64_t>())); }
  template <typename T>
  std::vector<T> array() {
    const uint64_t count = pod<uint64_t>();
    if (count > rest_.size() / sizeof(T)) throw ProtocolError("truncated worker message");
    std::vector<T> values(count);
    // An empty vector's data() may be null, which memcpy must not be given even for 0 bytes.
    if (count > 0) std::memcpy(values.data(), take(count * sizeof(T)).data(), count * sizeof(T));
    return values;
  }

 private:
  std::string_view take(uint64_t n) {
    if (n > rest_.size()) throw ProtocolError("truncated worker message");
    std::string_view out = rest_.substr(0, n);
    rest_.remove_prefix(n);
    return out;
  }
  std::string_view rest_;
};

void writeMesh(Writer& w, const render::mesh::ControlMesh& mesh) {
  w.pod(mesh.scheme).pod(mesh.boundary).pod(mesh.creaseMethod).pod(mesh.triangleSubdivision);
  w.array(mesh.points).array(mesh.faceVertexCounts).array(mesh.faceVertexIndices);
  w.array(mesh.creases).array(mesh.corners).array(mesh.holes);
}

render::mesh::ControlMesh readMesh(Reader& r) {
  render::mesh::ControlMesh mesh;
  mesh.scheme = r.pod<render::mesh::Scheme>();
  mesh.boundary = r.pod<render::mesh::BoundaryInterpolation>();
  mesh.creaseMethod = r.pod<render::mesh::CreaseMethod>();
  mesh.triangleSubdivision = r.pod<render::mesh::TriangleSubdivision>();
  mesh.points = r.array<render::Vec3>();
  mesh.faceVertexCounts = r.array<int>();
  mesh.faceVertexIndices = r.array<int>();
  mesh.creases = r.array<render::mesh::Crease>();
  mesh.corners = r.array<render::mesh::Corner>();
  mesh.holes = r.array<int>();
  return mesh;
}

bool writeAll(int fd, iovec* parts, int count) {
  while (count > 0) {
    const ssize_t n = ::writev(fd, parts, count);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    size_t written = static_cast<size_t>(n);
    while (count > 0 && written >= parts->iov_len) {
      written -= parts->iov_len;
      ++parts;
      --count;
    }
    if (count > 0) {
      parts->iov_base = static_cast<char*>(parts->iov_base) + written;
      parts->iov_len -= written;
    }
  }
  return true;
}

bool readAll(int fd, char* out, size_t size) {
  while (size > 0) {
    const ssize_t n = ::read(fd, out, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    out += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

std::string encode(const WorkerConfig& config) {
  return Writer(Kind::Config).pod(config.limits).pod(config.referenceCacheBytes).take();
}

std::string encode(const Ready& ready) {
  Writer w(Kind::Ready);
  w.pod(ready.ok).str(ready.error);
  w.str(ready.device.renderer).str(ready.device.vendor).str(ready.device.version);
  w.str(ready.device.eglPlatform).pod(ready.device.maxTextureSize);
  return w.take();
}

std::string encode(const Run& run) {
  Writer w(Kind::Run);
  w.pod(run.requestId).pod(run.task.endpoint).str(run.task.body).str(run.task.accept);
  w.pod(run.deadline.time_since_epoch().count());
  w.pod(run.mesh != nullptr);
  if (run.mesh) writeMesh(w, *run.mesh);
  return w.take();
}

std::string encodeCancel() { return Writer(Kind::Cancel).take(); }

Kind kindOf(std::string_view frame) {
  if (frame.empty()) throw ProtocolError("empty worker message");
  return static_cast<Kind>(frame[0]);
}

WorkerConfig decodeConfig(std::string_view frame) {
  Reader r(frame, Kind::Config);
  WorkerConfig config;
  config.limits = r.pod<render::pipeline::JobLimits>();
  config.referenceCacheBytes = r.pod<size_t>();
  return config;
}

Ready decodeReady(std::string_view frame) {
  Reader r(frame, Kind::Ready);
  Ready ready;
  ready.ok = r.pod<bool>();
  ready.error = r.str();
  ready.device.renderer = r.str();
  ready.device.vendor = r.str();
  ready.device.version = r.str();
  ready.device.eglPlatform = r.str();
  ready.device.maxTextureSize = r.pod<int>();
  return ready;
}

Run decodeRun(std::string_view frame) {
  Reader r(frame, Kind::Run);
  Run run;
  run.requestId = r.pod<uint64_t>();
  run.task.endpoint = r.pod<Endpoint>();
  run.task.body = r.str();
  run.task.accept = r.str();
  using Clock = render::CancelToken::Clock;
  run.deadline = Clock::time_point(Clock::duration(r.pod<Clock::rep>()));
  if (r.pod<bool>()) run.mesh = std::make_shared<render::mesh::ControlMesh>(readMesh(r));
  return run;
}

bool writeAnswer(int fd, const AnswerMessage& message) {
  const api::Answer& a = message.answer;
  Writer w(Kind::Answer);
  w.pod(a.status).str(a.contentType).pod(a.meshFaces);
  w.pod(static_cast<uint64_t>(a.headers.size()));
  for (const auto& [name, value] : a.headers) w.str(name).str(value);
  w.pod(static_cast<uint64_t>(a.stages.size()));
  for (const api::StageTime& stage : a.stages) w.str(stage.name).pod(stage.ms);
  w.pod(message.referenceCache);
  const std::string head = w.take();
  uint64_t headSize = head.size(), bodySize = a.body.size();
  iovec parts[] = {{&headSize, sizeof headSize},
                   {const_cast<char*>(head.data()), head.size()},
                   {&bodySize, sizeof bodySize},
                   {const_cast<char*>(a.body.data()), a.body.size()}};
  return writeAll(fd, parts, 4);
}

AnswerMessage decodeAnswer(std::string_view head, std::string body) {
  Reader r(head, Kind::Answer);
  AnswerMessage message;
  api::Answer& a = message.answer;
  a.status = r.pod<int>();
  a.contentType = r.str();
  a.meshFaces = r.pod<size_t>();
  for (uint64_t n = r.pod<uint64_t>(); n > 0; --n) {
    std::string name = r.str();
    a.headers.emplace_back(std::move(name), r.str());
  }
  for (uint64_t n = r.pod<uint64_t>(); n > 0; --n) {
    std::string name = r.str();
    a.stages.push_back({std::move(name), r.pod<double>()});
  }
  message.referenceCache = r.pod<render::oracle::ReferenceSceneCache::Counters>();
  a.body = std::move(body);
  return message;
}

bool writeFrame(int fd, std::string_view payload) {
  uint64_t size = payload.size();
  iovec parts[] = {{&size, sizeof size}, {const_cast<char*>(payload.data()), payload.size()}};
  return writeAll(fd, parts, 2);
}

std::optional<std::string> readFrame(int fd) {
  uint64_t size = 0;
  if (!readAll(fd, reinterpret_cast<char*>(&size), sizeof size)) return std::nullopt;
  // The largest answer limn makes is far below this; more means the stream is out of step.
  constexpr uint64_t kMaxFrame = uint64_t{1} << 36;
  if (size > kMaxFrame) throw ProtocolError("worker message too large");
  std::string payload(size, '\0');
  if (!readAll(fd, payload.data(), size)) return std::nullopt;
  return payload;
}

}  // namespace limn::server::wire
