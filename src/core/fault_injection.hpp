// Fault injection for the tests: a signal raised at a named point of a run.
//
// HARDBODY_FAULT="POINT:SIGNAL[:N]" raises SIGNAL (TERM, INT or KILL) the N-th time (default 1)
// the run passes POINT; SIGNAL = FAIL throws std::runtime_error there instead (a run-time failure
// such as a solver failure). The points are
//   growth        every few thousand events of a growth (setup/growth.hpp)
//   equilibrate   every few thousand events before the measured run (io/run.cpp)
//   measure       every few thousand events of the measured run
//   checkpoint    at the start of a checkpoint write
//   checkpoint-write  inside it: the temporary file is written, not yet renamed over the old one
//   final         at the start of the final outputs (summary.json, tables)
//   summary       between the commit of log.tsv and the write of summary.json
//   nonfinite     the finiteness check of the state (each log block and checkpoint; with FAIL:
//                 the state counts as non-finite there)
// TERM and INT go through the run's own handler, exactly as a signal from outside arriving at
// that moment; KILL ends the process there. Unset (always, outside tests), a point costs one
// load of a cached flag.
#pragma once
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

namespace hb {

namespace fault_detail {
struct Plan {
  std::string point;
  int sig = 0;
  long count = 1;
};
inline Plan parse() {
  Plan p;
  const char* env = std::getenv("HARDBODY_FAULT");
  if (!env || !*env) return p;
  const std::string s(env);
  const auto a = s.find(':');
  if (a == std::string::npos) return p;
  p.point = s.substr(0, a);
  const auto b = s.find(':', a + 1);
  const std::string sig = s.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1);
  p.sig = sig == "TERM" ? SIGTERM : sig == "INT" ? SIGINT : sig == "KILL" ? SIGKILL : sig == "FAIL" ? -1 : 0;
  if (b != std::string::npos) p.count = std::strtol(s.c_str() + b + 1, nullptr, 10);
  return p;
}
inline Plan& plan() {
  static Plan p = parse();
  return p;
}
}  // namespace fault_detail

inline void fault_point(const char* where) {
  fault_detail::Plan& p = fault_detail::plan();
  if (p.sig == 0 || p.point != where) return;
  if (--p.count > 0) return;
  const int sig = p.sig;
  p.sig = 0;  // once
  if (sig < 0) throw std::runtime_error(std::string("injected failure at ") + where);
  std::raise(sig);
}

}  // namespace hb
