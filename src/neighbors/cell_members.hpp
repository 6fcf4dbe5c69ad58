// The bodies of each cell of a grid (a CellList's cells) as one packed array per cell of
// (centre in single precision, id), for a walk over a cell stencil that needs only the centres
// first (ObbNeighbors::link: the circumsphere test before the box test).
//
// Why: a CellList keeps its cells as linked lists through the bodies. A walk then chases one
// pointer per body, each load waiting for the one before, and reads each body's record for its
// centre: at N = 256000 ellipsoids that walk and those loads were 8-9 % of the run (perf; the
// rebuild of one box meets ~330 bodies in its 27 cells). Here a cell's members are 16 bytes
// each, side by side: the walk reads a few lines per cell, all of them independent.
//
// Capacity: the same for every cell, twice the mean occupancy plus 8 (the grid should have at
// most one cell per body: capped_cell_width's max_per_body = 1), doubled for all cells at once
// on the rare overflow (no allocation per event, as AdjacencyLists). A removal moves the cell's
// last member into the hole, so the order within a cell depends on the history: callers must not
// depend on it (ObbNeighbors' lists are sorted).
//
// Rounding: |float(x) - x| <= 2^-24 |x|. A caller that tests distances between members' centres
// widens its cut-off by rounding_bound() (the slow twin: the exact test on the caller's own
// double-precision record).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "math/types.hpp"

namespace hb {

class CellMembers {
 public:
  struct Member {
    float x, y, z;
    std::uint32_t id;
    Vec3 centre() const { return Vec3(x, y, z); }
  };

  void init(std::size_t n_cells, std::size_t n_bodies) {
    const double mean = n_cells > 0 ? double(n_bodies) / double(n_cells) : 0.0;
    cap_ = static_cast<std::uint32_t>(std::ceil(2.0 * mean)) + 8;
    data_.assign(n_cells * cap_, Member{});
    size_.assign(n_cells, 0);
    max_abs_ = 0.0;
  }
  std::uint32_t size(std::uint32_t cell) const { return size_[cell]; }
  const Member* begin(std::uint32_t cell) const { return data_.data() + std::size_t(cell) * cap_; }
  const Member* end(std::uint32_t cell) const { return begin(cell) + size_[cell]; }

  void insert(std::uint32_t cell, std::uint32_t id, const Vec3& c) {
    if (size_[cell] == cap_) grow();
    max_abs_ = std::max(max_abs_, c.cwiseAbs().maxCoeff());
    data_[std::size_t(cell) * cap_ + size_[cell]++] =
        Member{float(c.x()), float(c.y()), float(c.z()), id};
  }
  void remove(std::uint32_t cell, std::uint32_t id) {
    Member* b = data_.data() + std::size_t(cell) * cap_;
    Member* e = b + size_[cell];
    Member* p = std::find_if(b, e, [id](const Member& m) { return m.id == id; });
    if (p == e) throw std::logic_error("cell members: body not in its cell");
    *p = e[-1];
    --size_[cell];
  }
  // A bound on |m.centre() - c| for every member inserted at centre c: sqrt(3) 2^-24 times the
  // largest coordinate inserted, doubled, plus 1e-44 (a coordinate below float's normal range
  // is rounded to within 2^-150 absolute).
  double rounding_bound() const {
    return 2.0 * 1.7320508075688772 * std::ldexp(max_abs_, -24) + 1e-44;
  }

 private:
  void grow() {
    const std::uint32_t cap = 2 * cap_;
    std::vector<Member> d(size_.size() * cap);
    for (std::size_t c = 0; c < size_.size(); ++c)
      std::copy_n(data_.begin() + c * cap_, size_[c], d.begin() + c * cap);
    data_.swap(d);
    cap_ = cap;
  }
  std::uint32_t cap_ = 8;
  std::vector<Member> data_;
  std::vector<std::uint32_t> size_;
  double max_abs_ = 0.0;
};

}  // namespace hb
