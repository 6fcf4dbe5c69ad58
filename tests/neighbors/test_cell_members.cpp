// CellMembers (neighbors/cell_members.hpp) against a CellList's own linked cells, its slow twin:
// after random moves between cells (with overflows that grow the capacity), every cell holds the
// same bodies, each member's centre is its body's to within rounding_bound(), and the stencil
// walk of CellList::for_each_stencil_cell over the members finds the bodies, with their image
// shifts, that CellList::for_each_neighbor finds.
#include <gtest/gtest.h>

#include <pcg_random.hpp>
#include <random>
#include <set>
#include <tuple>

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
  auto put = [&](std::uint32_t i, const Vec3& x) {
    r[i] = x;
    cells.insert(i, x);
    members.insert(cells.cell_of(i), i, x);
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
    for (const CellMembers::Member* m = members.begin(c); m != members.end(c); ++m) {
      packed.insert(m->id);
      EXPECT_LE((m->centre() - r[m->id]).norm(), members.rounding_bound());
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
      for (const CellMembers::Member* m = members.begin(c); m != members.end(c); ++m)
        b.insert({m->id, s.x(), s.y(), s.z()});
    });
    EXPECT_EQ(a, b) << "body " << i;
  }
  EXPECT_THROW(members.remove(0, 100000), std::logic_error);
}
