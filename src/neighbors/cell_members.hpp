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
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
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

  // Half-extents of the axis-aligned box around a member's body (single precision, rounded
  // up; inf: none given), kept beside the members (same slots) and read only by the walk with
  // boxes (for_each_within_box).
  struct Half {
    float x, y, z, pad;
    Vec3 value() const { return Vec3(x, y, z); }
  };

  void init(std::size_t n_cells, std::size_t n_bodies) {
    const double mean = n_cells > 0 ? double(n_bodies) / double(n_cells) : 0.0;
    cap_ = static_cast<std::uint32_t>(std::ceil(2.0 * mean)) + 8;
    data_.assign(n_cells * cap_, Member{});
    half_.assign(n_cells * cap_, Half{});
    size_.assign(n_cells, 0);
    max_abs_ = 0.0;
  }
  std::uint32_t size(std::uint32_t cell) const { return size_[cell]; }
  const Member* begin(std::uint32_t cell) const { return data_.data() + std::size_t(cell) * cap_; }
  const Member* end(std::uint32_t cell) const { return begin(cell) + size_[cell]; }

  const Half& half(const Member* m) const { return half_[std::size_t(m - data_.data())]; }

  // A member at centre c whose body lies within the axis-aligned box c +- half (default: none,
  // the box test passes it).
  void insert(std::uint32_t cell, std::uint32_t id, const Vec3& c,
              const Vec3& half = Vec3::Constant(kInf)) {
    if (size_[cell] == cap_) grow();
    max_abs_ = std::max(max_abs_, c.cwiseAbs().maxCoeff());
    const std::size_t slot = std::size_t(cell) * cap_ + size_[cell]++;
    data_[slot] = Member{float(c.x()), float(c.y()), float(c.z()), id};
    half_[slot] = Half{up(half.x()), up(half.y()), up(half.z()), 0.0f};
  }
  void remove(std::uint32_t cell, std::uint32_t id) {
    const std::size_t first = std::size_t(cell) * cap_, last = first + size_[cell] - 1;
    Member* b = data_.data() + first;
    Member* e = b + size_[cell];
    Member* p = std::find_if(b, e, [id](const Member& m) { return m.id == id; });
    if (p == e) throw std::logic_error("cell members: body not in its cell");
    const std::size_t at = std::size_t(p - data_.data());
    data_[at] = data_[last];
    half_[at] = half_[last];
    --size_[cell];
  }
  // Calls fn(id) for the members of `cell` whose centres are within `reach` of `from`, the
  // separation taken along each axis k as |x| folded once, min(|x|, P_k - |x|) (the nearest image
  // for |x| < P_k; P_k = kInf: no period). Conservative: every member whose stored centre
  // (m.centre(), in double precision) is within reach is reported, with some slightly beyond.
  // Callers widen reach by rounding_bound() for the distance to the centres they inserted.
  // Four single-precision lanes per member (its record is 16 bytes: x, y, z, id), no branch per
  // member: about 17 instructions a member where the double-precision loop took 38 (GCC 12,
  // docs/benchmarks/README.md, "Session of 2026-12-01"); the ids that pass go to a block buffer
  // and fn is called for them after the block ("Session of 2026-12-03, fourth part"). The float arithmetic (the conversions
  // of from and P, the subtraction, P - |x|, the squares and their sum) errs by less than
  // 2^-21 S in the distance, S = max_abs + max|from| + max finite P + reach (2^-24 relative per
  // operation); the cut-off is widened by 1e-5 S, twenty times that.
  template <class Fn>
  [[gnu::always_inline]] void for_each_within(std::uint32_t cell, const Vec3& from, const Vec3& period, double reach,
                       Fn&& fn) const {
    walk<false>(cell, from, period, reach, Vec3::Constant(kInf), fn);
  }
  // The same, and besides only the members whose axis-aligned boxes overlap the caller's
  // (its body within from +- half) along every axis: the folded separation at most half + the
  // member's half, widened as the distance is (1e-5 S). For elongated or flat bodies, whose
  // boxes are thin across some axis where the bodies are aligned (ObbNeighbors::link). It reads
  // the members' half-extents beside their records (16 bytes more a member walked).
  template <class Fn>
  [[gnu::always_inline]] void for_each_within_box(std::uint32_t cell, const Vec3& from, const Vec3& period,
                                                  double reach, const Vec3& half, Fn&& fn) const {
    walk<true>(cell, from, period, reach, half, fn);
  }

  // A bound on |m.centre() - c| for every member inserted at centre c: sqrt(3) 2^-24 times the
  // largest coordinate inserted, doubled, plus 1e-44 (a coordinate below float's normal range
  // is rounded to within 2^-150 absolute).
  double rounding_bound() const {
    return 2.0 * 1.7320508075688772 * std::ldexp(max_abs_, -24) + 1e-44;
  }
  // x >= 0 rounded up to single precision (inf stays inf): float(x) rounds to nearest, within
  // half an ulp; one ulp more (the product by 1 + 2^-23 rounds to at least that) is above x.
  static float up(double x) {
    const float f = static_cast<float>(x);
    return double(f) >= x ? f : f * (1.0f + 0x1p-23f);
  }
  // std::nextafter(f, inf) for f >= +0 (not NaN), bit for bit and inline: the next float up is
  // the next bit pattern (+0 -> the least subnormal, the largest finite -> inf); inf stays inf.
  // libm's out-of-line call cost ~30 instructions a walk, one walk a cell visited (~2.5k
  // instructions a collision for superquadrics at phi = 0.256, ~1 %).
  static float next_up(float f) {
    if (!(f < std::numeric_limits<float>::infinity())) return f;
    return std::bit_cast<float>(std::bit_cast<std::uint32_t>(f) + 1u);
  }

 private:
  template <bool kBoxes, class Fn>
  [[gnu::always_inline]] void walk(std::uint32_t cell, const Vec3& from, const Vec3& period, double reach,
                                   const Vec3& half, Fn& fn) const {
    using F4 = float __attribute__((vector_size(16)));
    using I4 = std::int32_t __attribute__((vector_size(16)));
    static_assert(sizeof(Member) == sizeof(F4), "a member is one vector of four lanes");
    static_assert(sizeof(Half) == sizeof(F4), "a member's half-extents are one vector of four lanes");
    double scale = max_abs_ + from.cwiseAbs().maxCoeff() + reach, pmax = 0.0;
    for (int k = 0; k < 3; ++k)
      if (std::isfinite(period[k])) pmax = std::max(pmax, period[k]);
    const double r = reach + 1e-5 * (scale + pmax);
    const float r2 = next_up(static_cast<float>(r * r));
    const F4 f = {float(from[0]), float(from[1]), float(from[2]), 0.0f};
    const double slack = 1e-5 * (scale + pmax);  // the distance's widening, along each axis
    const F4 hq = {up(half[0] + slack), up(half[1] + slack), up(half[2] + slack), 0.0f};
    const F4 p = {float(period[0]), float(period[1]), float(period[2]), 0.0f};  // kInf: inf
    const I4 centre = {-1, -1, -1, 0};                               // the fourth lane is the id
    const I4 magnitude = {0x7fffffff, 0x7fffffff, 0x7fffffff, 0};  // |x|
    // In blocks: the ids within reach are written to a buffer without a branch (a third of a
    // large cell's members pass, at random: the branch per member was mispredicted often), then
    // fn is called for each, in the members' order.
    constexpr int kBlock = 64;
    std::uint32_t pass[kBlock];
    for (const Member *m = begin(cell), *e = end(cell); m != e;) {
      const Member* stop = e - m > kBlock ? m + kBlock : e;
      int n = 0;
      for (; m != stop; ++m) {
        F4 v;
        std::memcpy(&v, m, sizeof v);
        const F4 a = (F4)((I4)((F4)((I4)v & centre) - f) & magnitude);
        const F4 q = p - a;
        const F4 x = a < q ? a : q;
        const F4 x2 = x * x;
        pass[n] = m->id;
        if constexpr (kBoxes) {
          F4 hm;
          std::memcpy(&hm, &half_[std::size_t(m - data_.data())], sizeof hm);
          // apart along an axis (lane 3: 0 > 0, never); the three lanes or-ed into lane 0
          I4 apart = x > hq + hm;
          apart |= __builtin_shufflevector(apart, apart, 1, 2, 0, 3);
          apart |= __builtin_shufflevector(apart, apart, 2, 0, 1, 3);
          n += (x2[0] + x2[1] + x2[2] <= r2) & (apart[0] == 0);
        } else {
          n += x2[0] + x2[1] + x2[2] <= r2;
        }
      }
      for (int k = 0; k < n; ++k) fn(pass[k]);
    }
  }

  void grow() {
    const std::uint32_t cap = 2 * cap_;
    std::vector<Member> d(size_.size() * cap);
    std::vector<Half> h(size_.size() * cap);
    for (std::size_t c = 0; c < size_.size(); ++c) {
      std::copy_n(data_.begin() + c * cap_, size_[c], d.begin() + c * cap);
      std::copy_n(half_.begin() + c * cap_, size_[c], h.begin() + c * cap);
    }
    data_.swap(d);
    half_.swap(h);
    cap_ = cap;
  }
  std::uint32_t cap_ = 8;
  std::vector<Member> data_;
  std::vector<Half> half_;  // beside data_, slot for slot
  std::vector<std::uint32_t> size_;
  double max_abs_ = 0.0;
};

}  // namespace hb
