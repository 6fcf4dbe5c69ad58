// Shared helpers of the whole-simulation benchmarks.
#pragma once
#include <ctime>

// CPU seconds of this process (benchmarks report CPU time, not wall time).
inline double cpu_now() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}
