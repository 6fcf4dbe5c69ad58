// CellMembers (neighbors/cell_members.hpp) against a CellList's own linked cells, its slow twin:
// after random moves between cells (with overflows that grow the capacity), every cell holds the
// same bodies, each member's centre is its body's to within rounding_bound() (and its box
// half-extents its body's, rounded up), and the stencil
// walk of CellList::for_each_stencil_cell over the members finds the bodies, with their image
// shifts, that CellList::for_each_neighbor finds; and the walk's distance test
// (for_each_within) against double precision.
#include <gtest/gtest.h>

#include <pcg_random.hpp>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "core/box.hpp"
#include "neighbors/cell_list.hpp"
#include "neighbors/cell_members.hpp"

using namespace hb;

TEST(CellMembers, HoldWhatTheLinkedCellsHold) {
  pcg32 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Box box;
  box.L = Vec3(9.0, 7.5, 12.0);
  const std::size_t n = 400;
  CellList cells;
  cells.init(box.L, 2.0, n, box.periodic, /*max_per_body=*/1.0);
  ASSERT_LE(cells.n_cells(), n);
  CellMembers members;
  members.init(cells.n_cells(), n);
  std::vector<Vec3> r(n);
  // each body's box half-extents, which must follow it through the moves into holes and growth
  auto half_of = [](std::uint32_t i) { return Vec3(0.1 + 1e-3 * i, 0.3 + 7e-4 * i, 0.2 + 3e-4 * i); };
  auto put = [&](std::uint32_t i, const Vec3& x) {
    r[i] = x;
    cells.insert(i, x);
    members.insert(cells.cell_of(i), i, x, half_of(i));
  };
  for (std::uint32_t i = 0; i < n; ++i) put(i, Vec3(u(rng) * box.L.x(), u(rng) * box.L.y(), u(rng) * box.L.z()));
  std::uniform_int_distribution<std::uint32_t> body(0, n - 1);
  for (int k = 0; k < 3000; ++k) {
    const std::uint32_t i = body(rng);
    members.remove(cells.cell_of(i), i);
    cells.remove(i);
    // a third of the moves pile bodies into one corner cell: its capacity overflows and grows
    const Vec3 x = k % 3 == 0 ? Vec3(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng))
                              : Vec3(u(rng) * box.L.x(), u(rng) * box.L.y(), u(rng) * box.L.z());
    put(i, x);
  }
  std::size_t biggest = 0;
  for (std::uint32_t c = 0; c < cells.n_cells(); ++c) {
    std::set<std::uint32_t> linked, packed;
    for (std::uint32_t j = cells.head(c); j != CellList::kNone; j = cells.next(j)) linked.insert(j);
    for (std::uint32_t k = 0; k < members.size(c); ++k) {
      const CellMembers::Member m = members.member(c, k);
      packed.insert(m.id);
      EXPECT_LE((m.centre() - r[m.id]).norm(), members.rounding_bound());
      const Vec3 h = members.half(c, k).value(), want = half_of(m.id);
      for (int a = 0; a < 3; ++a) {  // rounded up to single precision
        EXPECT_GE(h[a], want[a]) << "body " << m.id;
        EXPECT_LE(h[a], want[a] * (1.0 + 2.5e-7)) << "body " << m.id;
      }
    }
    EXPECT_EQ(packed, linked) << "cell " << c;
    EXPECT_EQ(members.size(c), linked.size());
    biggest = std::max(biggest, linked.size());
  }
  EXPECT_GT(biggest, 3 * n / cells.n_cells() + 8);  // the corner cell overflowed at least once
  for (std::uint32_t i = 0; i < n; i += 7) {
    std::multiset<std::tuple<std::uint32_t, double, double, double>> a, b;
    cells.for_each_neighbor(i, box.L, [&](std::uint32_t j, const Vec3& s) { a.insert({j, s.x(), s.y(), s.z()}); });
    cells.for_each_stencil_cell(i, box.L, [&](std::uint32_t c, const Vec3& s) {
      for (std::uint32_t k = 0; k < members.size(c); ++k)
        b.insert({members.member(c, k).id, s.x(), s.y(), s.z()});
    });
    EXPECT_EQ(a, b) << "body " << i;
  }
  EXPECT_THROW(members.remove(0, 100000), std::logic_error);
}

// for_each_within against the distance in double precision on the stored centres, its slow
// twin: in cells of 1 to 13 members (and of 62 to 139 every 50th trial: the walk's blocks of 64
// and their ends), after removals that move the last member into a hole (and
// a growth of the capacity), with members placed within 1e-7 of the cut-off on both sides, along
// periodic axes folded once and an axis without a period. Every member within reach is reported
// exactly once; nothing further than the documented widening (1e-5 S) is.
TEST(CellMembers, WalkFindsTheMembersWithinReach) {
  pcg32 rng(29);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec3 L(10.0, 8.0, 12.0);
  const Vec3 period(L.x(), L.y(), kInf);  // z has no period
  const double reach = 3.0;
  std::size_t reported = 0, near_cut = 0;
  for (int trial = 0; trial < 400; ++trial) {
    CellMembers members;
    members.init(1, 1);  // one cell of capacity 10: the 11th insertion grows it
    const Vec3 from(u(rng) * L.x(), u(rng) * L.y(), u(rng) * L.z());
    const std::uint32_t n = trial % 50 == 0 ? 62 + 11 * (trial / 50) : 1 + trial % 13;
    double max_abs = 0.0;  // of the centres inserted (S below)
    for (std::uint32_t k = 0; k < n + 2; ++k) {
      Vec3 c(u(rng) * L.x(), u(rng) * L.y(), u(rng) * L.z());
      if (k % 3 == 0) {  // on the cut-off, +-1e-7, in a random direction (through the fold)
        Vec3 dir(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
        dir.normalize();
        c = from + (reach + (u(rng) - 0.5) * 2e-7) * dir;
        for (int a = 0; a < 2; ++a) c[a] -= L[a] * std::floor(c[a] / L[a]);
      }
      members.insert(0, 100 + k, c);  // ids 100, 101, ...
      max_abs = std::max(max_abs, c.cwiseAbs().maxCoeff());
    }
    members.remove(0, 100 + trial % (n + 2));  // a hole, filled by the last member
    members.remove(0, members.member(0, members.size(0) - 1).id);
    ASSERT_EQ(members.size(0), n);
    std::multiset<std::uint32_t> got;
    std::vector<std::uint32_t> order;  // reported in the members' order
    members.for_each_within(0, from, period, reach, [&](std::uint32_t j) {
      got.insert(j);
      order.push_back(j);
    });
    {
      std::size_t at = 0;
      for (std::uint32_t k = 0; k < members.size(0) && at < order.size(); ++k)
        if (members.member(0, k).id == order[at]) ++at;
      EXPECT_EQ(at, order.size()) << "trial " << trial << ": not in the members' order";
    }
    const double S = max_abs + from.cwiseAbs().maxCoeff() + reach + L.head<2>().maxCoeff();
    std::set<std::uint32_t> all;
    for (std::uint32_t k = 0; k < members.size(0); ++k) {
      const CellMembers::Member m = members.member(0, k);
      const std::uint32_t j = m.id;
      all.insert(j);
      Vec3 d = m.centre() - from;
      for (int a = 0; a < 3; ++a) d[a] = std::min(std::abs(d[a]), period[a] - std::abs(d[a]));
      const double dist = d.norm();
      if (std::abs(dist - reach) < 1e-5) ++near_cut;
      if (dist <= reach) {
        EXPECT_EQ(got.count(j), 1u) << "trial " << trial << " member " << j;
      }
      if (dist > reach + 1e-5 * S + 1e-9) {
        EXPECT_EQ(got.count(j), 0u) << "trial " << trial;
      }
      EXPECT_LE(got.count(j), 1u);
    }
    for (std::uint32_t j : got) EXPECT_EQ(all.count(j), 1u) << "a removed member was reported";
    reported += got.size();
  }
  EXPECT_GT(reported, 400u);
  EXPECT_GT(near_cut, 200u);  // the cut-off was tried
}

// The walk's axis-aligned box test (for_each_within_box, members inserted with their
// half-extents) against double precision on the stored centres and the extents as given, its
// slow twin: a member is reported exactly once if it is within reach and its box overlaps the
// query's along every axis (the separation folded once), and never if it is beyond reach or
// apart along an axis by more than the documented widening. Boxes from needles to cubes,
// members placed within 1e-7 of a box face on both sides; members inserted without extents
// pass the box test.
TEST(CellMembers, WalkSkipsTheMembersWhoseBoxesLieApart) {
  pcg32 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec3 L(10.0, 8.0, 12.0);
  const Vec3 period(L.x(), L.y(), kInf);
  const double reach = 4.0;
  std::size_t reported = 0, skipped_by_boxes = 0, near_face = 0;
  auto extents = [&]() {  // a needle along a random axis, or a rounder box
    Vec3 h(u(rng) * 0.6 + 0.05, u(rng) * 0.6 + 0.05, u(rng) * 0.6 + 0.05);
    if (u(rng) < 0.5) h[static_cast<int>(u(rng) * 3) % 3] = 1.0 + u(rng);
    return h;
  };
  for (int trial = 0; trial < 400; ++trial) {
    CellMembers members;
    members.init(1, 1);
    const Vec3 from(u(rng) * L.x(), u(rng) * L.y(), u(rng) * L.z());
    const Vec3 hq = extents();
    const std::uint32_t n = 1 + trial % 70;
    std::vector<Vec3> half(n, Vec3::Constant(kInf));
    double max_abs = 0.0;
    for (std::uint32_t k = 0; k < n; ++k) {
      Vec3 c(u(rng) * L.x(), u(rng) * L.y(), u(rng) * L.z());
      if (k % 7 != 6) half[k] = extents();  // every seventh without extents
      if (k % 3 == 0 && k % 7 != 6) {  // on a box face along one axis, +-1e-7 (within reach)
        const int a = static_cast<int>(u(rng) * 3) % 3;
        c = from + Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5).cwiseProduct(hq + half[k]);
        c[a] = from[a] + (u(rng) < 0.5 ? -1.0 : 1.0) * (hq[a] + half[k][a] + (u(rng) - 0.5) * 2e-7);
        for (int b = 0; b < 2; ++b) c[b] -= L[b] * std::floor(c[b] / L[b]);
      }
      if (half[k].allFinite()) members.insert(0, k, c, half[k]);
      else members.insert(0, k, c);
      max_abs = std::max(max_abs, c.cwiseAbs().maxCoeff());
    }
    std::multiset<std::uint32_t> got;
    members.for_each_within_box(0, from, period, reach, hq, [&](std::uint32_t j) { got.insert(j); });
    const double S = max_abs + from.cwiseAbs().maxCoeff() + reach + L.head<2>().maxCoeff();
    const double slack = 1e-5 * S + 1e-9;
    for (std::uint32_t k = 0; k < members.size(0); ++k) {
      const CellMembers::Member m = members.member(0, k);
      const std::uint32_t j = m.id;
      Vec3 d = m.centre() - from;
      for (int a = 0; a < 3; ++a) d[a] = std::min(std::abs(d[a]), period[a] - std::abs(d[a]));
      const Vec3 gap = d - hq - half[j];  // > 0 along an axis: the boxes lie apart there
      if (gap.cwiseAbs().minCoeff() < 1e-6) ++near_face;
      if (d.norm() <= reach && gap.maxCoeff() <= 0.0) {
        EXPECT_EQ(got.count(j), 1u) << "trial " << trial << " member " << j;
      }
      if (d.norm() > reach + slack || gap.maxCoeff() > slack) {
        EXPECT_EQ(got.count(j), 0u) << "trial " << trial << " member " << j;
      }
      skipped_by_boxes += d.norm() <= reach && gap.maxCoeff() > slack;
      EXPECT_LE(got.count(j), 1u);
    }
    reported += got.size();
  }
  std::printf("  %zu reported, %zu within reach skipped by the boxes, %zu near a box face\n",
              reported, skipped_by_boxes, near_face);
  EXPECT_GT(reported, 1000u);
  EXPECT_GT(skipped_by_boxes, 1000u);
  EXPECT_GT(near_face, 500u);
}

// The walk's reach in single precision is rounded up by CellMembers::next_up, the inline twin of
// std::nextafter(f, inf): the same bits on every kind of non-negative float (zero, subnormals,
// the normal range across binades, the largest finite, inf) and on random squares of reaches.
TEST(CellMembers, NextUpIsNextafterBitForBit) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> xs = {0.0f, std::numeric_limits<float>::denorm_min(),
                           std::numeric_limits<float>::min(), 1.0f, 0.999999940f,
                           std::numeric_limits<float>::max(), inf};
  for (int e = -149; e <= 127; ++e) xs.push_back(std::ldexp(1.0f, e));
  pcg32 rng(7);
  std::uniform_real_distribution<double> u(0.0, 30.0);
  for (int n = 0; n < 100000; ++n) {
    const double r = u(rng);
    xs.push_back(static_cast<float>(r * r));
  }
  for (const float x : xs)
    EXPECT_EQ(std::bit_cast<std::uint32_t>(CellMembers::next_up(x)),
              std::bit_cast<std::uint32_t>(std::nextafter(x, inf)))
        << x;
}
