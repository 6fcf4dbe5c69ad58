#include "io/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace hb {

Progress::Progress() : tty_(isatty(fileno(stderr)) != 0), start_(clock::now()), last_(start_) {
  interval_ = tty_ ? 1.0 : 30.0;
}

double Progress::wall_seconds() const {
  return std::chrono::duration<double>(clock::now() - start_).count();
}

void Progress::update(const char* phase, double sim_time, std::uint64_t collisions, double z,
                      double fraction, bool force) {
  if (!force && !due()) return;
  update_text(phase, fmt::format("t={:.4g} Z={:.4f}", sim_time, z), collisions, fraction, true);
}

bool Progress::due() const {
  return std::chrono::duration<double>(clock::now() - last_).count() >= interval_;
}

void Progress::update_text(const char* phase, const std::string& text, std::uint64_t collisions,
                           double fraction, bool force) {
  if (!force && !due()) return;
  const auto now = clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (since > 0.0 && collisions >= last_collisions_) rate_ = double(collisions - last_collisions_) / since;
  last_collisions_ = collisions;
  last_ = now;
  const double elapsed = wall_seconds();
  std::string eta = "?";
  if (fraction > 1e-6 && fraction <= 1.0) {
    const double rest = elapsed * (1.0 - fraction) / fraction;
    eta = rest < 120 ? fmt::format("{:.0f}s", rest) : fmt::format("{:.1f}min", rest / 60.0);
  }
  const std::string line = fmt::format("[{}] {} collisions={} ({:.3g}/s) done={:.1f}% ETA {}", phase,
                                       text, collisions, rate_, 100.0 * fraction, eta);
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s", line.c_str());
    drawn_ = true;
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (tty_ && drawn_) std::fputc('\n', stderr);
}

}  // namespace hb
