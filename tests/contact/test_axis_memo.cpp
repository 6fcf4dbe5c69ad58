// AxisMemo (contact/axis_memo.hpp): a pair's axis comes back as stored, a slot taken by another
// partner is a miss, the rows of a checkpoint give back the same memo exactly, and a memo that is
// off finds nothing. (Its effect on runs: ObbNeighbors.AxisMemo* in test_obb_neighbors.cpp.)
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "contact/axis_memo.hpp"

namespace hb {
namespace {

TEST(AxisMemo, StoresFindsAndMisses) {
  AxisMemo m;
  Vec3 n(7.0, 7.0, 7.0);
  EXPECT_FALSE(m.find(0, 1, n));  // empty
  EXPECT_EQ(n, Vec3(7.0, 7.0, 7.0));  // untouched on a miss
  const Vec3 u = Vec3(0.3, -0.4, 0.5).normalized();
  m.store(10, 2, 5, u);
  ASSERT_TRUE(m.find(2, 5, n));
  EXPECT_EQ(n, u);  // exact: doubles
  EXPECT_FALSE(m.find(5, 2, n));  // the other direction is its own slot
  EXPECT_FALSE(m.find(2, 5 + AxisMemo::kSlots, n));  // same slot, other partner: a miss
  m.store(10, 2, 5 + AxisMemo::kSlots, Vec3(-u));  // takes the slot over
  EXPECT_FALSE(m.find(2, 5, n));
  ASSERT_TRUE(m.find(2, 5 + AxisMemo::kSlots, n));
  EXPECT_EQ(n, Vec3(-u));
  m.store(10, 3, 4, Vec3::Zero());  // no axis: not kept
  EXPECT_FALSE(m.find(3, 4, n));
  AxisMemo off = m;
  off.on = false;
  EXPECT_FALSE(off.find(2, 5 + AxisMemo::kSlots, n));
  off.store(10, 1, 1, u);
  off.on = true;
  EXPECT_FALSE(off.find(1, 1, n));  // nothing was stored while off
}

// find_near: either side's slot in a memo of at most kPartnerSideBodies bodies, the own slot
// alone in a larger one (its partner's slots would be a cache miss).
TEST(AxisMemo, FindNearLooksAtThePartnerOnlyInASmallMemo) {
  const Vec3 u = Vec3(0.3, -0.4, 0.5).normalized();
  for (const std::size_t bodies : {std::size_t(10), AxisMemo::kPartnerSideBodies,
                                   AxisMemo::kPartnerSideBodies + 1}) {
    AxisMemo m;
    m.store(bodies, 2, 5, u);  // only 2's slot for 5
    Vec3 n;
    ASSERT_TRUE(m.find_near(2, 5, n));
    EXPECT_EQ(n, u);
    ASSERT_TRUE(m.find_either(5, 2, n));  // from the other side, negated
    EXPECT_EQ(n, Vec3(-u));
    const bool small = bodies <= AxisMemo::kPartnerSideBodies;
    EXPECT_EQ(m.find_near(5, 2, n), small) << bodies << " bodies";
    EXPECT_FALSE(m.find_near(5, 3, n));
  }
}

TEST(AxisMemo, RowsRestoreTheSameMemo) {
  std::mt19937_64 g(5);
  std::normal_distribution<double> z(0.0, 1.0);
  std::uniform_int_distribution<std::uint32_t> body(0, 99);
  AxisMemo a;
  EXPECT_TRUE(a.rows().empty());
  for (int k = 0; k < 3000; ++k) a.store(100, body(g), body(g), Vec3(z(g), z(g), z(g)).normalized());
  const auto rows = a.rows();
  EXPECT_EQ(rows.size(), 100u * AxisMemo::kSlots);
  AxisMemo b;
  b.restore(rows);
  EXPECT_EQ(b.rows(), rows);
  for (std::uint32_t i = 0; i < 100; ++i)
    for (std::uint32_t j = 0; j < 100; ++j) {
      Vec3 na, nb;
      const bool fa = a.find(i, j, na), fb = b.find(i, j, nb);
      ASSERT_EQ(fa, fb);
      if (fa) {
        EXPECT_EQ(na, nb);
      }
    }
  EXPECT_THROW(b.restore(std::vector<AxisMemo::Row>(AxisMemo::kSlots + 1)), std::invalid_argument);
}

}  // namespace
}  // namespace hb
