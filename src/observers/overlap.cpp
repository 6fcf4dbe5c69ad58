#include "observers/overlap.hpp"

#include <cmath>

namespace hb {

namespace {
inline void check_pair(const Vec3& a, const Vec3& b, const Box& box, double sigma, double tol,
                       OverlapReport& rep) {
  const double d = box.minimum_image(b - a).norm();
  ++rep.pairs_checked;
  const double gap = d - sigma;
  if (gap < rep.min_distance) rep.min_distance = gap;
  if (d < sigma * (1.0 - tol)) ++rep.overlaps;
}
}  // namespace

OverlapReport sphere_overlaps_brute(const std::vector<Vec3>& r, const Box& box, double sigma,
                                    double tol) {
  OverlapReport rep;
  for (std::size_t i = 0; i < r.size(); ++i)
    for (std::size_t j = i + 1; j < r.size(); ++j) check_pair(r[i], r[j], box, sigma, tol, rep);
  return rep;
}

OverlapReport sphere_overlaps_grid(const std::vector<Vec3>& r, const Box& box, double sigma,
                                   double tol) {
  // Cells of width >= sigma; with fewer than 3 cells along an axis, fall back to brute force.
  int nc[3];
  for (int k = 0; k < 3; ++k) {
    nc[k] = static_cast<int>(std::floor(box.L[k] / sigma));
    if (nc[k] < 3) return sphere_overlaps_brute(r, box, sigma, tol);
  }
  const std::size_t ncell = std::size_t(nc[0]) * nc[1] * nc[2];
  std::vector<std::vector<std::uint32_t>> cell(ncell);
  std::vector<std::array<int, 3>> coord(r.size());
  for (std::uint32_t i = 0; i < r.size(); ++i) {
    Vec3 p = r[i];
    box.wrap(p);
    for (int k = 0; k < 3; ++k) {
      int c = static_cast<int>(std::floor(p[k] / box.L[k] * nc[k]));
      coord[i][k] = c < 0 ? 0 : (c >= nc[k] ? nc[k] - 1 : c);
    }
    cell[(std::size_t(coord[i][2]) * nc[1] + coord[i][1]) * nc[0] + coord[i][0]].push_back(i);
  }
  OverlapReport rep;
  for (std::uint32_t i = 0; i < r.size(); ++i) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = (coord[i][0] + dx + nc[0]) % nc[0];
          const int y = (coord[i][1] + dy + nc[1]) % nc[1];
          const int z = (coord[i][2] + dz + nc[2]) % nc[2];
          for (std::uint32_t j : cell[(std::size_t(z) * nc[1] + y) * nc[0] + x])
            if (j > i) check_pair(r[i], r[j], box, sigma, tol, rep);
        }
  }
  return rep;
}

OverlapReport sphere_overlaps(const std::vector<Vec3>& r, const Box& box, double sigma,
                              double tol) {
  return r.size() <= 20000 ? sphere_overlaps_brute(r, box, sigma, tol)
                           : sphere_overlaps_grid(r, box, sigma, tol);
}

}  // namespace hb
