// Neighbour lists with per-body rebuilds for spheres (the paper's NNL idea, section 3.3, with
// the bounding region of a sphere being a sphere): body i stays within delta/2 of its list
// centre c_i until its rebuild event; two bodies can touch only if |c_i - c_j| < range + delta,
// so only such pairs are listed. When a body reaches the edge of its region, only that body's
// list is rebuilt (DESIGN.md: per-body rebuilds keep the cost per collision flat in N): its
// centre moves to its position, and the lists it appears in are updated symmetrically.
// Centres are binned in cells of width >= range + delta to find new partners.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "events/event.hpp"
#include "neighbors/cell_list.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

// Symmetric adjacency lists in one flat array with a per-body capacity (no allocation per
// event; the capacity doubles, for every body at once, on the rare overflow). Each list is kept
// in index order, so it is a function of its set of neighbours alone, whatever the order of the
// updates: a list rebuilt from a checkpoint is the very list the run had (a pair model with a
// memo between solves needs its candidates in one order, simulation.hpp in_index_order), and
// neighbours numbered along a space-filling curve are read in memory order.
class AdjacencyLists {
 public:
  void init(std::size_t n, std::uint32_t capacity) {
    cap_ = std::max<std::uint32_t>(capacity, 4);
    data_.assign(n * cap_, 0);
    size_.assign(n, 0);
  }
  std::uint32_t size(std::uint32_t i) const { return size_[i]; }
  const std::uint32_t* begin(std::uint32_t i) const { return data_.data() + std::size_t(i) * cap_; }
  const std::uint32_t* end(std::uint32_t i) const { return begin(i) + size_[i]; }
  void add(std::uint32_t i, std::uint32_t j) {
    if (size_[i] == cap_) grow();
    std::uint32_t* b = data_.data() + std::size_t(i) * cap_;
    std::uint32_t* p = b + size_[i]++;
    for (; p > b && p[-1] > j; --p) *p = p[-1];
    *p = j;
  }
  void remove(std::uint32_t i, std::uint32_t j) {
    std::uint32_t* b = data_.data() + std::size_t(i) * cap_;
    std::uint32_t* e = b + size_[i];
    std::uint32_t* p = std::find(b, e, j);
    if (p == e) throw std::logic_error("neighbour list is not symmetric");
    std::copy(p + 1, e, p);
    --size_[i];
  }
  void clear(std::uint32_t i) { size_[i] = 0; }
  // A hint: list i's length and its first two cache lines (a list of ~30 entries), ahead of
  // reading it.
  [[gnu::always_inline]] void prefetch(std::uint32_t i) const {
    __builtin_prefetch(&size_[i]);
    __builtin_prefetch(begin(i));
    __builtin_prefetch(begin(i) + 16);
  }

 private:
  void grow() {
    const std::uint32_t cap = 2 * cap_;
    std::vector<std::uint32_t> d(size_.size() * cap);
    for (std::size_t i = 0; i < size_.size(); ++i)
      std::copy_n(data_.begin() + i * cap_, size_[i], d.begin() + i * cap);
    data_.swap(d);
    cap_ = cap;
  }
  std::uint32_t cap_ = 0;
  std::vector<std::uint32_t> data_;
  std::vector<std::uint32_t> size_;
};

class ShellNeighbors {
 public:
  static constexpr EventType kEventType = EventType::Rebuild;

  ShellNeighbors(double range = 1.0, double delta = 0.2) : range_(range), delta_(delta) {
    if (!(delta > 0.0)) throw std::invalid_argument("neighbour-list shell must be positive");
  }

  void init(const Box& box, State& s, double now) {
    const std::size_t n = s.size();
    const double reach = range_ + delta_;
    // expected partners rho * 4/3 pi reach^3, with room for fluctuations
    const double rho = double(n) / box.volume();
    lists_.init(n, static_cast<std::uint32_t>(2.0 * rho * 4.18879 * reach * reach * reach) + 16);
    cells_.init(box.L, reach, n, box.periodic);
    centre_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      s.advance_to(i, now);
      s.image[i] += box.wrap(s.r[i]);
      centre_[i] = s.r[i];
      cells_.insert(i, centre_[i]);
    }
    const double reach2 = reach * reach;
    for (std::uint32_t i = 0; i < n; ++i)
      cells_.for_each_neighbor(i, box.L, [&](std::uint32_t j, const Vec3& shift) {
        if (j > i && close(i, j, shift, box, reach2)) {
          lists_.add(i, j);
          lists_.add(j, i);
        }
      });
  }

  // Snapshot: the list centres. Restoring rebuilds the lists from them (the same pairs).
  std::vector<Vec3> snapshot() const { return centre_; }
  void restore(const Box& box, const State& s, const std::vector<Vec3>& centres) {
    const std::size_t n = s.size();
    const double reach = range_ + delta_, reach2 = reach * reach;
    const double rho = double(n) / box.volume();
    lists_.init(n, static_cast<std::uint32_t>(2.0 * rho * 4.18879 * reach * reach * reach) + 16);
    cells_.init(box.L, reach, n, box.periodic);
    centre_ = centres;
    for (std::uint32_t i = 0; i < n; ++i) cells_.insert(i, centre_[i]);
    for (std::uint32_t i = 0; i < n; ++i)
      cells_.for_each_neighbor(i, box.L, [&](std::uint32_t j, const Vec3& shift) {
        if (j > i && close(i, j, shift, box, reach2)) {
          lists_.add(i, j);
          lists_.add(j, i);
        }
      });
  }
  const AdjacencyLists& lists() const { return lists_; }
  const Vec3& centre(std::uint32_t i) const { return centre_[i]; }
  double delta() const { return delta_; }
  // Listed bodies are found by id, not by cell: pair code applies the near-image convention
  // (positions stay within delta/2 of centres kept in the box).
  bool needs_minimum_image() const { return true; }

  template <class Fn>
  void for_each_candidate(std::uint32_t i, const Box&, Fn&& fn) const {
    static const Vec3 zero = Vec3::Zero();
    for (const std::uint32_t* p = lists_.begin(i); p != lists_.end(i); ++p) fn(*p, zero);
  }

  // Time at which body i (stored at `now`) reaches distance delta/2 from its centre.
  Event next_event(std::uint32_t i, const State& s, double now) const {
    Event e;
    e.owner = i;
    const Vec3 d = s.r[i] - centre_[i];
    const Vec3& v = s.v[i];
    const double a = v.squaredNorm();
    if (a == 0.0) return e;
    const double h = 0.5 * delta_;
    const double b = d.dot(v);
    const double c = d.squaredNorm() - h * h;  // <= 0 inside
    double t = 0.0;
    if (c < 0.0) {
      const double disc = b * b - a * c;  // > 0 when c < 0
      const double sq = std::sqrt(disc);
      // larger root of a t^2 + 2 b t + c = 0, written without cancellation
      t = b > 0.0 ? -c / (b + sq) : (sq - b) / a;
    }
    e.time = now + t;
    e.type = kEventType;
    return e;
  }

  // Rebuild body i's list at its current position (already streamed to the event time).
  // Returns false: the caller predicts body i against its whole new list.
  template <class Fn>
  bool handle(std::uint32_t i, const Event&, State& s, const Box& box, Fn&&) {
    s.image[i] += box.wrap(s.r[i]);
    centre_[i] = s.r[i];
    cells_.remove(i);
    cells_.insert(i, centre_[i]);
    for (const std::uint32_t* p = lists_.begin(i); p != lists_.end(i); ++p) lists_.remove(*p, i);
    lists_.clear(i);
    const double reach = range_ + delta_, reach2 = reach * reach;
    cells_.for_each_neighbor(i, box.L, [&](std::uint32_t j, const Vec3& shift) {
      if (j != i && close(i, j, shift, box, reach2)) {
        lists_.add(i, j);
        lists_.add(j, i);
      }
    });
    return false;
  }

 private:
  bool close(std::uint32_t i, std::uint32_t j, const Vec3& shift, const Box& box,
             double reach2) const {
    Vec3 d = centre_[j] + shift - centre_[i];
    if (cells_.needs_minimum_image()) d = box.minimum_image(d);
    return d.squaredNorm() < reach2;
  }

  double range_, delta_;
  CellList cells_;  // over list centres; changes only at rebuilds
  std::vector<Vec3> centre_;
  AdjacencyLists lists_;
};

}  // namespace hb
