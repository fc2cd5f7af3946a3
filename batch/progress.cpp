#include "batch/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace limn::batch {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kBarWidth = 30;
// A terminal is redrawn at most this often: rows can finish faster than anyone can read.
constexpr std::chrono::milliseconds kRedraw{200};

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

}  // namespace

Progress::Mode Progress::modeFor(std::FILE* stream, bool quiet) {
  if (quiet) return Mode::Quiet;
  return ::isatty(::fileno(stream)) ? Mode::Bar : Mode::Lines;
}

Progress::Progress(std::FILE* stream, Mode mode, size_t total, std::chrono::seconds interval)
    : stream_(stream),
      mode_(mode),
      total_(total),
      interval_(interval),
      start_(Clock::now()),
      lastPrint_(Clock::now()) {}

std::string Progress::duration(double seconds) {
  const long s = std::lround(std::max(seconds, 0.0));
  char text[32];
  if (s >= 3600) {
    std::snprintf(text, sizeof text, "%ldh%02ldm", s / 3600, s % 3600 / 60);
  } else if (s >= 60) {
    std::snprintf(text, sizeof text, "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lds", s);
  }
  return text;
}

std::string Progress::rateAndTimeLeft(size_t done, size_t total, double elapsedSeconds) {
  if (done == 0 || elapsedSeconds <= 0) return "starting";
  const double rate = static_cast<double>(done) / elapsedSeconds;
  char text[64];
  std::snprintf(text, sizeof text, "%.2f rows/s", rate);
  return std::string(text) + ", " + duration(static_cast<double>(total - done) / rate) + " left";
}

std::string Progress::line(size_t done, size_t failed) const {
  const double fraction = total_ ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  std::string text;
  if (mode_ == Mode::Bar) {
    const int filled = static_cast<int>(fraction * kBarWidth);
    text = "[" + std::string(filled, '#') + std::string(kBarWidth - filled, '.') + "] ";
  } else {
    text = "limn batch: ";
  }
  char counts[96];
  std::snprintf(counts, sizeof counts, "%zu/%zu rows (%.0f%%)", done, total_, 100 * fraction);
  text += counts;
  if (failed) text += ", " + std::to_string(failed) + " failed";
  return text + ", " + rateAndTimeLeft(done, total_, secondsSince(start_));
}

void Progress::update(size_t done, size_t failed) {
  if (mode_ == Mode::Quiet) return;
  const auto since = Clock::now() - lastPrint_;
  if (mode_ == Mode::Bar ? since < kRedraw : since < interval_) return;
  lastPrint_ = Clock::now();
  if (mode_ == Mode::Bar) {
    std::fprintf(stream_, "\r%s\033[K", line(done, failed).c_str());
  } else {
    std::fprintf(stream_, "%s\n", line(done, failed).c_str());
  }
  std::fflush(stream_);
}

void Progress::finish(size_t done, size_t failed) {
  if (mode_ == Mode::Quiet) return;
  std::fprintf(stream_, mode_ == Mode::Bar ? "\r%s\033[K\n" : "%s\n", line(done, failed).c_str());
  std::fflush(stream_);
}

}  // namespace limn::batch
