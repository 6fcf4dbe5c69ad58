// Stop requests (SIGINT/SIGTERM) seen by every long loop of the library.
//
// A signal is process-wide, so the request is one process-wide flag: the signal handler installed
// by a run (io/run.cpp) stores the signal number, and every loop that can take more than a moment
// (the event loop's housekeeping, growth, the g(r) and F_self samplers, q-vector enumeration)
// calls poll_interrupt(), which throws Interrupted. The run catches it, writes a checkpoint when
// the phase has one, and exits with status 128 + signal.
#pragma once
#include <atomic>
#include <stdexcept>
#include <string>

namespace hb {

inline std::atomic<int> g_stop_signal{0};

// The signal asked for (0: none).
inline int pending_signal() { return g_stop_signal.load(std::memory_order_relaxed); }
// Async-signal-safe: a lock-free atomic store.
inline void request_stop(int sig) { g_stop_signal.store(sig, std::memory_order_relaxed); }
inline void clear_stop() { g_stop_signal.store(0, std::memory_order_relaxed); }

class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int sig, std::string phase = "")
      : std::runtime_error("interrupted"), signal(sig), phase(std::move(phase)) {}
  int signal;
  std::string phase;  // where it was caught (empty: the event loop)
};

inline void poll_interrupt(const char* phase = "") {
  if (const int s = pending_signal()) throw Interrupted(s, phase);
}

}  // namespace hb
