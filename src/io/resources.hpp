// What a run will need, estimated from its config before any work: the peak memory (against
// MemAvailable of /proc/meminfo) and the volume of the files it writes (against
// output.max_output_gb). load_config() calls check_resources(): a run that cannot fit is bad
// input (ConfigError: exit 2, one message with both figures, nothing written), not a
// std::bad_alloc after minutes of work or a full disk.
#pragma once
#include <string>

#include "setup/config.hpp"

namespace hb {

struct ResourceEstimate {
  double memory_bytes = 0.0;  // peak resident memory of the whole process
  // files: trajectory.gsd, log.tsv (+ nematic.tsv), correlation and g(r) tables, checkpoint.gsd
  double trajectory_bytes = 0.0, log_bytes = 0.0, table_bytes = 0.0, checkpoint_bytes = 0.0;
  double frames = 0.0, log_rows = 0.0, lags = 0.0;  // counts behind them
  double output_bytes() const { return trajectory_bytes + log_bytes + table_bytes + checkpoint_bytes; }
};

// The estimate of a validated config (see resources.cpp for the calibration).
ResourceEstimate estimate_resources(const Config& c);

// MemAvailable of /proc/meminfo in bytes; 0 when it cannot be read (memory is then not checked).
double available_memory_bytes();

// Throws ConfigError naming the config file and the key to change when the run's memory exceeds
// `available_bytes` (0: unknown, not checked) or its files exceed output.max_output_gb.
void check_resources(const Config& c, double available_bytes);

}  // namespace hb
