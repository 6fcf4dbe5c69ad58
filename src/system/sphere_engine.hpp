// A dedicated event loop for identical smooth hard spheres in a periodic box (issue 15): the
// fast path of the most common benchmark, beside the generic Simulation<HardSpheres, ...>
// (system/simulation.hpp), which stays its slow twin (tests/system/test_sphere_engine.cpp: the
// same collisions, in the same order, at the same times).
//
// What it does differently from the generic loop (the ideas of the fastest public hard-sphere
// codes; the code is our own):
//  * One compact 64-byte record per sphere (position, own clock, velocity, event counter): the
//    loads of a prediction touch one cache line per candidate.
//  * Cages instead of cell crossings.  Each sphere i owns a cage, the ball of radius s/2 about
//    its cage centre c_i (its position when the cage was made), and a neighbour list holding
//    every j with |c_i - c_j| < sigma + s (minimum image), kept symmetric.  While both spheres
//    are in their cages, |x_i - x_j| >= |c_i - c_j| - s, so spheres that are not listed
//    cannot touch: every contact is between listed pairs.  The only bookkeeping event is a
//    sphere leaving its cage (closed form, below); it then takes a new cage at its position,
//    leaves its old neighbours' lists and joins those of its new ones (found through a grid of
//    cage centres with cells of side >= sigma + s; a centre changes cell only there, so there
//    are no cell-crossing events).
//  * Early rejection before any square root.  For an approaching pair (b = r.v < 0) outside
//    contact (c = r^2 - sigma^2 >= 0) the first root t = c / (sqrt(b^2 - a c) - b) satisfies
//    t >= c / (-2 b) (sqrt(b^2 - a c) <= -b), so a pair with c >= -2 b t_best cannot beat the
//    best time found so far and is dropped without the square root.
//  * One event per sphere (its earliest collision or its cage exit) in a binary heap whose nodes
//    hold the event time inline (a sift reads contiguous memory, not the event records).
//  A collision event carries the partner's event counter at prediction; if the partner has
//  changed velocity since, the event is stale and the owner is predicted again (as in the
//  generic loop).
//
// Cage exit: with p = x_i - c_i (minimum image), |p + v tau| = s / 2 first at
//     tau = (-b + sqrt(b^2 - a c)) / a,   a = v.v, b = p.v, c = p.p - s^2 / 4 <= 0,
// written as tau = -c / (b + sqrt(b^2 - a c)) when b > 0 (no cancellation).
// Collision (equal masses): with the unit normal n from i to j and dv = v_j - v_i,
//     v_i += (dv.n) n,  v_j -= (dv.n) n.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/box.hpp"
#include "core/state.hpp"
#include "math/types.hpp"

namespace hb {

class SphereEngine {
 public:
  static constexpr int kMaxNeighbours = 20;  // per sphere (memory: 4 bytes each)
  static constexpr std::uint32_t kCage = 0xffffffffu;  // partner of a cage-exit event

  enum class Kind { collision, cage, stale };
  struct Step {
    Kind kind = Kind::stale;
    std::uint32_t i = 0, j = 0;
    double time = 0.0;
  };

  // Spheres of diameter sigma at the state's positions and velocities (all at s.t[i]); shell s:
  // the cage diameter (neighbour lists reach sigma + s).
  SphereEngine(const Box& box, const State& s, double sigma, double shell, double now = 0.0)
      : L_(box.L), hL_(0.5 * box.L), sigma_(sigma), shell_(shell), now_(now) {
    if (!box.fully_periodic()) throw std::invalid_argument("SphereEngine: the box must be periodic");
    if (!(shell > 0.0)) throw std::invalid_argument("SphereEngine: the shell must be positive");
    const std::size_t n = s.size();
    p_.resize(n);
    cage_.resize(n);
    nb_.assign(n * kMaxNeighbours, 0);
    for (std::size_t i = 0; i < n; ++i) {
      Sph& q = p_[i];
      const Vec3 r = s.position_at(i, now);
      q.x = wrap(r.x(), 0), q.y = wrap(r.y(), 1), q.z = wrap(r.z(), 2);
      q.t = now;
      q.vx = s.v[i].x(), q.vy = s.v[i].y(), q.vz = s.v[i].z();
      q.count = 0;
      q.nn = 0;
    }
    for (int k = 0; k < 3; ++k) {
      ncell_[k] = std::max(1, static_cast<int>(std::floor(L_[k] / (sigma + shell))));
      if (ncell_[k] < 3)
        throw std::invalid_argument("SphereEngine: the box is smaller than 3 cells of sigma + shell");
      cell_len_[k] = L_[k] / ncell_[k];
    }
    head_.assign(std::size_t(ncell_[0]) * ncell_[1] * ncell_[2], kNone);
    next_.assign(n, kNone);
    for (std::uint32_t i = 0; i < n; ++i) {
      cage_[i] = Vec3(p_[i].x, p_[i].y, p_[i].z);
      const std::uint32_t c = cell_of(cage_[i]);
      next_[i] = head_[c];
      head_[c] = i;
    }
    for (std::uint32_t i = 0; i < n; ++i) fill_list(i, /*only_higher=*/true);
    ev_.resize(n);
    heap_.resize(n);
    pos_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      heap_[i] = Node{kInf, i};
      pos_[i] = i;
    }
    for (std::uint32_t i = 0; i < n; ++i) predict(i);
  }

  double now() const { return now_; }
  std::uint64_t collisions() const { return collisions_; }
  std::uint64_t cage_exits() const { return cages_; }
  std::uint64_t stale_events() const { return stale_; }
  std::size_t size() const { return p_.size(); }

  // Process the next event.
  Step step() {
    const Node top = heap_[0];
    const std::uint32_t i = top.id;
    const Ev e = ev_[i];
    now_ = top.time;
    Step out;
    out.i = i;
    out.time = now_;
    if (e.partner == kCage) {
      advance(i);
      new_cage(i);
      ++cages_;
      out.kind = Kind::cage;
      predict(i);
      return out;
    }
    const std::uint32_t j = e.partner;
    out.j = j;
    if (p_[j].count != e.partner_count) {
      ++stale_;
      predict(i);
      return out;
    }
    advance(i);
    advance(j);
    collide(i, j);
    ++collisions_;
    out.kind = Kind::collision;
    predict(i);
    predict(j);
    return out;
  }

  // The spheres' state at the current time (positions wrapped into the box).
  State state() const {
    State s;
    s.resize(p_.size());
    for (std::size_t i = 0; i < p_.size(); ++i) {
      const Sph& q = p_[i];
      const double dt = now_ - q.t;
      s.r[i] = Vec3(wrap(q.x + q.vx * dt, 0), wrap(q.y + q.vy * dt, 1), wrap(q.z + q.vz * dt, 2));
      s.v[i] = Vec3(q.vx, q.vy, q.vz);
      s.t[i] = now_;
    }
    return s;
  }

  // Bytes of the per-sphere arrays (the memory figure of the benchmark).
  std::size_t bytes_per_sphere() const {
    return sizeof(Sph) + sizeof(Vec3) + kMaxNeighbours * sizeof(std::uint32_t) + sizeof(Ev) +
           sizeof(Node) + sizeof(std::uint32_t) /*pos*/ + sizeof(std::uint32_t) /*next*/;
  }

 private:
  static constexpr std::uint32_t kNone = 0xffffffffu;
  struct alignas(64) Sph {
    double x, y, z, t;     // position at the own clock t
    double vx, vy, vz;
    std::uint32_t count;   // velocity changes so far
    std::uint32_t nn;      // neighbours listed
  };
  struct Ev {
    std::uint32_t partner = kCage, partner_count = 0;
  };
  struct Node {
    double time;
    std::uint32_t id;
  };

  double wrap(double x, int k) const {
    if (x >= L_[k]) x -= L_[k];
    else if (x < 0.0) x += L_[k];
    return x;  // one box length at most: positions move less than a cage between wraps
  }
  double image(double d, int k) const {
    if (d > hL_[k]) d -= L_[k];
    else if (d < -hL_[k]) d += L_[k];
    return d;
  }
  std::uint32_t cell_of(const Vec3& c) const {
    int idx[3];
    for (int k = 0; k < 3; ++k) idx[k] = std::min(ncell_[k] - 1, static_cast<int>(c[k] / cell_len_[k]));
    return std::uint32_t((idx[2] * ncell_[1] + idx[1]) * ncell_[0] + idx[0]);
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
  // only j > i (the initial fill, which visits every pair once).
  void fill_list(std::uint32_t i, bool only_higher) {
    const Vec3& ci = cage_[i];
    const double reach2 = (sigma_ + shell_) * (sigma_ + shell_);
    int idx[3];
    for (int k = 0; k < 3; ++k) idx[k] = std::min(ncell_[k] - 1, static_cast<int>(ci[k] / cell_len_[k]));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = (idx[0] + dx + ncell_[0]) % ncell_[0];
          const int cy = (idx[1] + dy + ncell_[1]) % ncell_[1];
          const int cz = (idx[2] + dz + ncell_[2]) % ncell_[2];
          for (std::uint32_t j = head_[(cz * ncell_[1] + cy) * ncell_[0] + cx]; j != kNone; j = next_[j]) {
            if (j == i || (only_higher && j < i)) continue;
            const Vec3& cj = cage_[j];
            const double ex = image(cj.x() - ci.x(), 0), ey = image(cj.y() - ci.y(), 1),
                         ez = image(cj.z() - ci.z(), 2);
            if (ex * ex + ey * ey + ez * ez < reach2) {
              push(i, j);
              push(j, i);
            }
          }
        }
  }
  void push(std::uint32_t i, std::uint32_t j) {
    std::uint32_t& nn = p_[i].nn;
    if (nn == kMaxNeighbours)
      throw std::runtime_error("SphereEngine: more than " + std::to_string(kMaxNeighbours) +
                               " neighbours of sphere " + std::to_string(i) + "; use a smaller shell");
    nb_[std::size_t(i) * kMaxNeighbours + nn++] = j;
  }
  void remove(std::uint32_t j, std::uint32_t i) {  // i from j's list
    std::uint32_t* l = &nb_[std::size_t(j) * kMaxNeighbours];
    std::uint32_t& nn = p_[j].nn;
    for (std::uint32_t k = 0; k < nn; ++k)
      if (l[k] == i) {
        l[k] = l[--nn];
        return;
      }
  }

  // Sphere i (advanced to now) takes a new cage at its position.
  void new_cage(std::uint32_t i) {
    const std::uint32_t* l = &nb_[std::size_t(i) * kMaxNeighbours];
    for (std::uint32_t k = 0; k < p_[i].nn; ++k) remove(l[k], i);
    p_[i].nn = 0;
    const std::uint32_t c_old = cell_of(cage_[i]);
    cage_[i] = Vec3(p_[i].x, p_[i].y, p_[i].z);
    const std::uint32_t c_new = cell_of(cage_[i]);
    if (c_new != c_old) {
      std::uint32_t* link = &head_[c_old];
      while (*link != i) link = &next_[*link];
      *link = next_[i];
      next_[i] = head_[c_new];
      head_[c_new] = i;
    }
    fill_list(i, false);
  }

  void collide(std::uint32_t i, std::uint32_t j) {
    Sph& a = p_[i];
    Sph& b = p_[j];
    const double rx = image(b.x - a.x, 0), ry = image(b.y - a.y, 1), rz = image(b.z - a.z, 2);
    const double inv = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz);
    const double nx = rx * inv, ny = ry * inv, nz = rz * inv;
    const double dvn = (b.vx - a.vx) * nx + (b.vy - a.vy) * ny + (b.vz - a.vz) * nz;
    a.vx += dvn * nx, a.vy += dvn * ny, a.vz += dvn * nz;
    b.vx -= dvn * nx, b.vy -= dvn * ny, b.vz -= dvn * nz;
    ++a.count;
    ++b.count;
  }

  // Earliest event of sphere i: its cage exit or a collision with a listed sphere.
  void predict(std::uint32_t i) {
    advance(i);
    const Sph& a = p_[i];
    // cage exit
    const Vec3& c = cage_[i];
    const double px = image(a.x - c.x(), 0), py = image(a.y - c.y(), 1), pz = image(a.z - c.z(), 2);
    const double va = a.vx * a.vx + a.vy * a.vy + a.vz * a.vz;
    const double pb = px * a.vx + py * a.vy + pz * a.vz;
    const double pc = std::min(0.0, px * px + py * py + pz * pz - 0.25 * shell_ * shell_);
    double best = kInf;
    if (va > 0.0) {
      const double sq = std::sqrt(std::max(0.0, pb * pb - va * pc));
      best = pb > 0.0 ? -pc / (pb + sq) : (sq - pb) / va;
    }
    std::uint32_t partner = kCage;
    const double s2 = sigma_ * sigma_;
    const std::uint32_t* l = &nb_[std::size_t(i) * kMaxNeighbours];
    for (std::uint32_t k = 0; k < a.nn; ++k) {
      const std::uint32_t j = l[k];
      const Sph& b = p_[j];
      const double dt = now_ - b.t;
      const double dvx = b.vx - a.vx, dvy = b.vy - a.vy, dvz = b.vz - a.vz;
      const double rx = image(b.x + b.vx * dt - a.x, 0);
      const double ry = image(b.y + b.vy * dt - a.y, 1);
      const double rz = image(b.z + b.vz * dt - a.z, 2);
      const double bb = rx * dvx + ry * dvy + rz * dvz;
      if (bb >= 0.0) continue;  // receding
      const double cc = rx * rx + ry * ry + rz * rz - s2;
      if (cc >= -2.0 * bb * best) continue;  // t >= c / (-2b) >= best: cannot win
      double t;
      if (cc <= 0.0) {
        t = 0.0;  // touching to rounding and approaching: collide now
      } else {
        const double aa = dvx * dvx + dvy * dvy + dvz * dvz;
        const double disc = bb * bb - aa * cc;
        if (disc < 0.0) continue;  // passes by
        t = cc / (std::sqrt(disc) - bb);
      }
      if (t < best) best = t, partner = j;
    }
    ev_[i] = Ev{partner, partner == kCage ? 0u : p_[partner].count};
    set_time(i, now_ + best);
  }

  // Heap of (time, sphere) with positions pos_.
  void set_time(std::uint32_t i, double t) {
    std::uint32_t k = pos_[i];
    const double old = heap_[k].time;
    const Node node{t, i};
    const std::uint32_t n = static_cast<std::uint32_t>(heap_.size());
    if (t < old) {
      while (k > 0) {
        const std::uint32_t up = (k - 1) >> 1;
        if (!less(node, heap_[up])) break;
        heap_[k] = heap_[up];
        pos_[heap_[k].id] = k;
        k = up;
      }
    } else {
      for (;;) {
        std::uint32_t ch = 2 * k + 1;
        if (ch >= n) break;
        if (ch + 1 < n && less(heap_[ch + 1], heap_[ch])) ++ch;
        if (!less(heap_[ch], node)) break;
        heap_[k] = heap_[ch];
        pos_[heap_[k].id] = k;
        k = ch;
      }
    }
    heap_[k] = node;
    pos_[i] = k;
  }
  static bool less(const Node& a, const Node& b) {
    return a.time < b.time || (a.time == b.time && a.id < b.id);
  }

  Vec3 L_, hL_;
  double sigma_, shell_;
  double now_;
  int ncell_[3];
  double cell_len_[3];
  std::vector<Sph> p_;
  std::vector<Vec3> cage_;
  std::vector<std::uint32_t> nb_;
  std::vector<Ev> ev_;
  std::vector<Node> heap_;
  std::vector<std::uint32_t> pos_;
  std::vector<std::uint32_t> head_, next_;
  std::uint64_t collisions_ = 0, cages_ = 0, stale_ = 0;
};

}  // namespace hb
