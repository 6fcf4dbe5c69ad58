// A dedicated event loop for identical smooth hard spheres in a periodic box (issue 15): the
// fast path of the most common benchmark, beside the generic Simulation<HardSpheres, ...>
// (system/simulation.hpp), which stays its slow twin (tests/system/test_sphere_engine.cpp: the
// same collisions, in the same order, at the same times).
//
// What it does differently from the generic loop (the ideas of the fastest public hard-sphere
// codes; the code is our own):
//  * One compact 64-byte record per sphere (position, own clock, velocity, event counter, input
//    number): the loads of a prediction touch one cache line per candidate.
//  * The records are kept in the order of a space-filling curve (Morton order of the cage
//    centres' cells), re-sorted every few N events: neighbours sit close in memory, so a
//    prediction's loads mostly hit the cache at large N.  Steps and states speak of the spheres'
//    input numbers.
//  * Cages instead of cell crossings.  Each sphere i owns a cage, the ball of radius s/2 about
//    its cage centre c_i (its position when the cage was made), and a neighbour list holding
//    every j with |c_i - c_j| < sigma + s (minimum image), kept symmetric.  While both spheres
//    are in their cages, |x_i - x_j| >= |c_i - c_j| - s, so spheres that are not listed
//    cannot touch: every contact is between listed pairs.  The only bookkeeping event is a
//    sphere leaving its cage (closed form, below); it then takes a new cage at its position,
//    leaves its old neighbours' lists and joins those of its new ones (found through a grid of
//    cage centres with cells of side >= sigma + s; a centre changes cell only there, so there
//    are no cell-crossing events).  Each cell is a block of slots of one size for all cells
//    (8 to start with; one more whenever a cell overflows), read as an array.
//  * Periodic images only for spheres whose cage centre lies near a face (predict, below).
//  * Early rejection before any square root.  For an approaching pair (b = r.v < 0) outside
//    contact (c = r^2 - sigma^2 >= 0) the first root t = c / (sqrt(b^2 - a c) - b) satisfies
//    t >= c / (-2 b) (sqrt(b^2 - a c) <= -b), so a pair with c >= -2 b t_best cannot beat the
//    best time found so far and is dropped without the square root.
//  * One event per sphere (its earliest collision or its cage exit) in a bucketed calendar
//    (events/calendar.hpp): only the events of the current bucket are sorted, in a small heap;
//    later ones are inserted and removed in O(1).  Its width starts at 6 mean event times / N
//    and adapts.
//  A collision event carries the partner's event counter at prediction; if the partner has
//  changed velocity since, the event is stale and the owner is predicted again (as in the
//  generic loop).
//  * A pair is not taken by i if its time comes after the partner's own event: j is predicted
//    again at its event (whatever its kind: a collision, a cage exit or a stale end), and that
//    prediction reads i (the lists are symmetric) and finds the pair, if it is still to come,
//    no later than it happens.  So every future collision stays held by one side whose event
//    comes no later (initially every slot is at infinity, so nothing is skipped), and i's event
//    is not spent on a pair that j's earlier event will most likely make stale.  Stale events
//    fell from 0.35 to 0.13 a collision (N = 4000, phi = 0.45): -6 % time at N = 4000, -3 % at
//    32000, -5 % at 256000; at 10^6 it costs a calendar line a neighbour, asked for with its
//    record, and gains nothing (docs/benchmarks/README.md, 2026-12-07, fourth part).
//
// Cage exit: with p = x_i - c_i (minimum image), |p + v tau| = s / 2 first at
//     tau = (-b + sqrt(b^2 - a c)) / a,   a = v.v, b = p.v, c = p.p - s^2 / 4 <= 0,
// written as tau = -c / (b + sqrt(b^2 - a c)) when b > 0 (no cancellation).
// Collision: collide_spheres (collision/sphere.hpp) with equal masses.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "collision/sphere.hpp"
#include "core/box.hpp"
#include "core/state.hpp"
#include "events/calendar.hpp"
#include "math/morton.hpp"
#include "math/types.hpp"

namespace hb {

class SphereEngine {
 public:
  static constexpr int kMaxNeighbours = 24;  // per sphere (memory: 4 bytes each)
  static constexpr std::uint32_t kCage = 0xffffffffu;  // partner of a cage-exit event

  enum class Kind { collision, cage, stale };
  struct Step {
    Kind kind = Kind::stale;
    std::uint32_t i = 0, j = 0;
    double time = 0.0;
  };

  // Spheres of diameter sigma at the state's positions and velocities (all at s.t[i]); shell s:
  // the cage diameter (neighbour lists reach sigma + s).  cell_capacity: the cage-centre slots
  // per grid cell to start with (they grow by one whenever a cell overflows; tests start at 1).
  SphereEngine(const Box& box, const State& s, double sigma, double shell, double now = 0.0,
               std::uint32_t cell_capacity = 8)
      : L_(box.L), hL_(0.5 * box.L), sigma_(sigma), shell_(shell),
        inner_(sigma + 2.0 * shell < 0.5 * box.L.minCoeff() ? sigma + 2.0 * shell : kInf),
        now_(now),
        cap_(std::max<std::uint32_t>(1, cell_capacity)) {
    if (!box.fully_periodic()) throw std::invalid_argument("SphereEngine: the box must be periodic");
    if (!(shell > 0.0)) throw std::invalid_argument("SphereEngine: the shell must be positive");
    // A cage centre is the float nearest the sphere's position: within sqrt(3) ulp(L) / 2 of it.
    // The cage's radius s / 2 must dwarf that (else a new cage could already be left).
    const double far = std::ldexp(std::sqrt(3.0) / 2.0, std::ilogb(box.L.maxCoeff()) - 23);
    if (!(0.5 * shell > 128.0 * far))
      throw std::invalid_argument("SphereEngine: the shell is too thin for this box (cage centres "
                                  "are single precision; it must exceed " +
                                  std::to_string(256.0 * far) + ")");
    const std::size_t n = s.size();
    if (n == 0) throw std::invalid_argument("SphereEngine: no spheres");
    p_.resize(n);
    cage_.resize(n);
    nb_.assign(n * kMaxNeighbours, 0);
    for (std::size_t i = 0; i < n; ++i) {
      Sph& q = p_[i];
      const Vec3 r = s.position_at(i, now);
      q.x = wrap(r.x(), 0), q.y = wrap(r.y(), 1), q.z = wrap(r.z(), 2);
      q.t = now;
      q.vx = s.v[i].x(), q.vy = s.v[i].y(), q.vz = s.v[i].z();
      q.id = static_cast<std::uint32_t>(i);
      q.count = 0;
      q.nn = 0;
    }
    for (int k = 0; k < 3; ++k) {
      ncell_[k] = std::max(1, static_cast<int>(std::floor(L_[k] / (sigma + shell))));
      if (ncell_[k] < 3)
        throw std::invalid_argument("SphereEngine: the box is smaller than 3 cells of sigma + shell");
      cell_len_[k] = L_[k] / ncell_[k];
    }
    for (std::uint32_t i = 0; i < n; ++i) cage_[i] = Cage(p_[i]);
    rebuild_cells();
    for (std::uint32_t i = 0; i < n; ++i) fill_list(i, /*only_higher=*/true);
    const std::uint32_t lists = std::max<std::uint32_t>(16, std::uint32_t(n / 4));  // 2 B/sphere
    q_.reset(static_cast<std::uint32_t>(n), 1.0, lists, now);
    for (std::uint32_t i = 0; i < n; ++i) predict(i);
    q_.tune_width(now);  // buckets of about Calendar::kPerBucket events
    reorder_every_ = 16 * std::uint64_t(n);
    reorder();
    const std::size_t bytes = bytes_per_sphere() * n;
    prefetch_ = bytes > l2_bytes();
    prefetch_far_ = bytes > kFarBytes;
  }

  // Ask for the data of coming events and of neighbours ahead of their use (memory prefetches;
  // they change no result).  By default on when the engine's arrays outgrow the L2 cache: below
  // that everything is at hand and the prefetch instructions only cost (measured at N = 4000,
  // 840 kB against 1 MiB of L2: 2.9 % faster without; at N = 32000 they pay; figures in
  // docs/benchmarks/README.md).
  // Beyond kFarBytes the engine also asks, one event ahead, for the records the next event's
  // prediction will read (N = 256000 and 10^6: -4.5 % and -5.7 %; at N = 32000, 6.7 MB, it
  // cost 2 %: there those records come from the L3 quickly).  set_prefetch sets both levels.
  static constexpr std::size_t kFarBytes = std::size_t(32) << 20;

  // The cage diameter to use for n spheres of diameter sigma at packing fraction phi: the one
  // that ran fastest at phi = 0.45, capped so that a sphere lists at most about 16.5 others on
  // average (rho 4 pi (sigma + s)^3 / 3 <= 16.5, rho = 6 phi / (pi sigma^3); the lists hold
  // kMaxNeighbours = 24, and a cage of 0.8 sigma, 21 on average, overflowed them at 0.45).
  // A bigger cage means fewer cage exits (each scans 27 grid cells and edits about 25 lists)
  // but longer lists for every prediction.  While the arrays stay below kFarBytes (n <
  // kFarSpheres) an exit's loads hit the caches and 0.5 sigma is fastest (N = 4000:
  // 0.6 costs 1 %, 0.7 1 %; N = 32000: 0.6 0.4 %, 0.65 6 %).  Beyond, an exit's loads miss:
  // N = 256000: 0.6 is 3 % faster than 0.5 (0.65 0 %); N = 10^6: 0.6 -8 %, 0.65 -12 % (alternating
  // runs, docs/benchmarks/README.md, session of 2026-12-07, third part).
  static constexpr std::size_t kFarSpheres = 160000;  // ~kFarBytes at ~210 bytes a sphere
  static double default_shell(std::size_t n, double phi, double sigma = 1.0) {
    const double s = n < kFarSpheres ? 0.5 : n < 4 * kFarSpheres ? 0.6 : 0.65;
    if (!(phi > 0.0)) return s * sigma;
    // (sigma + s)^3 <= 16.5 sigma^3 / (8 phi)
    const double cap = std::cbrt(16.5 / (8.0 * phi)) - 1.0;
    return std::min(s, cap) * sigma;
  }
  void set_prefetch(bool on) { prefetch_ = prefetch_far_ = on; }
  bool prefetch() const { return prefetch_; }

  // Re-sort the records along the curve every `events` events (0: never; default 16 N).
  void set_reorder_interval(std::uint64_t events) {
    reorder_every_ = events;
    next_reorder_ = events == 0 ? ~std::uint64_t(0) : events_ + events;
  }

  double now() const { return now_; }
  std::uint64_t collisions() const { return collisions_; }
  std::uint64_t cage_exits() const { return cages_; }
  std::uint64_t stale_events() const { return stale_; }
  // Cage-centre slots per grid cell now, and how often a cell overflowed during the run.
  std::uint32_t cell_capacity() const { return cap_; }
  std::uint64_t cell_growths() const { return growths_; }
  std::size_t size() const { return p_.size(); }

  // Process the next event.
  Step step() {
    if (events_ >= next_reorder_) reorder();
    ++events_;
    const std::uint32_t i = q_.top();
    const std::uint32_t partner = q_.tag_of(i), partner_count = q_.stamp_of(i);
    if (!(q_.time_of(i) < kInf))
      throw std::runtime_error("SphereEngine: no event ahead (every sphere is at rest)");
    now_ = q_.time_of(i);
    Step out;
    out.i = p_[i].id;
    out.time = now_;
    if (partner == kCage) {
      advance(i);
      new_cage(i);
      ++cages_;
      out.kind = Kind::cage;
      predict(i);
      prefetch_next();
      return out;
    }
    const std::uint32_t j = partner;
    out.j = p_[j].id;
    if (p_[j].count != partner_count) {
      ++stale_;
      predict(i);
      prefetch_next();
      return out;
    }
    advance(i);
    advance(j);
    collide(i, j);
    ++collisions_;
    out.kind = Kind::collision;
    // j's neighbours are asked for while i is predicted (N = 10^6: -6 %; asking for the
    // partner's list one event ahead, or for all three lines of each list, made it 20-30 %
    // slower, measured the same way: docs/benchmarks/README.md)
    if (prefetch_) prefetch_neighbours(j);
    predict(i);
    predict(j);
    prefetch_next();
    return out;
  }

  // The spheres' state at the current time (positions wrapped into the box).
  State state() const {
    State s;
    s.resize(p_.size());
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const Sph& q = p_[i];
      const double dt = now_ - q.t;
      s.r[q.id] = Vec3(wrap(q.x + q.vx * dt, 0), wrap(q.y + q.vy * dt, 1), wrap(q.z + q.vz * dt, 2));
      s.v[q.id] = Vec3(q.vx, q.vy, q.vz);
      s.t[q.id] = now_;
    }
    return s;
  }

  // Bytes held per sphere (every array, the cell heads and the calendar included).
  std::size_t bytes_per_sphere() const {
    const std::size_t b = p_.capacity() * sizeof(Sph) + cage_.capacity() * sizeof(Cage) +
                          nb_.capacity() * sizeof(std::uint32_t) +
                          q_.bytes() + slot_.capacity() * sizeof(std::uint32_t) + used_.capacity() +
                          cand_.capacity() * sizeof(std::uint32_t);
    return p_.empty() ? 0 : (b + p_.size() - 1) / p_.size();
  }

 private:
  struct alignas(64) Sph {
    double x, y, z, t;     // position at the own clock t
    double vx, vy, vz;
    std::uint32_t id;          // the sphere's input number
    std::uint32_t count : 24;  // velocity changes so far, modulo 2^24 (see below)
    std::uint32_t nn : 8;      // neighbours listed
  };
  static_assert(kMaxNeighbours < 256, "nn has 8 bits");
  // A cage centre, in single precision (12 bytes instead of 24).  The centre is whatever the
  // float holds: the cage exit and the lists are both computed from that same point, so the
  // guarantee (unlisted pairs cannot touch) is exact as before; the sphere starts within a
  // float's rounding of its centre (7e-6 at L = 100), far inside its cage (the constructor
  // checks that the shell is at least 256 times that).
  struct Cage {
    float x = 0.0f, y = 0.0f, z = 0.0f;
    Cage() = default;
    explicit Cage(const Sph& q)
        : x(static_cast<float>(q.x)), y(static_cast<float>(q.y)), z(static_cast<float>(q.z)) {}
    double operator[](int k) const { return k == 0 ? x : k == 1 ? y : z; }
  };
  // Sphere i's event is its time in the calendar, with the partner (kCage for a cage exit) as its
  // tag and the partner's count at prediction as its stamp; it is stale once the partner's count
  // moved on (a wrap of 2^24 velocity changes of the partner within one event's lifetime is out
  // of reach: an event lives shorter than the owner's cage exit).

  // Positions move less than a cage between wraps, separations are between spheres in the box.
  double wrap(double x, int k) const { return wrap_once(x, L_[k]); }
  double image(double d, int k) const { return image_once(d, L_[k], hL_[k]); }
  // Cell index along axis k of a coordinate in [0, L) (the last cell takes x = L by rounding).
  int axis_cell(double x, int k) const {
    return std::min(ncell_[k] - 1, static_cast<int>(x / cell_len_[k]));
  }
  // Grid cell c's slots (used_[c] of them in use).
  std::uint32_t* slots_of(std::uint32_t c) { return &slot_[std::size_t(c) * cap_]; }
  std::uint32_t cell_of(const Cage& c) const {
    int idx[3];
    for (int k = 0; k < 3; ++k) idx[k] = axis_cell(c[k], k);
    return std::uint32_t((idx[2] * ncell_[1] + idx[1]) * ncell_[0] + idx[0]);
  }

  // Ask for the records of the next event, and of the two the calendar puts after it, while this
  // step's work is retiring (they miss at large N).  The partners are the calendar's tags, held
  // in its heap: no load waits on a miss here.
  void prefetch_next() {
    if (!prefetch_) return;
    q_.prefetch_ahead();
    const std::uint32_t i = q_.top();
    prefetch_event(i, q_.top_tag());
    if (prefetch_far_) prefetch_neighbours(i);  // the records its prediction will read
    std::uint32_t slot[2], tag[2];
    const int m = q_.next_after_top(slot, tag);
    for (int k = 0; k < m; ++k) prefetch_event(slot[k], tag[k]);
  }
  void prefetch_event(std::uint32_t i, std::uint32_t partner) {
    __builtin_prefetch(&p_[i]);
    __builtin_prefetch(&cage_[i]);
    __builtin_prefetch(&nb_[std::size_t(i) * kMaxNeighbours]);
    if (partner != kCage) __builtin_prefetch(&p_[partner]);
  }

  // The records of i's listed neighbours (a prediction of i reads them all).
  void prefetch_neighbours(std::uint32_t i) const {
    const std::uint32_t* l = &nb_[std::size_t(i) * kMaxNeighbours];
    for (std::uint32_t k = 0, nn = p_[i].nn; k < nn; ++k) __builtin_prefetch(&p_[l[k]]);
  }

  void advance(std::uint32_t i) {
    Sph& q = p_[i];
    const double dt = now_ - q.t;
    q.x = wrap(q.x + q.vx * dt, 0);
    q.y = wrap(q.y + q.vy * dt, 1);
    q.z = wrap(q.z + q.vz * dt, 2);
    q.t = now_;
  }

  // List every j whose cage centre is within sigma + s of i's (both ways); with only_higher,
  // only j > i (the initial fill, which visits every pair once).  The 27 cells' slots are read
  // as arrays (no chain of dependent loads) and the candidates kept without a branch (about one
  // in seven is kept, at random); the lists are written after the scan.
  // At large N (prefetch_) in three passes: the 27 cells' slots and counts are asked for, then
  // the slots gathered and their cage centres asked for, then the centres tested.  One pass
  // waited for each cell's slots and then for each candidate's centre in turn (at N = 10^6 those
  // two loads were 64 % of new_cage, a third of the run); the passes let the misses overlap.
  // Below the L2 (no prefetch) the one pass stays: there the gathering costs 3 % of a run.  The
  // candidates are the same, in the same order, either way.
  void fill_list(std::uint32_t i, bool only_higher) {
    const Cage ci = cage_[i];
    const double reach2 = (sigma_ + shell_) * (sigma_ + shell_);
    // the three wrapped cell indices along each axis (no division in the loop)
    int around[3][3];
    for (int k = 0; k < 3; ++k) {
      const int c = axis_cell(ci[k], k);
      around[k][0] = c == 0 ? ncell_[k] - 1 : c - 1;
      around[k][1] = c;
      around[k][2] = c == ncell_[k] - 1 ? 0 : c + 1;
    }
    std::uint32_t cells[27];
    int nc = 0;
    for (int dz = 0; dz < 3; ++dz)
      for (int dy = 0; dy < 3; ++dy) {
        const int row = (around[2][dz] * ncell_[1] + around[1][dy]) * ncell_[0];
        for (int dx = 0; dx < 3; ++dx) cells[nc++] = std::uint32_t(row + around[0][dx]);
      }
    std::uint32_t found[kMaxNeighbours + 1];
    std::uint32_t m = 0;
    auto consider = [&](std::uint32_t j) {
      const Cage& cj = cage_[j];
      const double ex = image(double(cj.x) - ci.x, 0), ey = image(double(cj.y) - ci.y, 1),
                   ez = image(double(cj.z) - ci.z, 2);
      const bool take = (ex * ex + ey * ey + ez * ez < reach2) & (j != i) &
                        (!only_higher | (j > i));
      found[m < kMaxNeighbours ? m : kMaxNeighbours] = j;
      m += take;
    };
    if (!prefetch_) {
      for (int c = 0; c < 27; ++c) {
        const std::uint32_t* cell = slots_of(cells[c]);
        const std::uint32_t used = used_[cells[c]];
        for (std::uint32_t q = 0; q < used; ++q) consider(cell[q]);
      }
    } else {
      for (int c = 0; c < 27; ++c) {
        const std::uint32_t* cell = slots_of(cells[c]);
        __builtin_prefetch(&used_[cells[c]]);
        __builtin_prefetch(cell);
        __builtin_prefetch(cell + cap_ - 1);
      }
      std::uint32_t* cand = cand_.data();  // 27 cap_ entries
      std::uint32_t n = 0;
      for (int c = 0; c < 27; ++c) {
        const std::uint32_t* cell = slots_of(cells[c]);
        const std::uint32_t used = used_[cells[c]];
        for (std::uint32_t q = 0; q < used; ++q) cand[n++] = cell[q];
      }
      for (std::uint32_t k = 0; k < n; ++k) __builtin_prefetch(&cage_[cand[k]]);
      for (std::uint32_t k = 0; k < n; ++k) consider(cand[k]);
    }
    if (m > kMaxNeighbours) push_overflow(i);
    for (std::uint32_t k = 0; k < m; ++k) {
      push(i, found[k]);
      push(found[k], i);
    }
  }

  // The L2 cache of this machine (1 MiB when the system does not say).
  static std::size_t l2_bytes() {
    const long b = sysconf(_SC_LEVEL2_CACHE_SIZE);
    return b > 0 ? std::size_t(b) : std::size_t(1) << 20;
  }

  [[noreturn]] void push_overflow(std::uint32_t i) const {
    throw std::runtime_error("SphereEngine: more than " + std::to_string(kMaxNeighbours) +
                             " neighbours of sphere " + std::to_string(p_[i].id) +
                             "; use a smaller shell");
  }
  void push(std::uint32_t i, std::uint32_t j) {
    const std::uint32_t nn = p_[i].nn;
    if (nn == kMaxNeighbours) push_overflow(i);
    nb_[std::size_t(i) * kMaxNeighbours + nn] = j;
    p_[i].nn = nn + 1;
  }
  // i from j's list.  The search compares all kMaxNeighbours slots, four at a time (a fixed
  // count, with no loop exit to mispredict), and keeps the listed ones; i is listed (the lists
  // are symmetric).  Written with vector types because the compiler left the plain loop scalar
  // (24 compares, 4.5 % of a run at N = 4000): a shift by k differs per lane, which SSE cannot do.
  using Lanes = std::uint32_t __attribute__((vector_size(16)));
  static_assert(kMaxNeighbours % 4 == 0, "the lists are read four slots at a time");
  static constexpr std::array<std::uint32_t, kMaxNeighbours> kSlotBit = [] {
    std::array<std::uint32_t, kMaxNeighbours> b{};
    for (int k = 0; k < kMaxNeighbours; ++k) b[k] = std::uint32_t(1) << k;
    return b;
  }();
  void remove(std::uint32_t j, std::uint32_t i) {
    std::uint32_t* l = &nb_[std::size_t(j) * kMaxNeighbours];
    const std::uint32_t nn = p_[j].nn;
    const Lanes key = {i, i, i, i};
    Lanes hit = {0, 0, 0, 0};
    for (int k = 0; k < kMaxNeighbours; k += 4) {
      Lanes slots, bits;
      std::memcpy(&slots, l + k, sizeof slots);
      std::memcpy(&bits, kSlotBit.data() + k, sizeof bits);
      hit |= static_cast<Lanes>(slots == key) & bits;
    }
    std::uint32_t found = hit[0] | hit[1] | hit[2] | hit[3];
    found &= (std::uint32_t(1) << nn) - 1;
    if (found == 0) return;
    const int k = __builtin_ctz(found);
    l[k] = l[nn - 1];
    p_[j].nn = nn - 1;
  }

  // Sphere i (advanced to now) takes a new cage at its position.
  void new_cage(std::uint32_t i) {
    const std::uint32_t* l = &nb_[std::size_t(i) * kMaxNeighbours];
    const std::uint32_t nn = p_[i].nn;
    if (prefetch_)
      for (std::uint32_t k = 0; k < nn; ++k) {  // the lists and counts about to be edited
        __builtin_prefetch(&nb_[std::size_t(l[k]) * kMaxNeighbours]);
        __builtin_prefetch(&p_[l[k]]);
      }
    for (std::uint32_t k = 0; k < nn; ++k) remove(l[k], i);
    p_[i].nn = 0;
    const std::uint32_t c_old = cell_of(cage_[i]);
    cage_[i] = Cage(p_[i]);
    const std::uint32_t c_new = cell_of(cage_[i]);
    if (c_new != c_old) {
      erase_cell(c_old, i);
      insert_cell(c_new, i);
    }
    fill_list(i, false);
  }

  void erase_cell(std::uint32_t c, std::uint32_t i) {  // i is in cell c
    std::uint32_t* cell = slots_of(c);
    const std::uint32_t nc = used_[c];
    std::uint32_t q = 0;
    while (cell[q] != i) ++q;
    cell[q] = cell[nc - 1];
    used_[c] = std::uint8_t(nc - 1);
  }
  void insert_cell(std::uint32_t c, std::uint32_t i) {
    if (used_[c] == cap_) {  // a crowded cell: one more slot in every cell
      ++growths_;
      grow_cells();
      rebuild_cells();
      return;  // the rebuild placed i (its new centre is set)
    }
    slot_[std::size_t(c) * cap_ + used_[c]] = i;
    used_[c] = std::uint8_t(used_[c] + 1);
  }
  // Every cell from the cage centres, each in increasing record order.
  void rebuild_cells() {
    const std::uint32_t n = static_cast<std::uint32_t>(p_.size());
    const std::size_t cells = std::size_t(ncell_[0]) * ncell_[1] * ncell_[2];
    for (;;) {
      slot_.assign(cells * cap_, 0);
      cand_.resize(27 * std::size_t(cap_));
      used_.assign(cells, 0);
      bool fits = true;
      for (std::uint32_t k = 0; k < n && fits; ++k) {
        const std::uint32_t c = cell_of(cage_[k]);
        if (used_[c] == cap_) fits = false;
        else slot_[std::size_t(c) * cap_ + used_[c]++] = k;
      }
      if (fits) return;
      grow_cells();
    }
  }
  void grow_cells() {
    if (cap_ == 255)  // used_ counts in 8 bits
      throw std::runtime_error("SphereEngine: more than 255 cage centres in a grid cell");
    ++cap_;
  }

  // Put the records in Morton order of their cage centres' cells and renumber everything that
  // names a record: lists, events, the calendar's slots and the cell lists.
  void reorder() {
    const std::uint32_t n = static_cast<std::uint32_t>(p_.size());
    next_reorder_ = reorder_every_ == 0 ? ~std::uint64_t(0) : events_ + reorder_every_;
    std::vector<std::uint64_t> key(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      std::uint32_t idx[3];
      for (int k = 0; k < 3; ++k)
        idx[k] = std::uint32_t(axis_cell(cage_[i][k], k));
      key[i] = morton_code(idx[0], idx[1], idx[2]);
    }
    const std::vector<std::uint32_t> perm = sorting_permutation(key);
    std::vector<std::uint32_t> inv(n);
    for (std::uint32_t k = 0; k < n; ++k) inv[perm[k]] = k;
    // In place, cycle by cycle (the only copies are the keys, the permutation and the events).
    struct Event {
      double time;
      std::uint32_t partner, count;
    };
    std::vector<Event> event(n);
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t from = perm[k], partner = q_.tag_of(from);
      event[k] = Event{q_.time_of(from), partner == kCage ? kCage : inv[partner], q_.stamp_of(from)};
    }
    std::vector<bool> done(n, false);
    std::uint32_t block[kMaxNeighbours];
    for (std::uint32_t s = 0; s < n; ++s) {
      if (done[s]) continue;
      const Sph ps = p_[s];
      const Cage cs = cage_[s];
      std::copy_n(&nb_[std::size_t(s) * kMaxNeighbours], kMaxNeighbours, block);
      std::uint32_t k = s;
      for (;;) {  // record k takes record perm[k]
        done[k] = true;
        const std::uint32_t from = perm[k];
        if (from == s) {
          p_[k] = ps, cage_[k] = cs;
          std::copy_n(block, kMaxNeighbours, &nb_[std::size_t(k) * kMaxNeighbours]);
          break;
        }
        p_[k] = p_[from], cage_[k] = cage_[from];
        std::copy_n(&nb_[std::size_t(from) * kMaxNeighbours], kMaxNeighbours,
                    &nb_[std::size_t(k) * kMaxNeighbours]);
        k = from;
      }
    }
    for (std::uint32_t k = 0; k < n; ++k) {  // renumber the references
      std::uint32_t* l = &nb_[std::size_t(k) * kMaxNeighbours];
      for (std::uint32_t m = 0; m < p_[k].nn; ++m) l[m] = inv[l[m]];
    }
    q_.reset(n, q_.width(), q_.lists(), now_);
    for (std::uint32_t k = 0; k < n; ++k) q_.set(k, event[k].time, event[k].partner, event[k].count);
    rebuild_cells();
  }

  void collide(std::uint32_t i, std::uint32_t j) {
    Sph& a = p_[i];
    Sph& b = p_[j];
    const Vec3 r(image(b.x - a.x, 0), image(b.y - a.y, 1), image(b.z - a.z, 2));
    Vec3 va(a.vx, a.vy, a.vz), vb(b.vx, b.vy, b.vz);
    collide_spheres(va, vb, r / r.norm(), 1.0, 1.0);  // equal masses
    a.vx = va.x(), a.vy = va.y(), a.vz = va.z();
    b.vx = vb.x(), b.vy = vb.y(), b.vz = vb.z();
    a.count = a.count + 1;  // modulo 2^24
    b.count = b.count + 1;
  }

  // Earliest event of sphere i: its cage exit or a collision with a listed sphere.
  void predict(std::uint32_t i) {
    advance(i);
    const Sph& a = p_[i];
    // cage exit
    const Cage c = cage_[i];
    const double px = image(a.x - c.x, 0), py = image(a.y - c.y, 1), pz = image(a.z - c.z, 2);
    const double va = a.vx * a.vx + a.vy * a.vy + a.vz * a.vz;
    const double pb = px * a.vx + py * a.vy + pz * a.vz;
    const double pc = std::min(0.0, px * px + py * py + pz * pz - 0.25 * shell_ * shell_);
    double best = kInf;
    if (va > 0.0) {
      const double sq = std::sqrt(std::max(0.0, pb * pb - va * pc));
      best = pb > 0.0 ? -pc / (pb + sq) : (sq - pb) / va;
    }
    std::uint32_t partner = kCage;
    const std::uint32_t* l = &nb_[std::size_t(i) * kMaxNeighbours];
    const std::uint32_t nn = a.nn;
    // The neighbours' records are the loads that miss at large N: ask for all of them at once.
    if (prefetch_)
      for (std::uint32_t k = 0; k < nn; ++k) {
        __builtin_prefetch(&p_[l[k]]);
        q_.prefetch_slot(l[k]);  // its event time (pairs)
      }
    // Periodic images only near the faces.  A listed j has |c_j - c_i| < sigma + s, and both
    // spheres are inside their cages (radius s / 2) until their events: with c_i more than
    // sigma + 2 s from every face, both positions lie inside the box, so their plain difference
    // (shorter than sigma + 2 s < L / 2) is the minimum image.
    const double m = inner_;
    if (c.x > m && c.x < L_[0] - m && c.y > m && c.y < L_[1] - m && c.z > m && c.z < L_[2] - m)
      pairs<false>(a, l, nn, best, partner);
    else
      pairs<true>(a, l, nn, best, partner);
    q_.set(i, now_ + best, partner, partner == kCage ? 0u : std::uint32_t(p_[partner].count));
  }
  // The earliest collision of a with its listed spheres l[0, nn) that beats best.
  template <bool Images>
  void pairs(const Sph& a, const std::uint32_t* l, std::uint32_t nn, double& best,
             std::uint32_t& partner) const {
    const double s2 = sigma_ * sigma_;
    for (std::uint32_t k = 0; k < nn; ++k) {
      const std::uint32_t j = l[k];
      const Sph& b = p_[j];
      const double dt = now_ - b.t;
      const double dvx = b.vx - a.vx, dvy = b.vy - a.vy, dvz = b.vz - a.vz;
      double rx = b.x + b.vx * dt - a.x, ry = b.y + b.vy * dt - a.y, rz = b.z + b.vz * dt - a.z;
      if constexpr (Images) rx = image(rx, 0), ry = image(ry, 1), rz = image(rz, 2);
      const double bb = rx * dvx + ry * dvy + rz * dvz;
      const double cc = rx * rx + ry * ry + rz * rz - s2;
      // Receding (bb >= 0), or t >= c / (-2b) >= best: cannot win.  One branch for both tests
      // (non-short-circuit &): about half the pairs recede, at random, so a branch of its own
      // is mispredicted often; most pairs fail one test or the other, so this one rarely passes.
      if (!((bb < 0.0) & (cc < -2.0 * bb * best))) continue;
      double t;
      if (cc <= 0.0) {
        t = 0.0;  // touching to rounding and approaching: collide now
      } else {
        const double aa = dvx * dvx + dvy * dvy + dvz * dvz;
        const double disc = bb * bb - aa * cc;
        if (disc < 0.0) continue;  // passes by
        t = cc / (std::sqrt(disc) - bb);
      }
      // (read only for the few pairs that beat best; the header says why it is safe)
      if (t < best && now_ + t <= q_.time_of(j)) best = t, partner = j;
    }
  }

  Vec3 L_, hL_;
  double sigma_, shell_;
  // A sphere whose cage centre is farther than this from every face has no neighbour across
  // one (below), so its pairs need no periodic image; kInf when boxes are too small for that.
  double inner_;
  double now_;
  int ncell_[3];
  double cell_len_[3];
  std::vector<Sph> p_;
  std::vector<Cage> cage_;
  std::vector<std::uint32_t> nb_;
  Calendar q_;
  // The grid of cage centres: cell c's spheres are slot_[c cap_ + k], k < used_[c].
  std::vector<std::uint32_t> slot_;
  std::vector<std::uint8_t> used_;
  std::uint32_t cap_;
  std::vector<std::uint32_t> cand_;  // fill_list's candidates (27 cap_ entries)
  std::uint64_t growths_ = 0;
  std::uint64_t collisions_ = 0, cages_ = 0, stale_ = 0;
  std::uint64_t events_ = 0, reorder_every_ = 0, next_reorder_ = 0;
  bool prefetch_ = true;       // set_prefetch
  bool prefetch_far_ = false;  // the next event's neighbours too (set_prefetch)
};

}  // namespace hb
