// The slow, obviously right twin of the g(r) pair search (src/observers/structure.cpp): every
// pair of bodies, minimum image, the same bin arithmetic. Test-only; production never loops
// over all pairs.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "math/types.hpp"
#include "core/box.hpp"

namespace hb::test {

// Bin of the pair (lo, hi), lo < hi, or -1 beyond r_max.
inline long twin_bin(const std::vector<Vec3>& p, std::size_t lo, std::size_t hi, const Box& box, double r_max,
                     std::size_t bins) {
  const double d2 = box.near_image(p[hi] - p[lo]).squaredNorm();
  if (d2 >= r_max * r_max) return -1;
  return long(std::min(static_cast<std::size_t>(std::sqrt(d2) * (double(bins) / r_max)), bins - 1));
}

// Every unordered pair once.
inline void all_pairs_histogram(const std::vector<Vec3>& p, const Box& box, double r_max,
                                std::vector<std::uint64_t>& hist) {
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      if (const long k = twin_bin(p, i, j, box, r_max, hist.size()); k >= 0) ++hist[std::size_t(k)];
}

// The ordered pairs (i, j), j != i, of the centres i = offset, offset + stride, ...
inline void centre_pairs_histogram(const std::vector<Vec3>& p, const Box& box, double r_max, std::size_t offset,
                                   std::size_t stride, std::vector<std::uint64_t>& hist) {
  for (std::size_t i = offset; i < p.size(); i += stride)
    for (std::size_t j = 0; j < p.size(); ++j)
      if (j != i)
        if (const long k = twin_bin(p, std::min(i, j), std::max(i, j), box, r_max, hist.size()); k >= 0)
          ++hist[std::size_t(k)];
}

}  // namespace hb::test
