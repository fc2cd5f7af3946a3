// Progress: what `limn batch` says while it runs. On a terminal, one line redrawn in place: a
// bar, rows done of the total, the rate and the time left. Elsewhere (CI logs, a pod's log) a
// plain line every `interval`, or nothing at all when quiet.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace limn::batch {

class Progress {
 public:
  enum class Mode { Bar, Lines, Quiet };
  // Bar when `stream` is a terminal, else Lines (unless quiet).
  static Mode modeFor(std::FILE* stream, bool quiet);

  Progress(std::FILE* stream, Mode mode, size_t total,
           std::chrono::seconds interval = std::chrono::seconds(30));

  void update(size_t done, size_t failed);
  // The last state, and the line's end on a terminal.
  void finish(size_t done, size_t failed);

  // "3.2 rows/s, 1m40s left" for `done` rows of `total` after `elapsed`.
  static std::string rateAndTimeLeft(size_t done, size_t total, double elapsedSeconds);
  // "1h02m", "3m05s", "42s".
  static std::string duration(double seconds);

 private:
  std::string line(size_t done, size_t failed) const;

  std::FILE* stream_;
  Mode mode_;
  size_t total_;
  std::chrono::seconds interval_;
  std::chrono::steady_clock::time_point start_, lastPrint_;
};

}  // namespace limn::batch
