// The Andersen thermostat as an event source of single bodies (DESIGN.md "Thermostat"): each body
// is hit by the events of its own Poisson process of `rate` per unit time; at each, its velocity
// is redrawn from the Maxwell distribution at kT, v_k ~ N(0, kT / m), and its angular velocity
// per principal body axis, W_k ~ N(0, kT / I_k) (body frame; w = R W). A smooth sphere's spin
// never couples to anything and is left alone. Between its events a body moves freely, so the
// stationary distribution is canonical and the dynamics is that of the bath-coupled gas.
//
// Reproducibility: the k-th event of body i draws its waiting time and velocities from a
// generator seeded by (seed, i, k) alone, so the run does not depend on the order in which events
// of different bodies happen to be processed, and the thermostat's whole state is each body's
// next event time and event count (saved in checkpoints).
#pragma once
#include <pcg_random.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "collision/rigid.hpp"
#include "core/state.hpp"
#include "math/types.hpp"

namespace hb {

class AndersenThermostat {
 public:
  AndersenThermostat() = default;
  AndersenThermostat(double rate, double kT, std::uint64_t seed) : rate_(rate), kT_(kT), seed_(seed) {
    if (!(rate >= 0.0) || !std::isfinite(rate)) throw std::invalid_argument("thermostat rate must be >= 0");
    if (!(kT > 0.0) || !std::isfinite(kT)) throw std::invalid_argument("thermostat temperature must be > 0");
  }

  bool active() const { return on_ && rate_ > 0.0; }
  double rate() const { return rate_; }
  double kT() const { return kT_; }
  // Switch the thermostat on or off (an "equilibration only" thermostat is switched off when the
  // measured stretch begins); the caller re-predicts every body.
  void set_on(bool on) { on_ = on; }
  bool on() const { return on_; }

  // Each body's first event from time t0 (n bodies), unless restored from a checkpoint.
  void start(std::size_t n, double t0) {
    next_.resize(n);
    fired_.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) next_[i] = t0 + wait(i, 0);
  }
  bool started(std::size_t n) const { return next_.size() == n; }
  double next(std::uint32_t i) const { return next_[i]; }

  // Body i's event at `now` (the body stored at now): new velocities, the next event time.
  // mass, moments: the body's mass and principal moments; rotate = false leaves w alone (a smooth
  // sphere). Returns the kinetic-energy change.
  double fire(State& s, std::uint32_t i, double now, double mass, const Vec3& moments, bool rotate) {
    pcg64 rng = generator(i, fired_[i], 0x76656c6f63697479ull);  // "velocity"
    std::normal_distribution<double> gauss(0.0, 1.0);
    const double e0 = 0.5 * mass * s.v[i].squaredNorm();
    const double sv = std::sqrt(kT_ / mass);
    s.v[i] = sv * Vec3(gauss(rng), gauss(rng), gauss(rng));
    double de = 0.5 * mass * s.v[i].squaredNorm() - e0;
    if (rotate) {
      const Vec3 W0 = s.q[i].conjugate() * s.w[i];
      Vec3 W;
      for (int k = 0; k < 3; ++k) W[k] = std::sqrt(kT_ / moments[k]) * gauss(rng);
      s.w[i] = s.q[i] * W;
      de += 0.5 * (W.dot(moments.cwiseProduct(W)) - W0.dot(moments.cwiseProduct(W0)));
    }
    ++fired_[i];
    next_[i] = now + wait(i, fired_[i]);
    return de;
  }

  // Checkpoint state: the next event time and the event count of every body.
  const std::vector<double>& next_times() const { return next_; }
  const std::vector<std::uint64_t>& counts() const { return fired_; }
  void restore(std::vector<double> next, std::vector<std::uint64_t> fired) {
    if (next.size() != fired.size()) throw std::invalid_argument("thermostat snapshot sizes differ");
    next_ = std::move(next);
    fired_ = std::move(fired);
  }

 private:
  // The generator of body i's k-th event for one purpose (salt): velocities or waiting time.
  pcg64 generator(std::uint32_t i, std::uint64_t k, std::uint64_t salt) const {
    // seed and stream from (seed, i, k): splitmix-style mixing, distinct streams per body
    auto mix = [](std::uint64_t x) {
      x += 0x9e3779b97f4a7c15ull;
      x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
      x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
      return x ^ (x >> 31);
    };
    return pcg64(mix(seed_ ^ mix(k ^ mix(salt))), mix(0x616e64657273656eull + i));  // "andersen"
  }
  double wait(std::uint32_t i, std::uint64_t k) const {
    if (!(rate_ > 0.0)) return kInf;
    pcg64 rng = generator(i, k, 0x77616974696e6731ull);  // "waiting1"
    const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    return -std::log1p(-u) / rate_;  // Exp(rate); u < 1 so the argument is > -1
  }

  double rate_ = 0.0, kT_ = 1.0;
  std::uint64_t seed_ = 1;
  bool on_ = true;
  std::vector<double> next_;
  std::vector<std::uint64_t> fired_;
};

}  // namespace hb
