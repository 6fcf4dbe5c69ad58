// Block averaging of a time series of equal-duration block means, with the standard error
// from the Flyvbjerg–Petersen blocking transformation: blocks are merged pairwise while at
// least `min_blocks` remain, and the largest standard error over the levels is reported (the
// plateau value when blocks outlast the correlation time; conservative otherwise). With fewer
// than two blocks the error is unknown: NaN (null in summary.json), never a false 0.
#pragma once
#include <cmath>
#include <limits>
#include <vector>

namespace hb {

struct MeanError {
  double mean = 0.0;
  double error = std::numeric_limits<double>::quiet_NaN();  // unknown below two blocks
  std::size_t blocks = 0;
  bool error_known() const { return !std::isnan(error); }
};

inline MeanError block_average(std::vector<double> x, std::size_t min_blocks = 16) {
  MeanError out;
  out.blocks = x.size();
  if (x.empty()) return out;
  double s = 0.0;
  for (double v : x) s += v;
  out.mean = s / double(x.size());
  if (x.size() < 2) return out;
  double best = 0.0;
  while (true) {
    const std::size_t n = x.size();
    double m = 0.0, q = 0.0;
    for (double v : x) m += v;
    m /= double(n);
    for (double v : x) q += (v - m) * (v - m);
    const double se = std::sqrt(q / (double(n) * double(n - 1)));
    if (se > best) best = se;
    if (n / 2 < min_blocks) break;
    std::vector<double> y(n / 2);
    for (std::size_t k = 0; k < n / 2; ++k) y[k] = 0.5 * (x[2 * k] + x[2 * k + 1]);
    x.swap(y);
  }
  out.error = best;
  return out;
}

}  // namespace hb
