// Structural observables of a configuration: the radial distribution function g(r) of the body
// centres (accumulated over samples) and the nematic order parameter S2 with its director.
// Read-only; the driver calls sample() on a synchronized state. Definitions and table formats
// are in docs/observables.md.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/species.hpp"
#include "math/types.hpp"
#include "observers/block_average.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

struct RdfSpec {
  // Largest pair distance histogrammed. 0 (automatic): half the shortest box edge at the first
  // sample, capped so that a body has at most `max_neighbours` neighbours within r_max in the
  // ideal gas ((N - 1) / V x 4/3 pi r_max^3); the cap only bites above N ~ 19000 in a cubic
  // box. An explicit r_max must not exceed half the shortest box edge.
  double r_max = 0.0;
  // Number of equal-width bins on [0, r_max]. Must be >= 1.
  int bins = 200;
  double max_neighbours = 10000.0;
  // Work bound of one sample: expected pair distances evaluated. When counting every pair
  // would cost more, a deterministic subset of centres is used (see PairSearch).
  double max_pairs = 2e8;
};

// How pair_histogram searches. The cell grid has cells of side >= r_max / k (k <= 4, chosen so
// that a cell holds about one body or more) and a stencil of +-k cells (all cells of an edge
// that has fewer than 2k + 1 cells), so every pair within r_max is found whatever r_max and the
// box shape. All pairs are counted when N x (bodies in a stencil) / 2 <= max_pairs; otherwise
// only the centres i = offset, offset + stride, ... are counted, each against every other body
// (ordered pairs), with stride = ceil(N x stencil bodies / max_pairs). The work of one call is
// O(N) to sort the bodies into cells plus at most max(max_pairs, N) distances.
struct PairSearch {
  double max_pairs = 2e8;
  std::size_t offset = 0;  // first centre when a subset is counted (taken modulo the stride)
  double cell_side = 0.0;  // > 0: use this cell side instead of the automatic one (tests)
};

// What a pair_histogram call counted.
struct PairCount {
  bool all_pairs = true;      // every unordered pair once; else ordered (centre, other) pairs
  std::size_t stride = 1;     // centres are offset, offset + stride, ... (1 with all_pairs)
  std::size_t offset = 0;
  std::size_t centres = 0;    // number of centres (N with all_pairs)
  std::array<int, 3> cells{}; // cells per box edge
  int stencil = 1;            // k: the stencil spans +-k cells (the widest edge)
  std::uint64_t distances = 0;  // pair distances evaluated (the work)
};

// Histogram of minimum-image distances |r_j - r_i| < r_max (bin k covers [k, k+1) * r_max /
// bins, hist.size() = bins), added into `hist`. With all pairs: pairs i < j; with a subset: the
// ordered pairs (i, j), i a centre, j != i. `positions` must lie in [0, L) and
// r_max <= min(L)/2; throws std::invalid_argument otherwise. Polls for interrupts; `hist` is
// unchanged when it throws. The tests compare it with an all-pairs loop.
PairCount pair_histogram(FieldView<Vec3> positions, const Box& box, double r_max,
                         std::vector<std::uint64_t>& hist, const PairSearch& search = {});

class RadialDistribution {
 public:
  explicit RadialDistribution(const RdfSpec& spec = {});

  // Add the pairs of the configuration at `time` (bodies behind are streamed on a copy):
  // prepare() then commit().
  // Throws std::invalid_argument if r_max exceeds half the shortest box edge.
  void sample(double time, const State& state, const Box& box);
  // The two halves of sample(), so that a driver can sample several observers all or nothing:
  // prepare() does the work and may throw (hb::Interrupted, std::invalid_argument) leaving the
  // accumulated histogram untouched (it fixes the automatic r_max at the first call);
  // commit() adds the prepared sample and does not throw. commit() without a pending sample
  // does nothing.
  void prepare(double time, const State& state, const Box& box);
  void commit() noexcept;
  void reset();
  // Flat serialisation for checkpoints; load() throws std::invalid_argument on a record whose
  // bin count differs.
  std::vector<double> save() const;
  void load(const std::vector<double>& record);

  double r_max() const { return r_max_; }  // 0 until the first sample when spec.r_max == 0
  // The r_max a sample of n bodies in `box` uses: r_max() once set, else the automatic one
  // (for a partial g(r) prepared before this observer's commit).
  double r_max_for(const Box& box, std::size_t n) const;
  int samples() const { return samples_; }
  // Samples that counted a subset of centres (see PairSearch), and the centres summed over all
  // samples (N per sample when every pair is counted).
  int subset_samples() const { return subset_samples_; }
  double centres() const { return sum_centres_; }
  // Per bin: centre, g(r) = pairs / (ideal-gas pairs x shell volume), with ideal-gas pairs
  // N (N-1) / (2 V) (all pairs) or K (N - 1) / V (K centres), and the mean number of neighbours
  // within the bin's upper edge, n(r).
  std::vector<double> r() const;
  std::vector<double> g() const;
  std::vector<double> coordination() const;
  const std::vector<std::uint64_t>& pair_counts() const { return hist_; }

  // Table: '#' comment lines (samples, N, r_max, bins, pair search), header
  //   r  g  n_r  pairs
  // and one row per bin (r = bin centre, pairs = raw count summed over samples).
  std::string to_tsv() const;

 private:
  RdfSpec spec_;
  double r_max_ = 0.0;
  bool r_max_capped_ = false;
  int samples_ = 0;
  int subset_samples_ = 0;
  std::size_t last_n_ = 0;
  double sum_pair_density_ = 0.0;  // sum over samples of the ideal-gas pairs per unit volume
  double sum_n_ = 0.0;             // sum over samples of 2 x pairs counted per centre pair (N or 2 K)
  double sum_centres_ = 0.0;       // sum over samples of the centres
  std::vector<std::uint64_t> hist_;
  std::vector<Vec3> pos_;          // scratch
  std::pair<double, bool> automatic_r_max(const Box& box, std::size_t n) const;  // r_max, capped
  struct Pending {
    bool ready = false;
    std::size_t n = 0;
    double r_max = 0.0;
    bool capped = false;
    PairCount count;
    double pair_density = 0.0;
    std::vector<std::uint64_t> hist;
  } pending_;
};

// Partial radial distribution functions g_ab(r) of a mixture, one per species pair a <= b, on
// the bins of a given r_max. Pairs are labelled by the species of both bodies while they are
// counted (the same search as pair_histogram, all pairs or a subset of centres). Normalisation:
// the ideal-gas pair density N_a (N_a - 1) / (2 V) for a = b, N_a N_b / V for a != b (all
// pairs); with K_a centres of species a: K_a (N_a - 1) / V and (K_a N_b + K_b N_a) / V.
class PartialRadialDistribution {
 public:
  PartialRadialDistribution(std::size_t species, int bins, double max_pairs = RdfSpec{}.max_pairs);
  // r_max <= half the shortest box edge (the driver takes the whole g(r)'s).
  void sample(double time, const State& state, const Box& box, double r_max);
  // As RadialDistribution::prepare/commit: prepare may throw and changes nothing.
  void prepare(double time, const State& state, const Box& box, double r_max);
  void commit() noexcept;
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
  double max_pairs_;
  double r_max_ = 0.0;
  int samples_ = 0;
  std::vector<double> density_;                  // per pair: sum over samples of its pair density
  std::vector<std::vector<std::uint64_t>> hist_;  // per pair
  struct Pending {
    bool ready = false;
    double r_max = 0.0;
    std::vector<double> density;
    std::vector<std::vector<std::uint64_t>> hist;
  } pending_;
};

// Nematic order of the body axes u_i = q_i * body_axis:
// Q = (1/N) sum_i (3 u_i u_i^T - I) / 2; S2 = its largest eigenvalue, director = its eigenvector
// (sign chosen so that the largest-magnitude component is positive).
struct NematicResult {
  double S2 = 0.0;
  Vec3 director = Vec3::UnitX();
  Vec3 eigenvalues = Vec3::Zero();  // ascending
};
NematicResult nematic_order(FieldView<Quat> orientations,
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
