#include "server/request_log.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace limn::server {

namespace {

spdlog::level::level_enum levelOf(std::string_view name) {
  if (name == "debug") return spdlog::level::debug;
  if (name == "info") return spdlog::level::info;
  if (name == "warn") return spdlog::level::warn;
  if (name == "error") return spdlog::level::err;
  if (name == "off") return spdlog::level::off;
  throw std::invalid_argument("log level must be debug, info, warn, error or off, not \"" +
                              std::string(name) + "\"");
}

// Routes are limn's own paths and methods come from the parser: neither needs JSON escaping
// beyond refusing what could break the line.
std::string safe(std::string_view text) {
  std::string out;
  for (char c : text)
    out += (c == '"' || c == '\\' || static_cast<unsigned char>(c) < 0x20) ? '?' : c;
  return out;
}

}  // namespace

RequestLog::RequestLog(const std::string& level, std::shared_ptr<spdlog::sinks::sink> sink) {
  if (!sink) sink = std::make_shared<spdlog::sinks::stderr_sink_mt>();
  logger_ = std::make_shared<spdlog::logger>("limn.requests", std::move(sink));
  // The message is the rest of a JSON object; spdlog adds the time (UTC) and level before it.
  logger_->set_pattern(R"({"ts":"%Y-%m-%dT%H:%M:%S.%eZ","level":"%l",%v})",
                       spdlog::pattern_time_type::utc);
  logger_->set_level(levelOf(level));
  logger_->flush_on(spdlog::level::trace);  // a line per request, never held back
}

RequestLog::~RequestLog() = default;

void RequestLog::answered(const AnsweredRequest& r) {
  const auto level = r.status >= 500 ? spdlog::level::err : spdlog::level::info;
  if (!logger_->should_log(level)) return;
  char numbers[160];
  std::snprintf(numbers, sizeof numbers, R"("status":%d,"ms":%.3f,"in":%zu,"out":%zu)", r.status,
                std::isfinite(r.seconds) ? r.seconds * 1000 : -1.0, r.bytesIn, r.bytesOut);
  std::string line = "\"id\":" + std::to_string(r.id) + ",\"method\":\"" + safe(r.method) +
                     "\",\"route\":\"" + safe(r.route) + "\"," + numbers;
  if (r.stages && !r.stages->empty()) {
    std::string stages;
    for (const api::StageTime& stage : *r.stages) {
      char ms[48];
      std::snprintf(ms, sizeof ms, "%.3f", std::isfinite(stage.ms) ? stage.ms : -1.0);
      stages += (stages.empty() ? "\"" : ",\"") + safe(stage.name) + "Ms\":" + ms;
    }
    line += ",\"stages\":{" + stages + "}";
  }
  logger_->log(level, line);
}

}  // namespace limn::server
