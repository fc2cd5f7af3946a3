#include "api/config.h"

#include <rapidjson/document.h>
#include <rapidjson/error/en.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace limn::api {

namespace {

using Value = rapidjson::Value;

// Reads one object's keys into their targets, refusing unknown keys and wrong types.
class ConfigReader {
 public:
  ConfigReader(const Value& object, std::string source, std::string prefix)
      : source_(std::move(source)), prefix_(std::move(prefix)) {
    if (!object.IsObject()) fail(prefix_.empty() ? "the top level" : prefix_, "must be an object");
    for (auto it = object.MemberBegin(); it != object.MemberEnd(); ++it) {
      pending_.push_back(
          {std::string(it->name.GetString(), it->name.GetStringLength()), &it->value});
    }
  }

  void integer(const char* key, int& target, long min, long max = std::numeric_limits<int>::max()) {
    if (const Value* v = take(key)) {
      if (!v->IsInt64() || v->GetInt64() < min || v->GetInt64() > max) {
        fail(path(key),
             "must be an integer in " + std::to_string(min) + ".." + std::to_string(max));
      }
      target = static_cast<int>(v->GetInt64());
    }
  }

  void size(const char* key, size_t& target, unsigned long long min) {
    if (const Value* v = take(key)) {
      if (!v->IsUint64() || v->GetUint64() < min) {
        fail(path(key), "must be an integer >= " + std::to_string(min));
      }
      target = static_cast<size_t>(v->GetUint64());
    }
  }

  void number(const char* key, double& target, double exclusiveMin) {
    if (const Value* v = take(key)) {
      if (!v->IsNumber() || !std::isfinite(v->GetDouble()) || !(v->GetDouble() > exclusiveMin)) {
        std::ostringstream bound;
        bound << exclusiveMin;
        fail(path(key), "must be a number > " + bound.str());
      }
      target = v->GetDouble();
    }
  }

  void string(const char* key, std::string& target) {
    if (const Value* v = take(key)) {
      if (!v->IsString() || v->GetStringLength() == 0)
        fail(path(key), "must be a non-empty string");
      target.assign(v->GetString(), v->GetStringLength());
    }
  }

  void strings(const char* key, std::vector<std::string>& target) {
    if (const Value* v = take(key)) {
      if (!v->IsArray()) fail(path(key), "must be an array of strings");
      target.clear();
      for (const Value& item : v->GetArray()) {
        if (!item.IsString() || item.GetStringLength() == 0) {
          fail(path(key), "must be an array of non-empty strings");
        }
        target.emplace_back(item.GetString(), item.GetStringLength());
      }
    }
  }

  const Value* object(const char* key) { return take(key); }

  // Every key must have been taken by now.
  void finish() const {
    if (!pending_.empty()) fail(path(pending_.front().name), "is not a known key");
  }

  std::string path(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }

 private:
  // The member's own value, not object_[key]: a name with an embedded NUL must stay unknown
  // rather than be looked up by its prefix (rapidjson asserts on a missing member).
  const Value* take(const char* key) {
    for (auto it = pending_.begin(); it != pending_.end(); ++it) {
      if (it->name == key) {
        const Value* value = it->value;
        pending_.erase(it);
        return value;
      }
    }
    return nullptr;
  }

  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw ConfigError(source_ + ": \"" + printable(key) + "\" " + message);
  }

  // A key as JSON would write it: control characters (a NUL would end what()) as \u00XX.
  static std::string printable(const std::string& key) {
    std::string out;
    for (unsigned char c : key) {
      if (c >= 0x20) {
        out += static_cast<char>(c);
        continue;
      }
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
    }
    return out;
  }

  struct Member {
    std::string name;
    const Value* value;
  };

  std::string source_, prefix_;
  std::vector<Member> pending_;
};

void readLimits(const Value& object, const std::string& source, ServiceConfig& config) {
  render::pipeline::JobLimits& limits = config.limits;
  ConfigReader r(object, source, "limits");
  r.integer("maxVertices", limits.mesh.maxVertices, 1);
  r.integer("maxFaces", limits.mesh.maxFaces, 1);
  r.integer("maxFaceSize", limits.mesh.maxFaceSize, 3);
  r.integer("maxValence", limits.mesh.maxValence, 3);
  r.integer("maxImageSide", limits.maxImageSide, 1);
  r.integer("maxSupersample", limits.maxSupersample, 1);
  r.size("maxSupersampledPixels", limits.maxSupersampledPixels, 1);
  r.integer("maxLevel", limits.maxLevel, 0);
  r.integer("maxIsolation", limits.maxIsolation, 1);
  r.size("maxFrames", limits.maxFrames, 1);
  r.size("maxFramePixels", limits.maxFramePixels, 1);
  r.number("minDicingRate", limits.minDicingRate, 0.0);
  r.integer("maxSearchSteps", limits.maxSearchSteps, 0);
  r.integer("maxCurveSamples", limits.maxCurveSamples, 0);
  r.size("maxTriangles", limits.maxTriangles, 1);
  r.size("maxReferenceTriangles", limits.maxReferenceTriangles, 1000);
  r.integer("maxPrimitives", limits.maxPrimitives, 1);
  r.integer("maxResolution", limits.maxResolution, 2);
  r.size("maxExpressionLength", limits.maxExpressionLength, 1);
  r.size("maxCompareRows", limits.maxCompareRows, 1);
  r.size("maxWorkerMemoryBytes", limits.maxWorkerMemoryBytes, 0);
  r.size("maxJobs", config.maxJobs, 1);
  r.size("maxJobRows", config.maxJobRows, 1);
  r.finish();
}

}  // namespace

ServiceConfig parseConfig(std::string_view json, const std::string& source) {
  rapidjson::Document document;
  document.Parse<rapidjson::kParseIterativeFlag>(json.data(), json.size());
  if (document.HasParseError()) {
    throw ConfigError(source +
                      ": not valid JSON: " + rapidjson::GetParseError_En(document.GetParseError()) +
                      " (at offset " + std::to_string(document.GetErrorOffset()) + ")");
  }
  ServiceConfig config;
  ConfigReader r(document, source, "");
  r.string("host", config.host);
  r.integer("port", config.port, 0, 65535);
  r.integer("workers", config.workers, 0, 1024);
  r.integer("queueDepth", config.queueDepth, 1);
  r.integer("reservedInteractiveWorkers", config.reservedInteractiveWorkers, 0, 1024);
  r.integer("heavyRequestMs", config.heavyRequestMs, 1);
  r.integer("heavyQueueMs", config.heavyQueueMs, 1);
  r.integer("clientQueueDepth", config.clientQueueDepth, 0);
  r.integer("heavyWorkerNice", config.heavyWorkerNice, 0, 19);
  r.integer("ioThreads", config.ioThreads, 1, 256);
  r.size("maxBodyBytes", config.maxBodyBytes, 1);
  r.integer("requestTimeoutMs", config.requestTimeoutMs, 1);
  r.integer("shutdownDrainMs", config.shutdownDrainMs, 0);
  r.size("referenceCacheBytes", config.referenceCacheBytes, 0);
  r.size("meshCacheBytes", config.meshCacheBytes, 0);
  r.string("authToken", config.authToken);
  r.strings("corsOrigins", config.corsOrigins);
  r.string("logLevel", config.logLevel);
  if (config.logLevel != "debug" && config.logLevel != "info" && config.logLevel != "warn" &&
      config.logLevel != "error" && config.logLevel != "off") {
    throw ConfigError(source + ": \"logLevel\" must be debug, info, warn, error or off");
  }
  r.integer("jobRetentionSeconds", config.jobRetentionSeconds, 0);
  r.string("jobStore", config.jobStore);
  r.integer("jobLeaseSeconds", config.jobLeaseSeconds, 1, 86400);
  r.string("workerIsolation", config.workerIsolation);
  if (config.workerIsolation != "process" && config.workerIsolation != "thread") {
    throw ConfigError(source + ": \"workerIsolation\" must be process or thread");
  }
  if (const Value* limits = r.object("limits")) readLimits(*limits, source, config);
  r.finish();
  return config;
}

ServiceConfig loadConfig(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ConfigError(path + ": cannot be opened");
  std::ostringstream text;
  text << file.rdbuf();
  return parseConfig(text.str(), path);
}

}  // namespace limn::api
