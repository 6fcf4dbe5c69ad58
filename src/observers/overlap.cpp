#include "observers/overlap.hpp"

#include <algorithm>
#include <cmath>

#include "geometry/perram_wertheim.hpp"
#include "neighbors/cell_list.hpp"
#include "observers/close_pairs.hpp"

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

OverlapReport sphere_overlaps_brute(FieldView<Vec3> r, const Box& box, double sigma,
                                    double tol) {
  OverlapReport rep;
  for (std::size_t i = 0; i < r.size(); ++i)
    for (std::size_t j = i + 1; j < r.size(); ++j) check_pair(r[i], r[j], box, sigma, tol, rep);
  return rep;
}

void for_close_pairs(FieldView<Vec3> r, const Box& box, double range,
                     const std::function<void(std::uint32_t, std::uint32_t, const Vec3&)>& fn) {
  int nc[3];
  bool brute = box.L.minCoeff() < 3.0 * range;
  // cells no wider than needed, but at most 64 per body (phi = 1e-9 asked for ~1e11 cells)
  const double w = brute ? range : capped_cell_width(box.L, range, r.size());
  for (int k = 0; k < 3; ++k) {
    nc[k] = static_cast<int>(std::floor(box.L[k] / w));
    if (nc[k] < 3) brute = true;
  }
  const double r2 = range * range;
  if (brute) {
    for (std::uint32_t i = 0; i < r.size(); ++i)
      for (std::uint32_t j = i + 1; j < r.size(); ++j) {
        const Vec3 d = box.minimum_image(r[j] - r[i]);
        if (d.squaredNorm() < r2) fn(i, j, d);
      }
    return;
  }
  std::vector<std::vector<std::uint32_t>> cell(std::size_t(nc[0]) * nc[1] * nc[2]);
  std::vector<std::array<int, 3>> coord(r.size());
  for (std::uint32_t i = 0; i < r.size(); ++i) {
    Vec3 p = r[i];
    box.wrap(p);
    for (int k = 0; k < 3; ++k) {
      const int c = static_cast<int>(std::floor(p[k] / box.L[k] * nc[k]));
      coord[i][k] = c < 0 ? 0 : (c >= nc[k] ? nc[k] - 1 : c);
    }
    cell[(std::size_t(coord[i][2]) * nc[1] + coord[i][1]) * nc[0] + coord[i][0]].push_back(i);
  }
  for (std::uint32_t i = 0; i < r.size(); ++i)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = (coord[i][0] + dx + nc[0]) % nc[0];
          const int y = (coord[i][1] + dy + nc[1]) % nc[1];
          const int z = (coord[i][2] + dz + nc[2]) % nc[2];
          for (std::uint32_t j : cell[(std::size_t(z) * nc[1] + y) * nc[0] + x]) {
            if (j <= i) continue;
            const Vec3 d = box.minimum_image(r[j] - r[i]);
            if (d.squaredNorm() < r2) fn(i, j, d);
          }
        }
}

OverlapReport ellipsoid_overlaps(FieldView<Vec3> r, FieldView<Quat> q,
                                 const Box& box, const Vec3& semi_axes, double tol) {
  OverlapReport rep;
  for_close_pairs(r, box, 2.0 * semi_axes.maxCoeff(), [&](std::uint32_t i, std::uint32_t j, const Vec3& d) {
    const EllipsoidPose A{semi_axes, r[i], q[i]}, B{semi_axes, Vec3(r[i] + d), q[j]};
    const PerramWertheim pw = perram_wertheim(A, B, d, tol);
    ++rep.pairs_checked;
    const double gap = d.norm() * (1.0 - 1.0 / std::sqrt(pw.F));
    if (gap < rep.min_distance) rep.min_distance = gap;
    if (pw.overlap) ++rep.overlaps;
  });
  return rep;
}

OverlapReport sphere_overlaps_grid(FieldView<Vec3> r, const Box& box, double sigma,
                                   double tol) {
  // Pairs closer than 2 sigma: every overlap, and the closest pair of any configuration
  // that is not extremely dilute (min_distance then agrees with the brute force).
  OverlapReport rep;
  for_close_pairs(r, box, 2.0 * sigma, [&](std::uint32_t i, std::uint32_t j, const Vec3&) {
    check_pair(r[i], r[j], box, sigma, tol, rep);
  });
  return rep;
}

OverlapReport sphere_overlaps(FieldView<Vec3> r, const Box& box, double sigma,
                              double tol) {
  return r.size() <= 20000 ? sphere_overlaps_brute(r, box, sigma, tol)
                           : sphere_overlaps_grid(r, box, sigma, tol);
}

}  // namespace hb

namespace hb {

OverlapReport sphere_mixture_overlaps(FieldView<Vec3> r, const std::vector<double>& radii,
                                      const Box& box, double tol) {
  OverlapReport rep;
  double rmax = 0.0;
  for (double x : radii) rmax = std::max(rmax, x);
  for_close_pairs(r, box, 2.0 * rmax, [&](std::uint32_t i, std::uint32_t j, const Vec3& d) {
    const double sigma = radii[i] + radii[j];
    const double dist = d.norm();
    ++rep.pairs_checked;
    rep.min_distance = std::min(rep.min_distance, dist - sigma);
    if (dist < sigma * (1.0 - tol)) ++rep.overlaps;
  });
  return rep;
}

}  // namespace hb
