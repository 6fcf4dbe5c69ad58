// The bodies of each cell of a grid (a CellList's cells) as one packed array per cell of
// (centre in single precision, id), for a walk over a cell stencil that needs only the centres
// first (ObbNeighbors::link: the circumsphere test before the box test).
//
// Why: a CellList keeps its cells as linked lists through the bodies. A walk then chases one
// pointer per body, each load waiting for the one before, and reads each body's record for its
// centre: at N = 256000 ellipsoids that walk and those loads were 8-9 % of the run (perf; the
// rebuild of one box meets ~330 bodies in its 27 cells). Here a cell's members are 16 bytes
// each (and 16 more for their boxes), side by side: the walk reads a few lines per cell, all of
// them independent.
//
// Layout: a cell's members in blocks of four, each block one cache line of the four centres'
// x, then y, then z, then ids, followed by the block of their boxes' half-extents (an aligned
// pair of lines, fetched together; in two arrays they missed one by one at large N), so that
// the walk tests four members with each vector operation. Measured (callgrind, ellipsoids
// X0 = 2 at phi = 0.5, N = 256, where a rebuild walks every body: docs/benchmarks/README.md,
// "Session of 2026-12-07, seventh part"): the walk with boxes took 38 instructions a member
// with one member (x, y, z, id) a vector, 18 in blocks of four.
//
// Capacity: the same for every cell, twice the mean occupancy plus 8 rounded up to whole blocks
// (the grid should have at most one cell per body: capped_cell_width's max_per_body = 1),
// doubled for all cells at once on the rare overflow (no allocation per event, as
// AdjacencyLists). A removal moves the cell's last member into the hole, so the order within a
// cell depends on the history: callers must not depend on it (ObbNeighbors' lists are sorted).
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
  // A member as inserted (its centre in single precision and its id), for reading one back.
  struct Member {
    float x, y, z;
    std::uint32_t id;
    Vec3 centre() const { return Vec3(x, y, z); }
  };

  // Half-extents of the axis-aligned box around a member's body (single precision, rounded
  // up; inf: none given), kept beside the members (same slots) and read only by the walk with
  // boxes (for_each_within_box).
  struct Half {
    float x, y, z;
    Vec3 value() const { return Vec3(x, y, z); }
  };

  void init(std::size_t n_cells, std::size_t n_bodies) {
    const double mean = n_cells > 0 ? double(n_bodies) / double(n_cells) : 0.0;
    cap_ = whole_blocks(static_cast<std::uint32_t>(std::ceil(2.0 * mean)) + 8);
    data_.assign(n_cells * (cap_ / kLanes), Pair{});
    size_.assign(n_cells, 0);
    max_abs_ = 0.0;
  }
  std::uint32_t size(std::uint32_t cell) const { return size_[cell]; }
  // A hint: a cell's size and its first `blocks` blocks of four members (with their boxes'
  // blocks, `boxes`; at most the cell's capacity), ahead of a walk. always_inline: a const
  // function of prefetches alone is found pure by GCC and its calls deleted
  // (system/simulation.hpp, prefetch_neighbors).
  [[gnu::always_inline]] void prefetch(std::uint32_t cell, int blocks, bool boxes) const {
    __builtin_prefetch(&size_[cell]);
    const Pair* p = first_pair(cell);
    blocks = std::min(blocks, int(cap_ / kLanes));
    for (int k = 0; k < blocks; ++k) {
      __builtin_prefetch(&p[k].m);
      if (boxes) __builtin_prefetch(&p[k].h);
    }
  }
  // Member k < size(cell) of a cell, and its box's half-extents.
  Member member(std::uint32_t cell, std::uint32_t k) const {
    const Block& b = pair(cell, k).m;
    const std::uint32_t l = k % kLanes;
    return Member{b.x[l], b.y[l], b.z[l], b.id[l]};
  }
  Half half(std::uint32_t cell, std::uint32_t k) const {
    const Block& b = pair(cell, k).h;
    const std::uint32_t l = k % kLanes;
    return Half{b.x[l], b.y[l], b.z[l]};
  }

  // A member at centre c whose body lies within the axis-aligned box c +- half (default: none,
  // the box test passes it).
  void insert(std::uint32_t cell, std::uint32_t id, const Vec3& c,
              const Vec3& half = Vec3::Constant(kInf)) {
    if (size_[cell] == cap_) grow();
    max_abs_ = std::max(max_abs_, c.cwiseAbs().maxCoeff());
    const std::uint32_t k = size_[cell]++;
    put(cell, k, Member{float(c.x()), float(c.y()), float(c.z()), id},
        Half{up(half.x()), up(half.y()), up(half.z())});
  }
  void remove(std::uint32_t cell, std::uint32_t id) {
    const std::uint32_t n = size_[cell];
    const Pair* b = first_pair(cell);
    std::uint32_t k = 0;
    while (k < n && b[k / kLanes].m.id[k % kLanes] != id) ++k;
    if (k == n) throw std::logic_error("cell members: body not in its cell");
    put(cell, k, member(cell, n - 1), half(cell, n - 1));
    --size_[cell];
  }
  // Calls fn(id) for the members of `cell` whose centres are within `reach` of `from`, the
  // separation taken along each axis k as |x| folded once, min(|x|, P_k - |x|) (the nearest image
  // for |x| < P_k; P_k = kInf: no period). Conservative: every member whose stored centre
  // (member(cell, k).centre(), in double precision) is within reach is reported, with some
  // slightly beyond. Callers widen reach by rounding_bound() for the distance to the centres
  // they inserted. Four members a vector (a block), no branch per member; the ids that pass go
  // to a buffer and fn is called for them after every 16 blocks, in the members' order
  // ("Session of 2026-12-03, fourth part"). The float arithmetic (the conversions of from and P,
  // the subtraction, P - |x|, the squares and their sum) errs by less than 2^-21 S in the
  // distance, S = max_abs + max|from| + max finite P + reach (2^-24 relative per operation);
  // the cut-off is widened by 1e-5 S, twenty times that.
  template <class Fn>
  [[gnu::always_inline]] void for_each_within(std::uint32_t cell, const Vec3& from, const Vec3& period, double reach,
                       Fn&& fn) const {
    walk<false>(cell, from, period, reach, Vec3::Constant(kInf), fn);
  }
  // The same, and besides only the members whose axis-aligned boxes overlap the caller's
  // (its body within from +- half) along every axis: the folded separation at most half + the
  // member's half, widened as the distance is (1e-5 S). For elongated or flat bodies, whose
  // boxes are thin across some axis where the bodies are aligned (ObbNeighbors::link). It reads
  // the members' half-extents beside their records (a block of 64 bytes more each four members).
  template <class Fn>
  [[gnu::always_inline]] void for_each_within_box(std::uint32_t cell, const Vec3& from, const Vec3& period,
                                                  double reach, const Vec3& half, Fn&& fn) const {
    walk<true>(cell, from, period, reach, half, fn);
  }

  // A bound on |member.centre() - c| for every member inserted at centre c: sqrt(3) 2^-24 times
  // the largest coordinate inserted, doubled, plus 1e-44 (a coordinate below float's normal
  // range is rounded to within 2^-150 absolute).
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
  static constexpr std::uint32_t kLanes = 4;
  // Four members: their x, y, z and ids (the half-extents' blocks leave the ids unused), one
  // cache line.
  struct alignas(64) Block {
    float x[kLanes] = {}, y[kLanes] = {}, z[kLanes] = {};
    std::uint32_t id[kLanes] = {};
  };
  static std::uint32_t whole_blocks(std::uint32_t n) { return (n + kLanes - 1) / kLanes * kLanes; }
  // A block of members and the block of their boxes' half-extents, side by side: the two lines
  // of an aligned pair, which the hardware fetches together (at large N the walk with boxes
  // missed each of them on its own when they lay in two arrays).
  struct alignas(128) Pair {
    Block m, h;
  };
  const Pair& pair(std::uint32_t cell, std::uint32_t k) const {
    return data_[(std::size_t(cell) * cap_ + k) / kLanes];
  }
  const Pair* first_pair(std::uint32_t cell) const {  // a cell's first block pair
    return data_.data() + std::size_t(cell) * (cap_ / kLanes);
  }
  void put(std::uint32_t cell, std::uint32_t k, const Member& m, const Half& h) {
    const std::size_t at = std::size_t(cell) * cap_ + k;
    const std::uint32_t l = k % kLanes;
    Block& b = data_[at / kLanes].m;
    b.x[l] = m.x, b.y[l] = m.y, b.z[l] = m.z, b.id[l] = m.id;
    Block& c = data_[at / kLanes].h;
    c.x[l] = h.x, c.y[l] = h.y, c.z[l] = h.z;
  }

  template <bool kBoxes, class Fn>
  [[gnu::always_inline]] void walk(std::uint32_t cell, const Vec3& from, const Vec3& period, double reach,
                                   const Vec3& half, Fn& fn) const {
    using F4 = float __attribute__((vector_size(16)));
    using I4 = std::int32_t __attribute__((vector_size(16)));
    static_assert(sizeof(Block) == 4 * sizeof(F4), "a block is four vectors of four lanes");
    double scale = max_abs_ + from.cwiseAbs().maxCoeff() + reach, pmax = 0.0;
    for (int k = 0; k < 3; ++k)
      if (std::isfinite(period[k])) pmax = std::max(pmax, period[k]);
    const double r = reach + 1e-5 * (scale + pmax);
    const float r2f = next_up(static_cast<float>(r * r));
    const double slack = 1e-5 * (scale + pmax);  // the distance's widening, along each axis
    auto splat = [](float v) { return F4{v, v, v, v}; };
    // per axis: the query's coordinate, period (kInf: inf) and half-extent
    const F4 f[3] = {splat(float(from[0])), splat(float(from[1])), splat(float(from[2]))};
    const F4 p[3] = {splat(float(period[0])), splat(float(period[1])), splat(float(period[2]))};
    const F4 hq[3] = {splat(up(half[0] + slack)), splat(up(half[1] + slack)), splat(up(half[2] + slack))};
    const F4 r2 = splat(r2f);
    const I4 magnitude = {0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff};  // |x|
    const I4 lane = {0, 1, 2, 3};
    // In blocks: the ids within reach are written to a buffer without a branch (a third of a
    // large cell's members pass, at random: the branch per member was mispredicted often), then
    // fn is called for each, in the members' order.
    constexpr std::uint32_t kBuffer = 64;
    std::uint32_t pass[kBuffer];
    const Pair* pb = first_pair(cell);
    const std::uint32_t n = size_[cell];
    for (std::uint32_t k = 0; k < n;) {
      const std::uint32_t stop = std::min(n, k + kBuffer);
      int m = 0;
      for (; k < stop; k += kLanes, ++pb) {
        const Block* b = &pb->m;
        const Block* hb = &pb->h;
        F4 x[3], v;
        for (int a = 0; a < 3; ++a) {
          std::memcpy(&v, a == 0 ? b->x : a == 1 ? b->y : b->z, sizeof v);
          const F4 d = (F4)((I4)(v - f[a]) & magnitude);
          const F4 q = p[a] - d;
          x[a] = d < q ? d : q;
        }
        I4 in = (x[0] * x[0] + x[1] * x[1]) + x[2] * x[2] <= r2;
        if constexpr (kBoxes) {
          for (int a = 0; a < 3; ++a) {
            std::memcpy(&v, a == 0 ? hb->x : a == 1 ? hb->y : hb->z, sizeof v);
            in &= ~(I4)(x[a] > hq[a] + v);  // apart along axis a
          }
        }
        in &= lane < (I4){int(n - k), int(n - k), int(n - k), int(n - k)};  // the block's members
        I4 id;
        std::memcpy(&id, b->id, sizeof id);
        for (std::uint32_t l = 0; l < kLanes; ++l) {
          pass[m] = std::uint32_t(id[l]);
          m -= in[l];  // in: 0 or -1
        }
      }
      for (int j = 0; j < m; ++j) fn(pass[j]);
    }
  }

  void grow() {
    const std::uint32_t cap = 2 * cap_;
    std::vector<Pair> d(size_.size() * (cap / kLanes));
    for (std::size_t c = 0; c < size_.size(); ++c) {
      const std::size_t blocks = (size_[c] + kLanes - 1) / kLanes;
      std::copy_n(data_.begin() + c * (cap_ / kLanes), blocks, d.begin() + c * (cap / kLanes));
    }
    data_.swap(d);
    cap_ = cap;
  }
  std::uint32_t cap_ = kLanes;  // a multiple of kLanes
  std::vector<Pair> data_;  // a cell's blocks of members with their boxes
  std::vector<std::uint32_t> size_;
  double max_abs_ = 0.0;
};

}  // namespace hb
