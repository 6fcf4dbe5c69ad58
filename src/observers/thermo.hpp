// Read-only observers fed by collision records and by the state at log times.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "collision/record.hpp"
#include "observers/block_average.hpp"

namespace hb {

// Molecular virial pressure: beta P / rho = kT_ratio + sum_coll J n.r_AB / (3 N kT t).
// One block per log interval; Z per block and its block-averaged mean and standard error.
class VirialPressure {
 public:
  void on_collision(const CollisionRecord& r) {
    const double w = r.J * r.n.dot(r.r_AB);
    sum_ += w;
    total_sum_ += w;
    ++collisions_;
    ++total_collisions_;
  }
  // Close the current block of duration dt at translational temperature kT.
  void close_block(double dt, double kT, std::size_t n) {
    if (dt <= 0.0) return;
    n_ = n;
    last_ = 1.0 + sum_ / (3.0 * double(n) * kT * dt);
    total_time_ += dt;
    total_kT_time_ += kT * dt;
    z_.push_back(last_);
    rate_.push_back(2.0 * double(collisions_) / (double(n) * dt));
    sum_ = 0.0;
    collisions_ = 0;
  }
  void reset() {
    total_sum_ = total_time_ = total_kT_time_ = 0.0;
    total_collisions_ = 0;
    sum_ = 0.0;
    collisions_ = 0;
    z_.clear();
    rate_.clear();
  }
  double last_Z() const { return last_; }
  const std::vector<double>& Z_blocks() const { return z_; }
  // Z over the whole measured time (exact ratio of sums; equals the block mean for equal
  // blocks) with the block-averaged standard error.
  MeanError Z() const {
    MeanError m = block_average(z_);
    if (total_time_ > 0.0 && n_ > 0)
      m.mean = 1.0 + total_sum_ / (3.0 * double(n_) * total_kT_time_);
    return m;
  }
  MeanError collision_rate() const {
    MeanError m = block_average(rate_);
    if (total_time_ > 0.0 && n_ > 0) m.mean = 2.0 * double(total_collisions_) / (double(n_) * total_time_);
    return m;
  }
  double measured_time() const { return total_time_; }

  // Flat serialisation for checkpoints (exact doubles; counts < 2^53).
  std::vector<double> save() const {
    std::vector<double> d{sum_, total_sum_, total_time_, total_kT_time_, double(collisions_),
                          double(total_collisions_), double(n_), last_, double(z_.size())};
    d.insert(d.end(), z_.begin(), z_.end());
    d.insert(d.end(), rate_.begin(), rate_.end());
    return d;
  }
  void load(const std::vector<double>& d) {
    if (d.size() < 9 || d.size() != 9 + 2 * std::size_t(d[8]))
      throw std::invalid_argument("pressure accumulator record has the wrong length");
    sum_ = d[0], total_sum_ = d[1], total_time_ = d[2], total_kT_time_ = d[3];
    collisions_ = std::uint64_t(d[4]), total_collisions_ = std::uint64_t(d[5]);
    n_ = std::size_t(d[6]), last_ = d[7];
    const std::size_t nb = std::size_t(d[8]);
    z_.assign(d.begin() + 9, d.begin() + 9 + nb);
    rate_.assign(d.begin() + 9 + nb, d.end());
  }

 private:
  double sum_ = 0.0, total_sum_ = 0.0, total_time_ = 0.0, total_kT_time_ = 0.0;
  std::uint64_t collisions_ = 0, total_collisions_ = 0;
  std::size_t n_ = 0;
  double last_ = 0.0;
  std::vector<double> z_, rate_;
};

// Temperatures per species, sampled at the end of every log block: translational 2 K_t / (3 n)
// and, per principal body axis k, I_k W_k^2 / n (W the body-frame angular velocity; equipartition
// makes each equal to kT). Reported as block-averaged means with standard errors. The caller
// computes the four sums of a sample (sample()); the observer only keeps the series.
class SpeciesTemperatures {
 public:
  static constexpr std::size_t kValues = 4;  // translational, rotational x, y, z
  explicit SpeciesTemperatures(std::size_t species = 0) : series_(species * kValues) {}

  // values[a * 4 + c]: species a, component c (see the class comment).
  void sample(const std::vector<double>& values) {
    if (values.size() != series_.size()) throw std::invalid_argument("SpeciesTemperatures: wrong sample size");
    for (std::size_t k = 0; k < values.size(); ++k) series_[k].push_back(values[k]);
  }
  std::size_t samples() const { return series_.empty() ? 0 : series_[0].size(); }
  MeanError get(std::size_t species, std::size_t component) const {
    return block_average(series_[species * kValues + component]);
  }

  std::vector<double> save() const {
    std::vector<double> d{double(series_.size()), double(samples())};
    for (const auto& x : series_) d.insert(d.end(), x.begin(), x.end());
    return d;
  }
  void load(const std::vector<double>& d) {
    if (d.size() < 2 || d.size() != 2 + std::size_t(d[0]) * std::size_t(d[1]) ||
        std::size_t(d[0]) != series_.size())
      throw std::invalid_argument("temperature accumulator record has the wrong length");
    const std::size_t n = std::size_t(d[1]);
    for (std::size_t k = 0; k < series_.size(); ++k)
      series_[k].assign(d.begin() + 2 + k * n, d.begin() + 2 + (k + 1) * n);
  }

 private:
  std::vector<std::vector<double>> series_;
};

}  // namespace hb
