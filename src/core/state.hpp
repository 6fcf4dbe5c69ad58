// State of all bodies as a structure of arrays with delayed (per-particle) times: body i is
// stored as it was at its own time t[i] and is streamed forward only when an event touches it.
#pragma once
#include <cstdint>
#include <vector>

#include "math/types.hpp"
#include "motion/free_flight.hpp"

namespace hb {

struct State {
  std::vector<Vec3> r;                // position at t[i] (wrapped into the box at events)
  std::vector<Vec3> v;                // velocity
  std::vector<Quat> q;                // orientation body -> lab at t[i]
  std::vector<Vec3> w;                // angular velocity (lab frame)
  std::vector<double> t;              // time stamp of the stored state
  std::vector<std::uint32_t> count;   // number of velocity changes (event counter)
  std::vector<Eigen::Vector3i> image; // periodic images crossed (for unwrapped positions)
  std::vector<std::uint16_t> species; // index into the run's species table (core/species.hpp)
  std::vector<double> scale;          // size scale of the body (1 unless polydisperse)
  // Per species: the principal moments that govern the free rotation (BodyState::top). Empty,
  // or equal moments: spherical tops (w constant). Set by the pair model (prepare()).
  std::vector<Vec3> tops;

  std::size_t size() const { return r.size(); }

 private:
  struct RotationCache {
    Quat q = Quat::Identity();
    Vec3 w = Vec3::Zero();
    bool valid = false;
    FreeRotation rot;
  };
  mutable std::vector<RotationCache> rot_cache_;  // per body, for tops only (free_rotation)

 public:
  void resize(std::size_t n) {
    r.assign(n, Vec3::Zero());
    v.assign(n, Vec3::Zero());
    q.assign(n, Quat::Identity());
    w.assign(n, Vec3::Zero());
    t.assign(n, 0.0);
    count.assign(n, 0);
    image.assign(n, Eigen::Vector3i::Zero());
    species.assign(n, 0);
    scale.assign(n, 1.0);
  }

  // Ask the memory system for body i's stored state ahead of its use (a hint, no effect on any
  // result): the prediction loop touches neighbours' records from all over the box, and each
  // contact-time solve is long enough to hide the next one's cache misses.
  void prefetch(std::size_t i) const {
    __builtin_prefetch(&r[i]);
    __builtin_prefetch(&v[i]);
    __builtin_prefetch(&q[i]);
    __builtin_prefetch(&w[i]);
    __builtin_prefetch(&t[i]);
  }
  // Position of body i at time `now` (no state change).
  Vec3 position_at(std::size_t i, double now) const { return r[i] + v[i] * (now - t[i]); }
  Vec3 top(std::size_t i) const { return tops.empty() ? Vec3::Zero() : tops[species[i]]; }
  // The exact free rotation of body i (a top that is not spherical) from its stored q and w, set
  // up once and kept until q or w change: a pure function of them, so no result depends on when
  // it was set up (checkpoints resume bit for bit).
  const FreeRotation& free_rotation(std::size_t i) const {
    if (rot_cache_.size() != r.size()) rot_cache_.assign(r.size(), RotationCache{});
    RotationCache& c = rot_cache_[i];
    if (!c.valid || c.q.coeffs() != q[i].coeffs() || c.w != w[i]) {
      c.rot = FreeRotation::make(top(i), q[i], w[i]);
      c.q = q[i], c.w = w[i], c.valid = true;
    }
    return c.rot;
  }
  BodyState body(std::size_t i) const {
    BodyState b{r[i], q[i], v[i], w[i], top(i)};
    if (!spherical_top(b.top)) b.rot = &free_rotation(i);
    return b;
  }
  BodyState body_at(std::size_t i, double now) const {
    BodyState b = body(i);
    advance(b, now - t[i]);
    return b;
  }
  // Stream body i forward to `now`.
  void advance_to(std::size_t i, double now) {
    const double dt = now - t[i];
    if (dt != 0.0) {
      r[i] += v[i] * dt;
      if (w[i].squaredNorm() != 0.0) {
        const Vec3 I = top(i);
        if (spherical_top(I)) q[i] = orientation_at(BodyState{r[i], q[i], v[i], w[i]}, dt);
        else free_rotation(i).evaluate(dt, q[i], w[i]);
      }
      t[i] = now;
    }
  }
};

}  // namespace hb
