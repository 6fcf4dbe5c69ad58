// Structural observables of a configuration: the radial distribution function g(r) of the body
// centres (accumulated over samples) and the nematic order parameter S2 with its director.
// Read-only; the driver calls sample() on a synchronized state. Definitions and table formats
// are in docs/observables.md.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/species.hpp"
#include "math/types.hpp"
#include "observers/block_average.hpp"
#include "system/box.hpp"
#include "system/state.hpp"

namespace hb {

struct RdfSpec {
  // Largest pair distance histogrammed. 0: half the shortest box edge at the first sample.
  // Must not exceed half the shortest box edge (so that each pair is counted once).
  double r_max = 0.0;
  // Number of equal-width bins on [0, r_max]. Must be >= 1.
  int bins = 200;
  // Pair search. automatic: brute force for N <= cells_above, cell lists above. Both give
  // identical histograms; cells falls back to brute force when fewer than 3 cells fit an edge.
  enum class Method { automatic, brute_force, cells };
  Method method = Method::automatic;
  std::size_t cells_above = 20000;
};

// Histogram of minimum-image distances |r_j - r_i| < r_max over pairs i < j, added into `hist`
// (size = bins; bin k covers [k, k+1) * r_max / bins). `positions` must lie in [0, L) and
// r_max <= min(L)/2. Exposed so that tests compare the two; the results are identical.
void pair_histogram_brute(const std::vector<Vec3>& positions, const Box& box, double r_max,
                          std::vector<std::uint64_t>& hist);
void pair_histogram_cells(const std::vector<Vec3>& positions, const Box& box, double r_max,
                          std::vector<std::uint64_t>& hist);

class RadialDistribution {
 public:
  explicit RadialDistribution(const RdfSpec& spec = {});

  // Add the pairs of the configuration at `time` (bodies behind are streamed on a copy).
  // Throws std::invalid_argument if r_max exceeds half the shortest box edge.
  void sample(double time, const State& state, const Box& box);
  void reset();
  // Flat serialisation for checkpoints; load() throws std::invalid_argument on a record whose
  // bin count differs.
  std::vector<double> save() const;
  void load(const std::vector<double>& record);

  double r_max() const { return r_max_; }  // 0 until the first sample when spec.r_max == 0
  int samples() const { return samples_; }
  // Per bin: centre, g(r) = pairs / (ideal-gas pairs N (N-1) / (2 V) x shell volume), and the
  // mean number of neighbours within the bin's upper edge, n(r) = 2 x pairs(< r) / N.
  std::vector<double> r() const;
  std::vector<double> g() const;
  std::vector<double> coordination() const;
  const std::vector<std::uint64_t>& pair_counts() const { return hist_; }

  // Table: '#' comment lines (samples, N, r_max, bins), header
  //   r  g  n_r  pairs
  // and one row per bin (r = bin centre, pairs = raw count summed over samples).
  std::string to_tsv() const;

 private:
  RdfSpec spec_;
  double r_max_ = 0.0;
  int samples_ = 0;
  std::size_t last_n_ = 0;
  double sum_pair_density_ = 0.0;  // sum over samples of N (N - 1) / (2 V)
  double sum_n_ = 0.0;             // sum over samples of N
  std::vector<std::uint64_t> hist_;
  std::vector<Vec3> pos_;          // scratch
};

// Partial radial distribution functions g_ab(r) of a mixture, one per species pair a <= b, on
// the bins of a given r_max. Histograms add, so the pairs of a and b are counted with the
// tested pair_histogram_* functions: pairs_aa = H(a), pairs_ab = H(a + b) - H(a) - H(b) for
// a != b (H(x): the histogram of the centres of the bodies in x). Normalisation: the ideal-gas
// pair density N_a (N_a - 1) / (2 V) for a = b, N_a N_b / V for a != b.
class PartialRadialDistribution {
 public:
  PartialRadialDistribution(std::size_t species, int bins);
  // r_max <= half the shortest box edge (the driver takes the whole g(r)'s).
  void sample(double time, const State& state, const Box& box, double r_max);
  std::size_t pair_index(std::size_t a, std::size_t b) const;  // a <= b
  std::vector<double> g(std::size_t a, std::size_t b) const;
  const std::vector<std::uint64_t>& pair_counts(std::size_t a, std::size_t b) const {
    return hist_[pair_index(a, b)];
  }
  std::vector<double> save() const;
  void load(const std::vector<double>& record);
  // Table: '#' comment lines, header r g_<A>_<B> ... (a <= b in species order), one row per bin.
  std::string to_tsv(const std::vector<std::string>& names) const;

 private:
  std::size_t ns_;
  int bins_;
  double r_max_ = 0.0;
  int samples_ = 0;
  std::vector<double> density_;                  // per pair: sum over samples of its pair density
  std::vector<std::vector<std::uint64_t>> hist_;  // per pair
};

// Nematic order of the body axes u_i = q_i * body_axis:
// Q = (1/N) sum_i (3 u_i u_i^T - I) / 2; S2 = its largest eigenvalue, director = its eigenvector
// (sign chosen so that the largest-magnitude component is positive).
struct NematicResult {
  double S2 = 0.0;
  Vec3 director = Vec3::UnitX();
  Vec3 eigenvalues = Vec3::Zero();  // ascending
};
NematicResult nematic_order(const std::vector<Quat>& orientations,
                            const Vec3& body_axis = Vec3::UnitX());

class NematicOrder {
 public:
  explicit NematicOrder(const Vec3& body_axis = Vec3::UnitX());

  // Evaluate S2 and the director at `time` and append them to the series.
  void sample(double time, const State& state, const Box& box);
  void reset();
  // Flat serialisation for checkpoints (the whole series).
  std::vector<double> save() const;
  void load(const std::vector<double>& record);

  const std::vector<double>& times() const { return times_; }
  const std::vector<NematicResult>& series() const { return series_; }
  // Mean S2 over the samples with its block-averaged standard error.
  MeanError S2() const;

  // Table: '#' comment line (mean S2 and error), header
  //   time  S2  director_x  director_y  director_z
  // and one row per sample.
  std::string to_tsv() const;

 private:
  Vec3 axis_;
  std::vector<double> times_;
  std::vector<NematicResult> series_;
  std::vector<Quat> q_;  // scratch
};

}  // namespace hb
