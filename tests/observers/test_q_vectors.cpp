// The F_self q vectors: the same choice as the former whole-window enumeration (kept here as the
// slow twin) where that one worked, bounded time and memory where it did not (a box of edge
// 1500 with q = 2 pi used to list ~4e8 candidates: std::bad_alloc), and interruptible.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>

#include "core/interrupt.hpp"
#include "observers/correlations.hpp"

using namespace hb;

namespace {

// The former selection, verbatim in behaviour: every lattice vector in a window around the
// target, the closest modulus, then the tolerance shell sorted by distance (stable in
// (nx, ny, nz) order), truncated. Memory grows like (q L)^3.
std::vector<Vec3> whole_window_twin(const Vec3& L, double target, double tol, int max_vectors) {
  const Vec3 dq = (2.0 * kPi) * L.cwiseInverse();
  const double dq_max = dq.maxCoeff();
  const double w = dq_max + 2.0 * tol * (target + dq_max);
  const double qlo = std::max(0.0, target - w), qhi = target + w;
  struct Cand {
    Vec3 q;
    double norm;
  };
  std::vector<Cand> cands;
  const int nx_max = int(std::ceil(qhi / dq.x())), ny_max = int(std::ceil(qhi / dq.y()));
  for (int nx = 0; nx <= nx_max; ++nx)
    for (int ny = (nx == 0 ? 0 : -ny_max); ny <= ny_max; ++ny) {
      const double qxy2 = sqr(nx * dq.x()) + sqr(ny * dq.y());
      if (qxy2 > qhi * qhi) continue;
      const int nz_hi = int(std::floor(std::sqrt(qhi * qhi - qxy2) / dq.z()));
      const double rest_lo = qlo * qlo - qxy2;
      const int nz_lo_abs = rest_lo > 0.0 ? int(std::ceil(std::sqrt(rest_lo) / dq.z())) : 0;
      for (int nz = -nz_hi; nz <= nz_hi; ++nz) {
        if (std::abs(nz) < nz_lo_abs) continue;
        if (nx == 0 && ny == 0 && nz <= 0) continue;
        const Vec3 q(nx * dq.x(), ny * dq.y(), nz * dq.z());
        cands.push_back({q, q.norm()});
      }
    }
  double best = cands.front().norm;
  for (const auto& c : cands)
    if (std::abs(c.norm - target) < std::abs(best - target)) best = c.norm;
  const double keep = (tol + 1e-12) * best;
  std::erase_if(cands, [&](const Cand& c) { return std::abs(c.norm - best) > keep; });
  std::stable_sort(cands.begin(), cands.end(),
                   [&](const Cand& a, const Cand& b) { return std::abs(a.norm - best) < std::abs(b.norm - best); });
  if (cands.size() > std::size_t(max_vectors)) cands.resize(std::size_t(max_vectors));
  std::vector<Vec3> out;
  for (const auto& c : cands) out.push_back(c.q);
  return out;
}

void expect_lattice_half_space(const Vec3& L, const std::vector<Vec3>& qs) {
  std::vector<Eigen::Vector3d> ns;
  for (const Vec3& q : qs) {
    Eigen::Vector3d n;
    for (int k = 0; k < 3; ++k) {
      n[k] = q[k] * L[k] / (2.0 * kPi);
      ASSERT_NEAR(n[k], std::round(n[k]), 1e-6 * std::max(1.0, std::abs(n[k])));
      n[k] = std::round(n[k]);
    }
    const int first = n[0] != 0.0 ? 0 : (n[1] != 0.0 ? 1 : 2);
    EXPECT_GT(n[first], 0.0) << "not one of each +-q pair";
    EXPECT_EQ(std::find(ns.begin(), ns.end(), n), ns.end()) << "duplicate " << n.transpose();
    ns.push_back(n);
  }
}

}  // namespace

TEST(QVectors, SameChoiceAsTheWholeWindowEnumeration) {
  struct Case {
    Vec3 L;
    double q, tol;
    int max_vectors;
  };
  const std::vector<Case> cases = {
      {Vec3::Constant(10.0), 2 * kPi, 0.0, 24},   {Vec3::Constant(10.0), 2 * kPi, 0.01, 24},
      {Vec3(7, 9, 11), 5.0, 0.03, 24},             {Vec3(10, 12, 14), 2 * kPi, 0.01, 24},
      {Vec3(10, 12, 14), 7.1, 0.01, 200},          {Vec3::Constant(5.0), 2.0, 0.01, 24},
      {Vec3::Constant(20.0), 2 * kPi, 0.01, 24},   {Vec3::Constant(20.0), 2 * kPi, 0.01, 1000},
      {Vec3(3, 4, 30), 2 * kPi, 0.01, 24},         {Vec3(8.3, 8.3, 8.3), 0.5, 0.2, 5},
      {Vec3::Constant(60.0), 2 * kPi, 0.01, 24},   {Vec3(50, 61, 73), 2 * kPi, 0.02, 48},
      {Vec3::Constant(10.0), 1e-3, 0.01, 24},      {Vec3(4, 4, 4), 40.0, 0.0, 3},
  };
  for (const Case& c : cases) {
    const QSelection sel = lattice_q_vectors(c.L, c.q, c.tol, c.max_vectors);
    const auto twin = whole_window_twin(c.L, c.q, c.tol, c.max_vectors);
    EXPECT_FALSE(sel.random);
    ASSERT_EQ(sel.q.size(), twin.size()) << "L = " << c.L.transpose() << " q = " << c.q;
    for (std::size_t k = 0; k < twin.size(); ++k) EXPECT_EQ(sel.q[k], twin[k]) << "vector " << k;
  }
}

// Regression: bodies of size ~100 with the default q = 2 pi (box edge 1500) used to list every
// lattice vector within 2 % of |q| (~4e8 of them, 14 GB) before keeping 24: std::bad_alloc.
TEST(QVectors, LargeBoxesAreBoundedAndKeepTheClosestShell) {
  const Vec3 L(1500.0, 1600.0, 1700.0);
  const QSelection sel = lattice_q_vectors(L, 2 * kPi, 0.01, 24);
  EXPECT_FALSE(sel.random);
  ASSERT_EQ(sel.q.size(), 24u);
  expect_lattice_half_space(L, sel.q);
  // Closest first: the distances to the first modulus never decrease, and all are tiny compared
  // with the tolerance (the shell holds ~1e9 vectors within 1 %).
  const double best = sel.q.front().norm();
  EXPECT_NEAR(best, 2 * kPi, 2 * kPi / 1500.0);
  double last = 0.0;
  for (const Vec3& q : sel.q) {
    const double d = std::abs(q.norm() - best);
    EXPECT_GE(d, last);
    last = d;
    EXPECT_LT(d, 1e-6 * best);
  }
  // The observer takes them, and says how.
  CorrelationSpec spec;
  spec.interval = 1.0;
  spec.max_lag_samples = 2;
  TimeCorrelations corr(spec);
  State s;
  s.resize(3);
  Box box;
  box.L = L;
  corr.sample(0.0, s, box);
  EXPECT_EQ(corr.q_vectors().size(), 24u);
  EXPECT_NE(corr.to_tsv().find("q_vectors=24 q_selection=shell"), std::string::npos);
}

TEST(QVectors, HugeBoxesDrawAFixedSetOfLatticeVectors) {
  const Vec3 L(1e5, 1.1e5, 0.9e5);
  EXPECT_TRUE(lattice_q_is_random(L, 2 * kPi, 0.01));
  const QSelection a = lattice_q_vectors(L, 2 * kPi, 0.01, 24), b = lattice_q_vectors(L, 2 * kPi, 0.01, 24);
  EXPECT_TRUE(a.random);
  ASSERT_EQ(a.q.size(), 24u);
  EXPECT_EQ(a.q, b.q);  // fixed seed
  expect_lattice_half_space(L, a.q);
  const double dq_max = 2 * kPi / 0.9e5;
  for (const Vec3& q : a.q) EXPECT_LE(std::abs(q.norm() - 2 * kPi), 0.87 * dq_max);
  // Directions spread over the sphere, not one axis: the mean of |q_z| / |q| is near 1/2.
  double mz = 0.0;
  for (const Vec3& q : a.q) mz += std::abs(q.z()) / q.norm() / 24.0;
  EXPECT_NEAR(mz, 0.5, 0.2);
}

TEST(QVectors, EnumerationHonoursStopRequests) {
  request_stop(SIGINT);
  EXPECT_THROW(lattice_q_vectors(Vec3::Constant(10.0), 2 * kPi, 0.01, 24), Interrupted);
  EXPECT_THROW(lattice_q_vectors(Vec3::Constant(1e5), 2 * kPi, 0.01, 24), Interrupted);
  clear_stop();
}

// A stop request inside a correlation sample leaves the observer as it was (checkpoints hold
// whole samples only); prepare + commit is sample.
TEST(Correlations, InterruptedSampleChangesNothing) {
  Box box;
  box.L = Vec3::Constant(12.0);
  State s;
  s.resize(9000);  // a 21^3 grid (partly filled), velocities from a smooth pseudo-random map
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double x = double(i);
    s.r[i] = (12.0 / 21.0) * Vec3(double(i % 21), double(i / 21 % 21), double(i / 441));
    s.v[i] = Vec3(std::sin(1.3 * x), std::cos(2.1 * x), std::sin(0.7 * x + 1.0));
  }
  CorrelationSpec spec;
  spec.interval = 0.1;
  spec.origin_every = 2;
  spec.max_lag_samples = 6;
  TimeCorrelations a(spec), b(spec);
  auto advance = [&](int k) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.advance_to(i, k * spec.interval);
      s.image[i] += box.wrap(s.r[i]);
    }
  };
  // Interrupted at the very first sample: no q vectors, no origin, no sample.
  request_stop(SIGTERM);
  EXPECT_THROW(a.sample(0.0, s, box), Interrupted);
  clear_stop();
  EXPECT_TRUE(a.q_vectors().empty());
  EXPECT_EQ(a.save(), b.save());
  for (int k = 0; k < 5; ++k) {
    advance(k);
    a.sample(k * spec.interval, s, box);
    b.sample(k * spec.interval, s, box);
  }
  advance(5);
  const auto before = a.save();
  request_stop(SIGTERM);
  EXPECT_THROW(a.sample(5 * spec.interval, s, box), Interrupted);
  clear_stop();
  EXPECT_EQ(a.save(), before);
  a.commit();  // nothing pending
  EXPECT_EQ(a.save(), before);
  // The retried sample gives what an uninterrupted observer has.
  a.prepare(5 * spec.interval, s, box);
  EXPECT_EQ(a.save(), before);
  a.commit();
  b.sample(5 * spec.interval, s, box);
  EXPECT_EQ(a.save(), b.save());
  EXPECT_EQ(a.to_tsv(), b.to_tsv());
}
