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

}  // namespace hb
