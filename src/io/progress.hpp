// The progress line on stderr: simulated time, collisions, collisions/s, Z so far, ETA.
// On a terminal it is redrawn in place about once a second; otherwise one line is printed
// every `quiet_interval` wall seconds.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

namespace hb {

class Progress {
 public:
  Progress();
  // Called often; prints only when due. `fraction` of the whole job done (for the ETA).
  void update(const char* phase, double sim_time, std::uint64_t collisions, double z,
              double fraction, bool force = false);
  // The same line with `text` in place of "t=.. Z=..".
  void update_text(const char* phase, const std::string& text, std::uint64_t collisions,
                   double fraction, bool force = false);
  void finish();
  double wall_seconds() const;

 private:
  using clock = std::chrono::steady_clock;
  bool due() const;
  bool tty_ = false;
  clock::time_point start_, last_;
  double interval_ = 1.0;
  std::uint64_t last_collisions_ = 0;
  double rate_ = 0.0;
  bool drawn_ = false;
};

}  // namespace hb
