// Time-correlation functions with multiple time origins: mean-squared displacement (and the
// self-diffusion coefficient from its long-time slope), orientational correlations
// C1(t) = < u(0).u(t) > and C2(t) = < P2(u(0).u(t)) > of the body x axis, the self intermediate
// scattering function F_self(q, t) and the non-Gaussian parameter alpha2(t).
//
// Read-only: the driver calls sample() on a synchronized state every `interval` of simulated
// time; the observer keeps its own copies of the origins. Definitions and the table format are
// in docs/observables.md.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "math/types.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

struct CorrelationSpec {
  // Simulated time between two calls of sample(); the unit of every lag. Must be > 0.
  double interval = 0.1;
  // A new time origin is taken every `origin_every` samples (1 = every sample). Must be >= 1.
  int origin_every = 10;
  // Longest lag, in samples: the table covers lags 0 .. max_lag_samples * interval. Must be >= 1.
  int max_lag_samples = 1000;
  // Upper bound on the number of origins alive at once (each stores 6 doubles per body). If
  // max_lag_samples / origin_every would need more, origin_every is raised to fit; see
  // effective_origin_every(). Must be >= 1.
  int max_origins = 64;
  // Lag grid. false: every lag 0, 1, ..., max_lag_samples. true: every lag up to 10, then
  // `lags_per_decade` log-spaced lags per decade up to max_lag_samples (always included).
  // A log grid only saves work (origins are updated at grid lags only), not memory.
  bool log_lags = false;
  int lags_per_decade = 10;
  // Target wave number |q| of F_self (in inverse length units). The q vectors used are the
  // box-compatible ones q = 2 pi (n_x/L_x, n_y/L_y, n_z/L_z) whose modulus is within
  // q_tolerance (relative) of the achievable modulus closest to q; see q_vectors().
  // Default 2 pi / 1: the first peak of S(q) for unit-diameter bodies is near 7. With
  // q_tolerance = 0 only the exact shell is used (in a cubic box, all n with the same n.n).
  double q = 2.0 * kPi;
  double q_tolerance = 0.01;
  // Most q vectors kept (those closest to the target modulus; q and -q count once since F_self
  // is even in q). The cost of one sample is (live origins) x N x (q vectors) cosines.
  int max_q_vectors = 24;
  // Body axis whose reorientation C1, C2 follow (body frame; normalised on use). Body x is the
  // symmetry axis of a spheroid with semi-axes [a, b, b].
  Vec3 body_axis = Vec3::UnitX();
  // Fit range of MSD = 6 D t + c, as fractions of the longest lag that has data.
  double fit_from = 0.5;
  double fit_to = 1.0;
};

// Least-squares line MSD(t) = 6 D t + intercept over [t_from, t_to].
struct DiffusionFit {
  double D = 0.0;
  double D_error = 0.0;    // standard error of the slope / 6 (from the fit residuals)
  double intercept = 0.0;
  double t_from = 0.0, t_to = 0.0;
  int points = 0;          // 0: no fit (fewer than 2 lags with data in the range)
};

class TimeCorrelations {
 public:
  explicit TimeCorrelations(const CorrelationSpec& spec);

  // Record the state at simulated time `time`. Every body must be at `time` (t[i] == time);
  // a body behind is streamed forward here without changing the state. Times must advance by
  // spec.interval between calls (a relative mismatch above 1e-6 throws std::invalid_argument),
  // and the number of bodies must not change. sample() = prepare() then commit().
  void sample(double time, const State& state, const Box& box);
  // The two halves of sample(), so that a driver can sample several observers all or nothing:
  // prepare() does the work (the q vectors at the first sample, the correlations of every live
  // origin), polls for interrupts and may throw (hb::Interrupted, std::invalid_argument)
  // without changing the observer; commit() applies the prepared sample and does not throw.
  // commit() without a pending sample does nothing.
  void prepare(double time, const State& state, const Box& box);
  void commit() noexcept;
  // Forget all origins and sums (e.g. at the end of equilibration).
  void reset();
  // Flat serialisation for checkpoints (exact doubles; includes the live origins, so about
  // 6 N doubles per origin). load() needs an object built from the same spec and throws
  // std::invalid_argument on a record that does not match it.
  std::vector<double> save() const;
  void load(const std::vector<double>& record);

  const CorrelationSpec& spec() const { return spec_; }
  int effective_origin_every() const { return origin_every_; }
  const std::vector<int>& lags() const { return lags_; }       // lag grid, in samples
  // q vectors of F_self (set at the first sample from the box) and their mean modulus.
  const std::vector<Vec3>& q_vectors() const { return qs_; }
  double q_used() const;
  // "shell" (the closest lattice shells, see lattice_q_vectors) or "random" (huge q L).
  const char* q_selection() const;

  // Per-lag results, index matching lags(); NaN where no origin has reached that lag.
  std::vector<double> times() const;
  std::vector<double> msd() const;
  std::vector<double> c1() const;
  std::vector<double> c2() const;
  std::vector<double> fself() const;
  std::vector<double> alpha2() const;
  // Number of (origin) averages behind each lag.
  const std::vector<std::int64_t>& samples() const { return count_; }
  DiffusionFit diffusion() const;

  // Table: '#' comment lines (spec, q, D and its fit range), then the header
  //   time  msd  msd_samples  c2  fself  c1  alpha2
  // and one row per lag with data. Full precision (%.10g).
  std::string to_tsv() const;

 private:
  struct Origin {
    std::int64_t index = 0;  // sample index at which it was taken
    std::vector<Vec3> r;     // unwrapped positions
    std::vector<Vec3> u;     // lab-frame body axis
  };
  struct Term {  // one origin's contribution to lag slot j
    int j;
    double s2, s4, c1, c2, fs;
  };
  Term correlate(const std::vector<Vec3>& r0, const std::vector<Vec3>& u0, int j,
                 const std::vector<Vec3>& qs) const;
  std::vector<double> ratio(const std::vector<double>& sum) const;

  CorrelationSpec spec_;
  int origin_every_ = 1;
  std::vector<int> lags_;
  std::vector<int> slot_;            // lag -> index into lags_, -1 if not on the grid
  std::vector<Vec3> qs_;
  Vec3 box_L_ = Vec3::Zero();
  std::vector<Origin> origins_;      // ring of live origins
  std::int64_t next_sample_ = 0;
  double first_time_ = 0.0;
  std::size_t n_ = 0;
  // Per-lag sums over origins of the particle averages.
  std::vector<double> sum_msd_, sum_r4_, sum_c1_, sum_c2_, sum_fs_;
  std::vector<std::int64_t> count_;
  std::vector<Vec3> r_now_, u_now_;  // scratch
  struct Pending {
    bool ready = false;
    bool first = false;      // the first sample: sets first_time_, n_ (and the q vectors)
    double first_time = 0.0;
    std::size_t n = 0;
    bool new_q = false;
    std::vector<Vec3> qs;
    Vec3 box_L = Vec3::Zero();
    bool new_origin = false;
    std::size_t slot = 0;
    std::int64_t index = 0;
    std::vector<Vec3> r, u;  // the new origin (swapped into the ring by commit)
    std::vector<Term> terms;
  } pending_;
};

// The q vectors of F_self for a box of edges L: lattice vectors k = 2 pi (n_x / L_x, n_y / L_y,
// n_z / L_z), one of each +-k pair (first nonzero component of n positive). Shell selection:
// the achievable modulus closest to `q` (first in (n_x, n_y, n_z) order on ties), then the
// vectors whose modulus is within `tolerance` (relative) of it, closest first (ties in
// (n_x, n_y, n_z) order), at most `max_vectors`. The shells are enumerated directly (the
// (n_x, n_y) columns of the shell, widened until max_vectors are found), so the time is
// O((q L)^2) and the memory O(max_vectors). When the shell has more than
// kMaxQColumns (n_x, n_y) columns the vectors are instead the lattice points nearest to
// max_vectors directions drawn with a fixed seed (each within sqrt(3)/2 of a lattice spacing of
// |q|; `tolerance` is not used). Polls for interrupts. Throws std::invalid_argument when no
// vector fits (q L too large for int indices).
constexpr double kMaxQColumns = 1e7;
struct QSelection {
  std::vector<Vec3> q;
  bool random = false;
};
QSelection lattice_q_vectors(const Vec3& L, double q, double tolerance, int max_vectors);
bool lattice_q_is_random(const Vec3& L, double q, double tolerance);

// Analytic C2(t) = < P2(u(0).u(t)) > of a free spherical top (moment of inertia I, constant
// angular velocity) with Maxwell-distributed angular velocity, <w_k^2> = kT/I per component,
// and isotropic u(0) independent of w (derivation in docs/observables.md). With s = (kT/I) t^2:
//   C2(t) = [1 + 2 (1 - s) exp(-s/2) + 2 (1 - 4 s) exp(-2 s)] / 5
// Short times: 1 - 3 (kT/I) t^2; long times: 1/5.
inline double c2_free_rotor(double t, double kT_over_I) {
  const double s = kT_over_I * t * t;
  return (1.0 + 2.0 * (1.0 - s) * std::exp(-0.5 * s) + 2.0 * (1.0 - 4.0 * s) * std::exp(-2.0 * s)) / 5.0;
}

// Same for C1(t) = < u(0).u(t) >: [1 + 2 (1 - s) exp(-s/2)] / 3.
inline double c1_free_rotor(double t, double kT_over_I) {
  const double s = kT_over_I * t * t;
  return (1.0 + 2.0 * (1.0 - s) * std::exp(-0.5 * s)) / 3.0;
}

}  // namespace hb
