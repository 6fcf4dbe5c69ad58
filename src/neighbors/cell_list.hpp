// Linked cell lists over the periodic box: cells at least `min_width` wide, so bodies that can
// touch sit in the same or adjacent cells (27-cell stencil). Bodies change cell only through
// cell-crossing events, which the caller schedules from crossing_time().
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "math/types.hpp"

namespace hb {

class CellList {
 public:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  CellList() = default;
  CellList(const Vec3& L, double min_width, std::size_t n_bodies) { init(L, min_width, n_bodies); }

  void init(const Vec3& L, double min_width, std::size_t n_bodies) {
    for (int k = 0; k < 3; ++k) {
      int nc = static_cast<int>(std::floor(L[k] / min_width));
      if (nc < 1) throw std::invalid_argument("box smaller than one cell");
      // With fewer than 3 cells the stencil would wrap onto itself; use one cell then.
      if (nc < 3) nc = 1;
      nc_[k] = nc;
      width_[k] = L[k] / nc;
    }
    head_.assign(static_cast<std::size_t>(nc_[0]) * nc_[1] * nc_[2], kNone);
    next_.assign(n_bodies, kNone);
    prev_.assign(n_bodies, kNone);
    cell_.assign(n_bodies, kNone);
    coord_.assign(n_bodies, {0, 0, 0});
  }

  const std::array<int, 3>& dims() const { return nc_; }
  const Vec3& width() const { return width_; }
  std::size_t n_cells() const { return head_.size(); }
  std::uint32_t cell_of(std::uint32_t i) const { return cell_[i]; }
  const std::array<int, 3>& coord_of(std::uint32_t i) const { return coord_[i]; }
  std::uint32_t head(std::uint32_t c) const { return head_[c]; }
  std::uint32_t next(std::uint32_t i) const { return next_[i]; }

  std::uint32_t index(int x, int y, int z) const {
    return static_cast<std::uint32_t>((z * nc_[1] + y) * nc_[0] + x);
  }
  int wrap(int c, int k) const { return c < 0 ? c + nc_[k] : (c >= nc_[k] ? c - nc_[k] : c); }

  // Insert body i at position r (wrapped into the box).
  void insert(std::uint32_t i, const Vec3& r) {
    std::array<int, 3> c;
    for (int k = 0; k < 3; ++k) {
      c[k] = static_cast<int>(std::floor(r[k] / width_[k]));
      if (c[k] < 0) c[k] = 0;
      if (c[k] >= nc_[k]) c[k] = nc_[k] - 1;
    }
    place(i, c);
  }
  void remove(std::uint32_t i) {
    const std::uint32_t c = cell_[i];
    if (c == kNone) return;
    if (prev_[i] != kNone) next_[prev_[i]] = next_[i]; else head_[c] = next_[i];
    if (next_[i] != kNone) prev_[next_[i]] = prev_[i];
    cell_[i] = kNone;
  }
  // Move body i one cell through face f (0..5 = -x,+x,-y,+y,-z,+z). Returns true when the body
  // crossed the periodic boundary (its position must be wrapped by the caller).
  bool cross(std::uint32_t i, int face) {
    const int k = face >> 1;
    std::array<int, 3> c = coord_[i];
    c[k] += (face & 1) ? 1 : -1;
    const bool wrapped = c[k] < 0 || c[k] >= nc_[k];
    c[k] = wrap(c[k], k);
    remove(i);
    place(i, c);
    return wrapped;
  }

  // Time from now until a body at r (inside its cell) moving with velocity v leaves its cell,
  // and through which face. Positions slightly outside the cell by rounding give time 0.
  double crossing_time(std::uint32_t i, const Vec3& r, const Vec3& v, int& face) const {
    double best = kInf;
    face = -1;
    for (int k = 0; k < 3; ++k) {
      if (nc_[k] == 1) continue;  // a single cell along k: never crossed
      double t;
      int f;
      if (v[k] > 0.0) {
        t = ((coord_[i][k] + 1) * width_[k] - r[k]) / v[k];
        f = 2 * k + 1;
      } else if (v[k] < 0.0) {
        t = (coord_[i][k] * width_[k] - r[k]) / v[k];
        f = 2 * k;
      } else {
        continue;
      }
      if (t < 0.0) t = 0.0;
      if (t < best) { best = t; face = f; }
    }
    return best;
  }

  // Calls fn(j) for every body j in the 27 cells around body i's cell (including i itself).
  template <class Fn>
  void for_each_neighbor(std::uint32_t i, Fn&& fn) const {
    const auto& c = coord_[i];
    std::array<int, 3> lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = nc_[k] == 1 ? 0 : -1;
      hi[k] = nc_[k] == 1 ? 0 : 1;
    }
    for (int dz = lo[2]; dz <= hi[2]; ++dz) {
      const int z = wrap(c[2] + dz, 2);
      for (int dy = lo[1]; dy <= hi[1]; ++dy) {
        const int y = wrap(c[1] + dy, 1);
        for (int dx = lo[0]; dx <= hi[0]; ++dx) {
          const int x = wrap(c[0] + dx, 0);
          for (std::uint32_t j = head_[index(x, y, z)]; j != kNone; j = next_[j]) fn(j);
        }
      }
    }
  }
  // Calls fn(j) for the bodies in the 9 cells that became adjacent to body i when it entered
  // its cell through face `face` (the far layer of the new 27-cell stencil).
  template <class Fn>
  void for_each_new_neighbor(std::uint32_t i, int face, Fn&& fn) const {
    const int k = face >> 1;
    if (nc_[k] == 1) return;
    const auto& c = coord_[i];
    std::array<int, 3> lo{-1, -1, -1}, hi{1, 1, 1};
    for (int m = 0; m < 3; ++m)
      if (nc_[m] == 1) lo[m] = hi[m] = 0;
    lo[k] = hi[k] = (face & 1) ? 1 : -1;
    for (int dz = lo[2]; dz <= hi[2]; ++dz) {
      const int z = wrap(c[2] + dz, 2);
      for (int dy = lo[1]; dy <= hi[1]; ++dy) {
        const int y = wrap(c[1] + dy, 1);
        for (int dx = lo[0]; dx <= hi[0]; ++dx) {
          const int x = wrap(c[0] + dx, 0);
          for (std::uint32_t j = head_[index(x, y, z)]; j != kNone; j = next_[j]) fn(j);
        }
      }
    }
  }

 private:
  void place(std::uint32_t i, const std::array<int, 3>& c) {
    const std::uint32_t id = index(c[0], c[1], c[2]);
    coord_[i] = c;
    cell_[i] = id;
    prev_[i] = kNone;
    next_[i] = head_[id];
    if (head_[id] != kNone) prev_[head_[id]] = i;
    head_[id] = i;
  }

  std::array<int, 3> nc_{1, 1, 1};
  Vec3 width_ = Vec3::Ones();
  std::vector<std::uint32_t> head_, next_, prev_, cell_;
  std::vector<std::array<int, 3>> coord_;
};

}  // namespace hb
