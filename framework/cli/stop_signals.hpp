#pragma once
// SIGINT and SIGTERM during a long command (`run`, `compare`, `sweep`): the handler sets a flag that the loops read
// after each step or each variation, so that the command ends cleanly and writes what it has.

#include <signal.h>

#include <atomic>

namespace redres::cli {

/// Set by SIGINT or SIGTERM while a StopOnSignals lives.
inline std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the flag is set from a signal handler");

extern "C" inline void request_stop(int /*signal*/) { g_stop_requested.store(true, std::memory_order_relaxed); }

/// Routes SIGINT and SIGTERM to request_stop() while it lives, then puts back what was there.
class StopOnSignals {
 public:
  StopOnSignals() {
    struct sigaction action {};
    action.sa_handler = request_stop;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &old_int_);
    ::sigaction(SIGTERM, &action, &old_term_);
  }
  ~StopOnSignals() {
    ::sigaction(SIGINT, &old_int_, nullptr);
    ::sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

 private:
  struct sigaction old_int_ {
  }, old_term_{};
};

}  // namespace redres::cli
