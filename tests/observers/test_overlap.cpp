// The final overlap checks against their brute-force twins.
#include <gtest/gtest.h>

#include <pcg_random.hpp>
#include <random>

#include "observers/overlap.hpp"
#include "setup/init.hpp"

using namespace hb;

TEST(OverlapCheck, GridAgreesWithAllPairs) {
  pcg32 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int rep = 0; rep < 6; ++rep) {
    Box box;
    box.L = Vec3(9.0 + rep, 10.0, 11.5);
    const double sigma = 1.0;
    // a lattice (no overlaps), then some bodies displaced onto others (overlaps)
    std::vector<Vec3> r = fcc_lattice(500, 8.5);
    for (auto& p : r) p = p.cwiseProduct(box.L / 8.5);
    for (int k = 0; k < 3 * rep; ++k) {
      const std::size_t i = std::size_t(u(rng) * r.size()), j = std::size_t(u(rng) * r.size());
      if (i != j) r[i] = r[j] + 0.6 * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    }
    const OverlapReport a = sphere_overlaps_brute(r, box, sigma);
    const OverlapReport b = sphere_overlaps_grid(r, box, sigma);
    EXPECT_EQ(a.overlaps, b.overlaps) << "rep " << rep;
    EXPECT_DOUBLE_EQ(a.min_distance, b.min_distance) << "rep " << rep;
    if (rep > 0) {
      EXPECT_GT(a.overlaps, 0u);
    }
  }
}
