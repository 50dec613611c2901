#pragma once
// The CLI's progress bar: on stderr, shown only on a terminal, and only once the work looks like it takes over a
// second.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace redres::cli {

// A progress bar on stderr, shown only on a terminal, and only once a run looks like it takes over a second.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet)
      : label_(std::move(label)),
        enabled_(!quiet && isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()) {}
  ~ProgressBar() {
    if (shown_) std::fprintf(stderr, "\r\033[K");
  }
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Fraction done in [0, 1] and what to show after it (e.g. "t = 1.20 s" or "12/180 runs").
  void update(double fraction, const char* where) {
    if (!enabled_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (!shown_ && (elapsed < 0.2 || fraction <= 0.0 || elapsed / fraction < 1.0)) return;
    shown_ = true;
    const int width = 30;
    const int done = static_cast<int>(fraction * width);
    const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%%  %s  eta %.1f s", label_.c_str(), done,
                 "##############################", width - done, "", 100.0 * fraction, where, eta);
    std::fflush(stderr);
  }

 private:
  std::string label_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace redres::cli
