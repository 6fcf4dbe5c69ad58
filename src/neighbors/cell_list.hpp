// Linked cell lists over the box: cells at least `min_width` wide, so bodies that can touch sit
// in the same or adjacent cells (27-cell stencil). Bodies change cell only through cell-crossing
// events, which the caller schedules from crossing_time(). Along an axis that is not periodic
// (hard walls at 0 and L) the stencil stops at the first and last cells instead of wrapping, and
// the outer faces of those cells are never crossed.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "math/types.hpp"

namespace hb {

// The width of the cells of a grid over the box L for n bodies: min_width, or wider so that there
// are at most max_per_body cells per body (64 by default; and 2^28 in all). A dilute box
// (phi = 1e-9) would otherwise ask for ~1e11 empty cells; wider cells are as correct (a body
// still meets only the 27 cells around it). A function of (L, min_width, n, max_per_body) alone:
// a checkpoint's cell coordinates fit the grid rebuilt on restore. Throws std::invalid_argument
// when the box is narrower than min_width.
inline double capped_cell_width(const Vec3& L, double min_width, std::size_t n_bodies,
                                double max_per_body = 64.0) {
  constexpr double kMaxCells = double(1u << 28);
  const double cap = std::min(kMaxCells, std::max(27.0, max_per_body * double(n_bodies)));
  double w = min_width;
  auto cells = [&] { return std::floor(L[0] / w) * std::floor(L[1] / w) * std::floor(L[2] / w); };
  for (int k = 0; k < 3; ++k)
    if (!(std::floor(L[k] / w) >= 1.0)) throw std::invalid_argument("box smaller than one cell");
  if (cells() > cap) {
    w *= std::cbrt(cells() / cap);
    while (cells() > cap) w *= 1.0 + 1.0 / 64;
  }
  return w;
}

class CellList {
 public:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  CellList() = default;
  CellList(const Vec3& L, double min_width, std::size_t n_bodies,
           std::array<bool, 3> periodic = {true, true, true}) {
    init(L, min_width, n_bodies, periodic);
  }

  // max_per_body: the cap on cells per body of capped_cell_width.
  void init(const Vec3& L, double min_width, std::size_t n_bodies,
            std::array<bool, 3> periodic = {true, true, true}, double max_per_body = 64.0) {
    periodic_ = periodic;
    const double w = capped_cell_width(L, min_width, n_bodies, max_per_body);
    auto count = [&](int k) { return std::floor(L[k] / w); };
    for (int k = 0; k < 3; ++k) {
      int nc = static_cast<int>(std::max(1.0, count(k)));
      // With fewer than 3 cells a periodic stencil would wrap onto itself; use one cell then.
      if (nc < 3 && periodic_[k]) nc = 1;
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
  const std::array<bool, 3>& periodic() const { return periodic_; }
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
  // Insert body i into the cell with the given coordinates.
  void place_at(std::uint32_t i, const std::array<int, 3>& c) {
    for (int k = 0; k < 3; ++k)
      if (c[k] < 0 || c[k] >= nc_[k]) throw std::invalid_argument("cell coordinate out of range");
    place(i, c);
  }
  std::size_t size() const { return cell_.size(); }
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
    if (!periodic_[k] && wrapped) throw std::logic_error("cell crossing through a wall");
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
        if (!periodic_[k] && coord_[i][k] == nc_[k] - 1) continue;  // the wall's side
        t = ((coord_[i][k] + 1) * width_[k] - r[k]) / v[k];
        f = 2 * k + 1;
      } else if (v[k] < 0.0) {
        if (!periodic_[k] && coord_[i][k] == 0) continue;
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

  // True when some periodic axis has a single cell: then the stencil cannot tell periodic images
  // apart and callers must apply the minimum-image convention themselves.
  bool needs_minimum_image() const {
    for (int k = 0; k < 3; ++k)
      if (nc_[k] == 1 && periodic_[k]) return true;
    return false;
  }

  // Calls fn(j, shift) for every body j in the 27 cells around body i's cell (including i
  // itself); `shift` is the periodic image offset to add to j's position to place it next to i
  // (zero along axes with a single cell, see needs_minimum_image()).
  template <class Fn>
  void for_each_neighbor(std::uint32_t i, const Vec3& L, Fn&& fn) const {
    for_each_stencil_cell(i, L, [&](std::uint32_t cell, const Vec3& shift) { walk(cell, shift, fn); });
  }
  // Calls fn(c, shift) for every cell c of the 27 cells around body i's cell, with the image
  // shift of its bodies as for_each_neighbor gives it (for a caller that keeps its own record
  // of each cell's bodies: neighbors/cell_members.hpp).
  template <class Fn>
  [[gnu::always_inline]] void for_each_stencil_cell(std::uint32_t i, const Vec3& L, Fn&& fn) const {
    std::array<int, 3> lo{-1, -1, -1}, hi{1, 1, 1};
    for (int m = 0; m < 3; ++m)
      if (nc_[m] == 1) lo[m] = hi[m] = 0;
    visit_cells(coord_[i], lo, hi, L, fn);
  }
  // Calls fn(j, shift) for the bodies in the 9 cells that became adjacent to body i when it
  // entered its cell through face `face` (the far layer of the new 27-cell stencil).
  template <class Fn>
  void for_each_new_neighbor(std::uint32_t i, int face, const Vec3& L, Fn&& fn) const {
    const int k = face >> 1;
    if (nc_[k] == 1) return;
    std::array<int, 3> lo{-1, -1, -1}, hi{1, 1, 1};
    for (int m = 0; m < 3; ++m)
      if (nc_[m] == 1) lo[m] = hi[m] = 0;
    lo[k] = hi[k] = (face & 1) ? 1 : -1;
    visit(coord_[i], lo, hi, L, fn);
  }
  // Without image shifts (tests, diagnostics).
  template <class Fn>
  void for_each_neighbor(std::uint32_t i, Fn&& fn) const {
    for_each_neighbor(i, Vec3::Zero(), [&](std::uint32_t j, const Vec3&) { fn(j); });
  }
  template <class Fn>
  void for_each_new_neighbor(std::uint32_t i, int face, Fn&& fn) const {
    for_each_new_neighbor(i, face, Vec3::Zero(), [&](std::uint32_t j, const Vec3&) { fn(j); });
  }

 private:
  // Visit the cells c + d for d in [lo, hi] (per axis), wrapping periodically and telling fn
  // the image shift of each cell; along an axis that is not periodic, cells beyond the ends are
  // left out.
  template <class Fn>
  void visit(const std::array<int, 3>& c, const std::array<int, 3>& lo,
             const std::array<int, 3>& hi, const Vec3& L, Fn& fn) const {
    visit_cells(c, lo, hi, L, [&](std::uint32_t cell, const Vec3& shift) { walk(cell, shift, fn); });
  }
  // fn(j, shift) for each body j of the cell.
  template <class Fn>
  void walk(std::uint32_t cell, const Vec3& shift, Fn& fn) const {
    for (std::uint32_t j = head_[cell]; j != kNone; j = next_[j]) fn(j, shift);
  }
  // The cells of visit, each once: fn(cell index, image shift).
  template <class Fn>
  [[gnu::always_inline]] void visit_cells(const std::array<int, 3>& c, const std::array<int, 3>& lo,
                   const std::array<int, 3>& hi, const Vec3& L, Fn&& fn) const {
    int xs[3], ys[3], zs[3];
    double sx[3], sy[3], sz[3];
    const int nx = axis(c[0], lo[0], hi[0], 0, L[0], xs, sx);
    const int ny = axis(c[1], lo[1], hi[1], 1, L[1], ys, sy);
    const int nz = axis(c[2], lo[2], hi[2], 2, L[2], zs, sz);
    for (int a = 0; a < nz; ++a)
      for (int b = 0; b < ny; ++b) {
        const std::uint32_t row = static_cast<std::uint32_t>((zs[a] * nc_[1] + ys[b]) * nc_[0]);
        for (int d = 0; d < nx; ++d) fn(row + xs[d], Vec3(sx[d], sy[b], sz[a]));
      }
  }
  int axis(int c, int lo, int hi, int k, double L, int* out, double* shift) const {
    int n = 0;
    for (int d = lo; d <= hi; ++d) {
      int x = c + d;
      double s = 0.0;
      if (x < 0 || x >= nc_[k]) {
        if (!periodic_[k]) continue;
        if (x < 0) x += nc_[k], s = -L;
        else x -= nc_[k], s = L;
      }
      out[n] = x;
      shift[n] = s;
      ++n;
    }
    return n;
  }

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
  std::array<bool, 3> periodic_{true, true, true};
  Vec3 width_ = Vec3::Ones();
  std::vector<std::uint32_t> head_, next_, prev_, cell_;
  std::vector<std::array<int, 3>> coord_;
};

}  // namespace hb
