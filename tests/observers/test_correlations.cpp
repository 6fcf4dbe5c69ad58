#include <gtest/gtest.h>

#include <cmath>
#include <pcg_random.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

#include "observers/correlations.hpp"

using namespace hb;

namespace {

Quat random_quat(pcg32& rng) {
  std::normal_distribution<double> g;
  Quat q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q;
}

Vec3 gauss3(pcg32& rng, double sigma) {
  std::normal_distribution<double> g(0.0, sigma);
  return Vec3(g(rng), g(rng), g(rng));
}

// N free bodies: uniform positions, random orientations, Maxwell v (kT/m = v_var) and w (kT/I).
State free_bodies(std::size_t n, const Box& box, pcg32& rng, double v_var, double w_var) {
  State s;
  s.resize(n);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    s.r[i] = Vec3(u(rng), u(rng), u(rng)).cwiseProduct(box.L);
    s.q[i] = random_quat(rng);
    s.v[i] = gauss3(rng, std::sqrt(v_var));
    s.w[i] = gauss3(rng, std::sqrt(w_var));
  }
  return s;
}

// Free flight of every body to `time`, wrapping into the box and counting images as the engine does.
void stream(State& s, const Box& box, double time) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.advance_to(i, time);
    s.image[i] += box.wrap(s.r[i]);
  }
}

double p2(double x) { return 1.5 * x * x - 0.5; }

// Rotation of x by the angle |w| t about w (Rodrigues), independent of the quaternion code.
Vec3 rodrigues(const Vec3& x, const Vec3& w, double t) {
  const double wn = w.norm();
  if (wn == 0.0) return x;
  const Vec3 k = w / wn;
  const double th = wn * t;
  return x * std::cos(th) + k.cross(x) * std::sin(th) + k * k.dot(x) * (1.0 - std::cos(th));
}

}  // namespace

TEST(Correlations, BallisticMsdIsV2T2AndFselfIsExactAverage) {
  pcg32 rng(11);
  Box box;
  box.L = Vec3(8.0, 9.0, 10.0);
  State s = free_bodies(300, box, rng, 1.0, 0.0);
  CorrelationSpec spec;
  spec.interval = 0.25;
  spec.origin_every = 3;
  spec.max_lag_samples = 40;  // flights of up to 10 time units: many box crossings
  spec.q = 2.0;
  TimeCorrelations corr(spec);
  double v2 = 0.0;
  for (const auto& v : s.v) v2 += v.squaredNorm();
  v2 /= double(s.size());
  for (int k = 0; k < 100; ++k) {
    stream(s, box, k * spec.interval);
    corr.sample(k * spec.interval, s, box);
  }
  const auto t = corr.times();
  const auto msd = corr.msd(), c2 = corr.c2(), fs = corr.fself();
  const auto& qs = corr.q_vectors();
  ASSERT_FALSE(qs.empty());
  ASSERT_EQ(t.size(), 41u);
  for (std::size_t j = 0; j < t.size(); ++j) {
    EXPECT_NEAR(msd[j], v2 * t[j] * t[j], 1e-9 * (1.0 + v2 * t[j] * t[j])) << "lag " << j;
    EXPECT_NEAR(c2[j], 1.0, 1e-12);
    double f = 0.0;
    for (const auto& v : s.v)
      for (const auto& q : qs) f += std::cos(q.dot(v) * t[j]);
    f /= double(s.size() * qs.size());
    EXPECT_NEAR(fs[j], f, 1e-9) << "lag " << j;
    // Origins at samples 0, 3, ..., 99 - lag.
    EXPECT_EQ(corr.samples()[j], (99 - int(j)) / 3 + 1);
  }
}

TEST(Correlations, FselfOfMaxwellGasIsGaussian) {
  pcg32 rng(12);
  Box box;
  box.L = Vec3::Constant(10.0);
  const double kT = 1.3;  // m = 1
  State s = free_bodies(6000, box, rng, kT, 0.0);
  CorrelationSpec spec;
  spec.interval = 0.02;
  spec.origin_every = 5;
  spec.max_lag_samples = 30;
  spec.q = 2.0 * kPi;
  spec.q_tolerance = 0.0;  // the exact shell only
  TimeCorrelations corr(spec);
  for (int k = 0; k < 40; ++k) {
    stream(s, box, k * spec.interval);
    corr.sample(k * spec.interval, s, box);
  }
  const double q = corr.q_used();
  EXPECT_NEAR(q, 2.0 * kPi, 1e-12);
  EXPECT_EQ(corr.q_vectors().size(), 15u);  // n.n = 100 in a cubic box: 30 vectors, 15 up to sign
  const auto t = corr.times();
  const auto fs = corr.fself();
  double worst = 0.0;
  for (std::size_t j = 0; j < t.size(); ++j) {
    const double expect = std::exp(-q * q * kT * t[j] * t[j] / 2.0);
    worst = std::max(worst, std::abs(fs[j] - expect));
  }
  // Per-particle variance of cos is <= 1/2: sd of the mean <= sqrt(0.5 / 6000) = 0.009.
  EXPECT_LT(worst, 0.04);
  RecordProperty("fself_max_abs_deviation", std::to_string(worst));
}

TEST(Correlations, MultipleOriginsEqualBruteForce) {
  // Random walk with random rotations; the observer's averages against a direct double loop
  // over the stored trajectory. Linear and log lag grids, and an origin cap that forces
  // a coarser origin spacing.
  struct Case {
    bool log_lags;
    int origin_every, max_lag, max_origins;
  };
  for (const Case& c : {Case{false, 2, 17, 64}, Case{true, 1, 60, 64}, Case{false, 1, 20, 5}}) {
    pcg32 rng(13);
    Box box;
    box.L = Vec3(5.0, 6.0, 7.0);
    const std::size_t n = 40;
    State s = free_bodies(n, box, rng, 0.0, 0.0);
    CorrelationSpec spec;
    spec.interval = 0.5;
    spec.origin_every = c.origin_every;
    spec.max_lag_samples = c.max_lag;
    spec.max_origins = c.max_origins;
    spec.log_lags = c.log_lags;
    spec.lags_per_decade = 7;
    spec.q = 3.0;
    spec.body_axis = Vec3(0.0, 1.0, 1.0);
    TimeCorrelations corr(spec);
    const int every = corr.effective_origin_every();
    if (c.max_origins == 5) {
      EXPECT_EQ(every, 5);  // ceil(20 / 4)
    }
    const int samples = 90;
    std::vector<std::vector<Vec3>> R, U;  // unwrapped positions and axes per sample
    std::vector<Vec3> unwrapped(s.r);
    const Vec3 axis = spec.body_axis.normalized();
    for (int k = 0; k < samples; ++k) {
      if (k > 0) {
        for (std::size_t i = 0; i < n; ++i) {
          const Vec3 d = gauss3(rng, 0.4);
          unwrapped[i] += d;
          s.r[i] += d;
          s.image[i] += box.wrap(s.r[i]);
          s.q[i] = (Quat(Eigen::AngleAxisd(0.3, gauss3(rng, 1.0).normalized())) * s.q[i]).normalized();
        }
      }
      for (std::size_t i = 0; i < n; ++i) s.t[i] = k * spec.interval;
      corr.sample(k * spec.interval, s, box);
      R.push_back(unwrapped);
      std::vector<Vec3> u(n);
      for (std::size_t i = 0; i < n; ++i) u[i] = s.q[i] * axis;
      U.push_back(u);
    }
    const auto& lags = corr.lags();
    if (c.log_lags) {
      EXPECT_LT(lags.size(), 30u);
      EXPECT_EQ(lags.back(), 60);
    }
    const auto msd = corr.msd(), c1 = corr.c1(), c2 = corr.c2(), fs = corr.fself(), a2 = corr.alpha2();
    const auto& qs = corr.q_vectors();
    for (std::size_t j = 0; j < lags.size(); ++j) {
      const int lag = lags[j];
      double sm = 0, s4 = 0, sc1 = 0, sc2 = 0, sf = 0;
      int origins = 0;
      for (int k0 = 0; k0 + lag < samples; k0 += every) {
        ++origins;
        for (std::size_t i = 0; i < n; ++i) {
          const Vec3 d = R[k0 + lag][i] - R[k0][i];
          sm += d.squaredNorm() / n;
          s4 += sqr(d.squaredNorm()) / n;
          const double x = U[k0][i].dot(U[k0 + lag][i]);
          sc1 += x / n;
          sc2 += p2(x) / n;
          for (const auto& q : qs) sf += std::cos(q.dot(d)) / double(n * qs.size());
        }
      }
      ASSERT_EQ(corr.samples()[j], origins) << "lag " << lag;
      ASSERT_GT(origins, 0);
      EXPECT_NEAR(msd[j], sm / origins, 1e-9 * (1 + sm / origins)) << "lag " << lag;
      EXPECT_NEAR(c1[j], sc1 / origins, 1e-10) << "lag " << lag;
      EXPECT_NEAR(c2[j], sc2 / origins, 1e-10) << "lag " << lag;
      EXPECT_NEAR(fs[j], sf / origins, 1e-10) << "lag " << lag;
      if (lag > 0) {
        const double m2 = sm / origins, m4 = s4 / origins;
        EXPECT_NEAR(a2[j], 3.0 * m4 / (5.0 * m2 * m2) - 1.0, 1e-8) << "lag " << lag;
      }
    }
  }
}

TEST(Correlations, FreeRotorWithCommonOmegaMatchesRotationAverage) {
  // Every body spins with the same w: C2(t) = mean_i P2(c_i^2 + (1 - c_i^2) cos(|w| t)) with
  // c_i = u_i(0).w/|w|, and for isotropic u(0) the average (1 + 2 cos th + 2 cos 2 th) / 5.
  pcg32 rng(14);
  Box box;
  box.L = Vec3::Constant(20.0);
  State s = free_bodies(20000, box, rng, 0.0, 0.0);
  const Vec3 w(0.7, -1.1, 0.4);
  for (auto& wi : s.w) wi = w;
  std::vector<double> c0(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) c0[i] = (s.q[i] * Vec3::UnitX()).dot(w.normalized());
  CorrelationSpec spec;
  spec.interval = 0.1;
  spec.origin_every = 1000;  // one origin
  spec.max_lag_samples = 40;
  TimeCorrelations corr(spec);
  for (int k = 0; k <= 40; ++k) {
    stream(s, box, k * spec.interval);
    corr.sample(k * spec.interval, s, box);
  }
  const auto t = corr.times();
  const auto c2 = corr.c2();
  for (std::size_t j = 0; j < t.size(); ++j) {
    const double th = w.norm() * t[j];
    double exact = 0.0;
    for (double c : c0) exact += p2(c * c + (1.0 - c * c) * std::cos(th));
    exact /= double(c0.size());
    EXPECT_NEAR(c2[j], exact, 1e-9) << "t " << t[j];
    EXPECT_NEAR(c2[j], (1.0 + 2.0 * std::cos(th) + 2.0 * std::cos(2.0 * th)) / 5.0, 0.02) << "t " << t[j];
  }
}

TEST(Correlations, FreeRotorFormulaLimits) {
  const double a = 2.5;
  EXPECT_DOUBLE_EQ(c2_free_rotor(0.0, a), 1.0);
  EXPECT_DOUBLE_EQ(c1_free_rotor(0.0, a), 1.0);
  EXPECT_NEAR(c2_free_rotor(50.0, a), 0.2, 1e-12);
  EXPECT_NEAR(c1_free_rotor(50.0, a), 1.0 / 3.0, 1e-12);
  const double t = 1e-3;  // 1 - 3 (kT/I) t^2 and 1 - (kT/I) t^2
  EXPECT_NEAR(c2_free_rotor(t, a), 1.0 - 3.0 * a * t * t, 1e-10);
  EXPECT_NEAR(c1_free_rotor(t, a), 1.0 - a * t * t, 1e-10);
}

TEST(Correlations, FreeRotorFormulaMatchesMonteCarlo) {
  // Isotropic u(0), Gaussian w with <w_k^2> = kT/I, u(t) by Rodrigues' formula.
  pcg32 rng(15);
  const double kT_over_I = 2.5;
  const int m = 200000;
  const std::vector<double> ts = {0.1, 0.3, 0.5, 0.8, 1.2, 2.0, 4.0};
  std::vector<double> s1(ts.size(), 0.0), s2(ts.size(), 0.0);
  for (int k = 0; k < m; ++k) {
    const Vec3 u = gauss3(rng, 1.0).normalized();
    const Vec3 w = gauss3(rng, std::sqrt(kT_over_I));
    for (std::size_t j = 0; j < ts.size(); ++j) {
      const double x = u.dot(rodrigues(u, w, ts[j]));
      s1[j] += x;
      s2[j] += p2(x);
    }
  }
  double worst = 0.0;
  for (std::size_t j = 0; j < ts.size(); ++j)
    worst = std::max(worst, std::abs(s2[j] / m - c2_free_rotor(ts[j], kT_over_I)));
  RecordProperty("c2_mc_max_abs_deviation", std::to_string(worst));
  for (std::size_t j = 0; j < ts.size(); ++j) {
    // sd of the mean <= 1/sqrt(m) = 0.0022
    EXPECT_NEAR(s2[j] / m, c2_free_rotor(ts[j], kT_over_I), 0.008) << "t " << ts[j];
    EXPECT_NEAR(s1[j] / m, c1_free_rotor(ts[j], kT_over_I), 0.008) << "t " << ts[j];
  }
}

TEST(Correlations, ObserverOnMaxwellRotorsFollowsFormula) {
  pcg32 rng(16);
  Box box;
  box.L = Vec3::Constant(15.0);
  const double kT_over_I = 0.8;
  State s = free_bodies(8000, box, rng, 1.0, kT_over_I);
  CorrelationSpec spec;
  spec.interval = 0.1;
  spec.origin_every = 10;
  spec.max_lag_samples = 40;
  TimeCorrelations corr(spec);
  for (int k = 0; k < 60; ++k) {
    stream(s, box, k * spec.interval);
    corr.sample(k * spec.interval, s, box);
  }
  const auto t = corr.times();
  const auto c1 = corr.c1(), c2 = corr.c2();
  double worst = 0.0;
  for (std::size_t j = 0; j < t.size(); ++j) worst = std::max(worst, std::abs(c2[j] - c2_free_rotor(t[j], kT_over_I)));
  RecordProperty("c2_observer_max_abs_deviation", std::to_string(worst));
  for (std::size_t j = 0; j < t.size(); ++j) {
    EXPECT_NEAR(c2[j], c2_free_rotor(t[j], kT_over_I), 0.03) << "t " << t[j];
    EXPECT_NEAR(c1[j], c1_free_rotor(t[j], kT_over_I), 0.03) << "t " << t[j];
  }
}

TEST(Correlations, DiffusionFitOfRandomWalk) {
  pcg32 rng(17);
  Box box;
  box.L = Vec3::Constant(10.0);
  const std::size_t n = 2000;
  State s = free_bodies(n, box, rng, 0.0, 0.0);
  const double D = 0.05, dt = 0.2;
  CorrelationSpec spec;
  spec.interval = dt;
  spec.origin_every = 5;
  spec.max_lag_samples = 100;
  spec.fit_from = 0.25;
  spec.max_q_vectors = 1;  // F_self is not under test here; keeps the test fast
  TimeCorrelations corr(spec);
  for (int k = 0; k < 400; ++k) {
    if (k > 0)
      for (std::size_t i = 0; i < n; ++i) {
        s.r[i] += gauss3(rng, std::sqrt(2.0 * D * dt));
        s.image[i] += box.wrap(s.r[i]);
      }
    for (auto& ti : s.t) ti = k * dt;
    corr.sample(k * dt, s, box);
  }
  const DiffusionFit fit = corr.diffusion();
  EXPECT_GT(fit.points, 50);
  EXPECT_NEAR(fit.t_from, 0.25 * 100 * dt, 1e-12);
  EXPECT_NEAR(fit.t_to, 100 * dt, 1e-12);
  EXPECT_NEAR(fit.D, D, 0.03 * D);
  RecordProperty("D_fit", std::to_string(fit.D) + " +- " + std::to_string(fit.D_error));
  EXPECT_LT(fit.D_error, 0.03 * D);
  // Gaussian displacements: alpha2 ~ 0.
  const auto a2 = corr.alpha2();
  EXPECT_NEAR(a2[50], 0.0, 0.05);
}

TEST(Correlations, QVectorsFitTheBox) {
  Box box;
  box.L = Vec3(7.0, 9.0, 11.0);
  CorrelationSpec spec;
  spec.q = 5.0;
  spec.q_tolerance = 0.03;
  TimeCorrelations corr(spec);
  pcg32 rng(18);
  State s = free_bodies(5, box, rng, 1.0, 1.0);
  corr.sample(0.0, s, box);
  const auto& qs = corr.q_vectors();
  ASSERT_FALSE(qs.empty());
  const double q = corr.q_used();
  EXPECT_NEAR(q, 5.0, 2.0 * kPi / 7.0);
  for (std::size_t a = 0; a < qs.size(); ++a) {
    EXPECT_NEAR(qs[a].norm(), q, 0.06 * q);
    for (int k = 0; k < 3; ++k) {  // on the reciprocal lattice
      const double n = qs[a][k] * box.L[k] / (2.0 * kPi);
      EXPECT_NEAR(n, std::round(n), 1e-9);
    }
    for (std::size_t b = 0; b < qs.size(); ++b)
      if (a != b) {
        EXPECT_GT((qs[a] + qs[b]).norm(), 1e-9) << "q and -q both kept";
      }
  }
}

TEST(Correlations, RejectsBadSpecAndIrregularSampling) {
  CorrelationSpec bad;
  bad.interval = 0.0;
  EXPECT_THROW(TimeCorrelations{bad}, std::invalid_argument);
  bad = {};
  bad.origin_every = 0;
  EXPECT_THROW(TimeCorrelations{bad}, std::invalid_argument);
  bad = {};
  bad.fit_from = 0.9;
  bad.fit_to = 0.5;
  EXPECT_THROW(TimeCorrelations{bad}, std::invalid_argument);

  CorrelationSpec spec;
  spec.interval = 0.5;
  TimeCorrelations corr(spec);
  Box box;
  box.L = Vec3::Constant(5.0);
  pcg32 rng(19);
  State s = free_bodies(10, box, rng, 1.0, 1.0);
  corr.sample(1.0, s, box);
  for (auto& t : s.t) t = 1.7;
  EXPECT_THROW(corr.sample(1.7, s, box), std::invalid_argument);
}

TEST(Correlations, TsvTableHasHeaderAndOneRowPerLagWithData) {
  Box box;
  box.L = Vec3::Constant(6.0);
  pcg32 rng(20);
  State s = free_bodies(20, box, rng, 1.0, 1.0);
  CorrelationSpec spec;
  spec.interval = 0.1;
  spec.origin_every = 2;
  spec.max_lag_samples = 10;
  TimeCorrelations corr(spec);
  for (int k = 0; k < 6; ++k) {  // lags 0..5 reached
    stream(s, box, k * 0.1);
    corr.sample(k * 0.1, s, box);
  }
  std::istringstream in(corr.to_tsv());
  std::string line;
  int comments = 0, rows = 0;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.starts_with("#")) {
      ++comments;
      continue;
    }
    if (!header) {
      EXPECT_EQ(line, "time\tmsd\tmsd_samples\tc2\tfself\tc1\talpha2");
      header = true;
      continue;
    }
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), '\t'), 6) << line;
  }
  EXPECT_GE(comments, 3);
  EXPECT_TRUE(header);
  EXPECT_EQ(rows, 6);
}

TEST(Correlations, SaveLoadResumesExactly) {
  pcg32 rng(21);
  Box box;
  box.L = Vec3::Constant(7.0);
  State s = free_bodies(50, box, rng, 1.0, 1.0);
  CorrelationSpec spec;
  spec.interval = 0.1;
  spec.origin_every = 3;
  spec.max_lag_samples = 12;
  TimeCorrelations a(spec), b(spec);
  for (int k = 0; k < 30; ++k) {
    if (k == 17) {
      b.load(a.save());  // b resumes from a's checkpoint, mid-way through several origins
      EXPECT_EQ(b.save(), a.save());
    }
    stream(s, box, k * 0.1);
    a.sample(k * 0.1, s, box);
    if (k >= 17) b.sample(k * 0.1, s, box);
  }
  EXPECT_EQ(a.to_tsv(), b.to_tsv());
  std::vector<double> bad = a.save();
  bad.pop_back();
  EXPECT_THROW(b.load(bad), std::invalid_argument);
  CorrelationSpec other = spec;
  other.max_lag_samples = 13;
  TimeCorrelations c(other);
  EXPECT_THROW(c.load(a.save()), std::invalid_argument);
}
