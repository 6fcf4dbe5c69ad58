// Elastic collision of rigid bodies: conservation laws, reversal of the normal contact
// velocity, the hard-sphere limit, periodic images and the growth rule.
#include "collision/rigid.hpp"
#include "collision/sphere.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace hb {
namespace {

constexpr unsigned kSeed = 20240611u;  // logged in failure messages

Vec3 random_unit(std::mt19937_64& g) {
  std::normal_distribution<double> N(0.0, 1.0);
  Vec3 x(N(g), N(g), N(g));
  return x.normalized();
}

Quat random_quat(std::mt19937_64& g) {
  std::normal_distribution<double> N(0.0, 1.0);
  Quat q(N(g), N(g), N(g), N(g));
  q.normalize();
  return q;
}

// Support point of the ellipsoid with centre r, body->lab q and semi-axes s in direction d:
// x = r + M d / sqrt(d.M d), M = Q diag(s^2) Q^T.
Vec3 support(const Vec3& r, const Quat& q, const Vec3& s, const Vec3& d) {
  const Mat3 R = q.toRotationMatrix();
  const Mat3 M = R * s.cwiseProduct(s).asDiagonal() * R.transpose();
  return r + M * d / std::sqrt(d.dot(M * d));
}

// A random ellipsoid-like body: mass, semi-axes, and either the solid-ellipsoid inertia
// (diagonal in the body frame) or a random symmetric positive-definite body-frame tensor.
struct RandomBody {
  BodyState s;
  Vec3 axes;
  MassProperties mp;
};

RandomBody random_body(std::mt19937_64& g, bool general_tensor) {
  std::uniform_real_distribution<double> U(0.2, 3.0);
  std::normal_distribution<double> N(0.0, 1.0);
  RandomBody b;
  b.axes = Vec3(U(g), U(g), U(g));
  const double m = U(g);
  if (general_tensor) {
    // principal moments of a solid ellipsoid, expressed in a random body frame
    const Vec3 a2 = b.axes.cwiseProduct(b.axes);
    const Vec3 I(m * (a2.y() + a2.z()) / 5, m * (a2.x() + a2.z()) / 5, m * (a2.x() + a2.y()) / 5);
    const Mat3 P = random_quat(g).toRotationMatrix();
    b.mp = MassProperties::from_tensor(m, P * I.asDiagonal() * P.transpose());
  } else {
    b.mp = MassProperties::spherical_top(m, 0.4 * m * sqr(b.axes.minCoeff()));
  }
  b.s.q = random_quat(g);
  b.s.v = Vec3(N(g), N(g), N(g));
  b.s.w = Vec3(N(g), N(g), N(g));
  return b;
}

struct Totals {
  Vec3 P;
  Vec3 L;
  double E;
};

// Momentum, angular momentum about `about` and kinetic energy, with B at A.r + r_AB.
Totals totals(const RandomBody& A, const RandomBody& B, const Vec3& r_AB, const Vec3& about) {
  BodyState Bu = B.s;
  Bu.r = A.s.r + r_AB;
  return {A.mp.mass * A.s.v + B.mp.mass * B.s.v,
          angular_momentum(A.s, A.mp, about) + angular_momentum(Bu, B.mp, about),
          kinetic_energy(A.s, A.mp) + kinetic_energy(B.s, B.mp)};
}

// Scale of each conserved quantity, for relative errors.
Totals scales(const RandomBody& A, const RandomBody& B, const Vec3& r_AB, const Vec3& about) {
  BodyState Bu = B.s;
  Bu.r = A.s.r + r_AB;
  auto Lmag = [&](const RandomBody& X, const BodyState& s) {
    return X.mp.mass * (s.r - about).norm() * s.v.norm() + X.mp.apply_inertia(s.q, s.w).norm();
  };
  const double p = A.mp.mass * A.s.v.norm() + B.mp.mass * B.s.v.norm();
  const double l = Lmag(A, A.s) + Lmag(B, Bu);
  return {Vec3::Constant(p), Vec3::Constant(l), kinetic_energy(A.s, A.mp) + kinetic_energy(B.s, B.mp)};
}

// Places two random ellipsoids in contact along a random normal; B is stored in a shifted
// periodic image (B.r = A.r + r_AB + shift), which must not matter.
struct Pair {
  RandomBody A, B;
  Vec3 x_C, n, r_AB;
};

Pair random_pair(std::mt19937_64& g, bool general_tensor, const Vec3& shift) {
  Pair p;
  p.A = random_body(g, general_tensor);
  p.B = random_body(g, general_tensor);
  std::uniform_real_distribution<double> U(-5.0, 5.0);
  p.A.s.r = Vec3(U(g), U(g), U(g));
  p.n = random_unit(g);
  p.x_C = support(p.A.s.r, p.A.s.q, p.A.axes, p.n);
  const Vec3 rB = support(p.x_C, p.B.s.q, p.B.axes, -p.n);  // contact point of B, if B.r = x_C
  const Vec3 rB_unwrapped = p.x_C - (rB - p.x_C);           // centre of B touching A at x_C
  p.r_AB = rB_unwrapped - p.A.s.r;
  p.B.s.r = rB_unwrapped + shift;
  // make it a real collision: approaching at the contact
  if (contact_relative_velocity(p.A.s, p.B.s, p.x_C, p.r_AB).dot(p.n) < 0.0) {
    for (BodyState* s : {&p.A.s, &p.B.s}) {
      s->v = -s->v;
      s->w = -s->w;
    }
  }
  return p;
}

void run_conservation(bool general_tensor, const char* label) {
  std::mt19937_64 g(kSeed + (general_tensor ? 1 : 0));
  const Vec3 shift(10.0, -20.0, 30.0);  // B stored in another periodic image
  double maxP = 0, maxL0 = 0, maxLp = 0, maxE = 0, maxRev = 0, maxdE = 0;
  for (int i = 0; i < 10000; ++i) {
    Pair p = random_pair(g, general_tensor, shift);
    const Vec3 about(7.0, -3.0, 11.0);  // an arbitrary point
    const Totals t0 = totals(p.A, p.B, p.r_AB, Vec3::Zero());
    const Totals tp0 = totals(p.A, p.B, p.r_AB, about);
    const Totals sc = scales(p.A, p.B, p.r_AB, Vec3::Zero());
    const Totals scp = scales(p.A, p.B, p.r_AB, about);
    const double un = contact_relative_velocity(p.A.s, p.B.s, p.x_C, p.r_AB).dot(p.n);
    ASSERT_GT(un, 0.0);
    // scale of the contact velocities (u.n itself may be tiny: cancellation)
    const double uscale = p.A.s.v.norm() + p.B.s.v.norm() +
                          p.A.s.w.norm() * (p.x_C - p.A.s.r).norm() +
                          p.B.s.w.norm() * (p.x_C - p.A.s.r - p.r_AB).norm();

    const CollisionRecord rec = collide(p.A.s, p.A.mp, p.B.s, p.B.mp, p.x_C, p.n, p.r_AB);
    ASSERT_GT(rec.J, 0.0) << "seed " << kSeed << " case " << i;
    const Totals t1 = totals(p.A, p.B, p.r_AB, Vec3::Zero());
    const Totals tp1 = totals(p.A, p.B, p.r_AB, about);
    const double un1 = contact_relative_velocity(p.A.s, p.B.s, p.x_C, p.r_AB).dot(p.n);

    const double eP = (t1.P - t0.P).norm() / sc.P.x();
    const double eL0 = (t1.L - t0.L).norm() / sc.L.x();
    const double eLp = (tp1.L - tp0.L).norm() / scp.L.x();
    const double eE = std::abs(t1.E - t0.E) / sc.E;
    const double eRev = std::abs(un1 + un) / uscale;
    maxP = std::max(maxP, eP);
    maxL0 = std::max(maxL0, eL0);
    maxLp = std::max(maxLp, eLp);
    maxE = std::max(maxE, eE);
    maxRev = std::max(maxRev, eRev);
    maxdE = std::max(maxdE, std::abs(rec.dE) / sc.E);
    ASSERT_LT(eP, 1e-13) << "momentum, seed " << kSeed << " case " << i;
    ASSERT_LT(eL0, 1e-13) << "angular momentum (origin), seed " << kSeed << " case " << i;
    ASSERT_LT(eLp, 1e-13) << "angular momentum (point), seed " << kSeed << " case " << i;
    ASSERT_LT(eE, 1e-13) << "energy, seed " << kSeed << " case " << i;
    ASSERT_LT(eRev, 1e-13) << "u'.n = -u.n, seed " << kSeed << " case " << i;
    ASSERT_LT(std::abs(rec.dE) / sc.E, 1e-13);
    EXPECT_LT((rec.n - p.n).norm(), 1e-15);
    EXPECT_EQ(rec.r_AB, p.r_AB);
  }
  std::printf("[%s] max relative errors over 10000 collisions: P %.2e  L(origin) %.2e  "
              "L(point) %.2e  E %.2e  |u'.n+u.n|/|u| %.2e  |dE|/E %.2e\n",
              label, maxP, maxL0, maxLp, maxE, maxRev, maxdE);
}

TEST(RigidCollision, ConservesEverythingSphericalTop) { run_conservation(false, "spherical top"); }

TEST(RigidCollision, ConservesEverythingGeneralInertiaTensor) {
  run_conservation(true, "general tensor");
}

TEST(RigidCollision, PeriodicImageOfBDoesNotMatter) {
  std::mt19937_64 g(kSeed + 7);
  for (int i = 0; i < 100; ++i) {
    Pair p = random_pair(g, true, Vec3::Zero());
    Pair q = p;
    q.B.s.r += Vec3(-12.5, 0.0, 25.0);
    collide(p.A.s, p.A.mp, p.B.s, p.B.mp, p.x_C, p.n, p.r_AB);
    collide(q.A.s, q.A.mp, q.B.s, q.B.mp, q.x_C, q.n, q.r_AB);
    EXPECT_EQ(p.A.s.v, q.A.s.v);
    EXPECT_EQ(p.A.s.w, q.A.s.w);
    EXPECT_EQ(p.B.s.v, q.B.s.v);
    EXPECT_EQ(p.B.s.w, q.B.s.w);
  }
}

TEST(RigidCollision, SwappingTheBodiesGivesTheSameResult) {
  std::mt19937_64 g(kSeed + 8);
  for (int i = 0; i < 100; ++i) {
    Pair p = random_pair(g, true, Vec3::Zero());
    Pair q = p;
    const CollisionRecord r1 = collide(p.A.s, p.A.mp, p.B.s, p.B.mp, p.x_C, p.n, p.r_AB);
    // B as the first body: contact point in B's image, normal and separation reversed
    const CollisionRecord r2 = collide(q.B.s, q.B.mp, q.A.s, q.A.mp, q.x_C, -q.n, -q.r_AB);
    EXPECT_NEAR(r1.J, r2.J, 1e-13 * r1.J);
    EXPECT_LT((p.A.s.v - q.A.s.v).norm(), 1e-12 * (1 + p.A.s.v.norm()));
    EXPECT_LT((p.B.s.w - q.B.s.w).norm(), 1e-12 * (1 + p.B.s.w.norm()));
  }
}

TEST(RigidCollision, SphereCaseIsTheHardSphereRuleAndKeepsSpins) {
  std::mt19937_64 g(kSeed + 2);
  std::uniform_real_distribution<double> U(0.3, 2.0);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const double RA = U(g), RB = U(g), mA = U(g), mB = U(g);
    BodyState A, B;
    A.r = Vec3(N(g), N(g), N(g));
    const Vec3 n = random_unit(g);
    B.r = A.r + (RA + RB) * n;
    A.v = Vec3(N(g), N(g), N(g));
    B.v = Vec3(N(g), N(g), N(g));
    A.w = Vec3(N(g), N(g), N(g));
    B.w = Vec3(N(g), N(g), N(g));
    A.q = random_quat(g);
    B.q = random_quat(g);
    if ((A.v - B.v).dot(n) < 0) std::swap(A.v, B.v);
    if ((A.v - B.v).dot(n) <= 0) continue;
    const Vec3 vA0 = A.v, vB0 = B.v, wA0 = A.w, wB0 = B.w;
    const auto pA = MassProperties::spherical_top(mA, 0.4 * mA * RA * RA);
    const auto pB = MassProperties::spherical_top(mB, 0.4 * mB * RB * RB);
    const Vec3 x_C = A.r + RA * n;
    const CollisionRecord rec = collide(A, pA, B, pB, x_C, n, B.r - A.r);
    // hard spheres: J = 2 mu (v_A - v_B).n, mu the reduced mass
    const double mu = mA * mB / (mA + mB);
    const double J = 2 * mu * (vA0 - vB0).dot(n);
    // J suffers the cancellation in (v_A - v_B).n: compare on the scale of the momenta
    EXPECT_NEAR(rec.J, J, 1e-14 * mu * (vA0.norm() + vB0.norm()));
    EXPECT_LT((A.v - (vA0 - J / mA * n)).norm(), 1e-14 * (1 + vA0.norm()));
    EXPECT_LT((B.v - (vB0 + J / mB * n)).norm(), 1e-14 * (1 + vB0.norm()));
    // the lever arm is parallel to n: rA x n is ~1e-16 and the spins barely move
    EXPECT_LT((A.w - wA0).norm(), 1e-14 * (1 + wA0.norm()));
    EXPECT_LT((B.w - wB0).norm(), 1e-14 * (1 + wB0.norm()));
  }
}

// The rigid-body rule with the contact on the line of centres agrees with the project's
// hard-sphere fast path (collision/sphere.hpp), with and without growth.
TEST(RigidCollision, AgreesWithTheHardSphereFastPath) {
  std::mt19937_64 g(kSeed + 9);
  std::uniform_real_distribution<double> U(0.3, 2.0), G(0.0, 0.5);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const double RA = U(g), RB = U(g), mA = U(g), mB = U(g), grow = (i % 2) ? G(g) : 0.0;
    BodyState A, B;
    const Vec3 n = random_unit(g);
    B.r = A.r + (RA + RB) * n;
    A.v = Vec3(N(g), N(g), N(g));
    B.v = Vec3(N(g), N(g), N(g));
    if ((A.v - B.v).dot(n) + grow <= 0) std::swap(A.v, B.v);
    if ((A.v - B.v).dot(n) + grow <= 0) continue;
    Vec3 vA = A.v, vB = B.v;
    const double J = collide_spheres(vA, vB, n, 1.0 / mA, 1.0 / mB, grow);
    const CollisionRecord rec =
        collide(A, MassProperties::spherical_top(mA, 0.4 * mA * RA * RA), B,
                MassProperties::spherical_top(mB, 0.4 * mB * RB * RB), A.r + RA * n, n,
                B.r - A.r, grow);
    EXPECT_NEAR(rec.J, J, 1e-14 * (mA + mB) * (vA.norm() + vB.norm() + 1));
    EXPECT_LT((A.v - vA).norm(), 1e-14 * (1 + vA.norm()));
    EXPECT_LT((B.v - vB).norm(), 1e-14 * (1 + vB.norm()));
  }
}

TEST(RigidCollision, ExactlyCollinearLeverArmLeavesSpinsBitIdentical) {
  BodyState A, B;
  B.r = Vec3(2.0, 0.0, 0.0);
  A.v = Vec3(1.0, 0.3, 0.0);
  A.w = Vec3(0.1, 0.2, 0.3);
  B.w = Vec3(-0.4, 0.5, 0.6);
  const auto p = MassProperties::spherical_top(1.0, 0.4);
  const Vec3 wA0 = A.w, wB0 = B.w;
  const CollisionRecord rec = collide(A, p, B, p, Vec3(1, 0, 0), Vec3(1, 0, 0), B.r - A.r);
  EXPECT_DOUBLE_EQ(rec.J, 1.0);
  EXPECT_EQ(A.w, wA0);
  EXPECT_EQ(B.w, wB0);
  EXPECT_EQ(A.v, Vec3(0.0, 0.3, 0.0));
  EXPECT_EQ(B.v, Vec3(1.0, 0.0, 0.0));
}

TEST(RigidCollision, NotApproachingMeansNoImpulse) {
  std::mt19937_64 g(kSeed + 3);
  Pair p = random_pair(g, true, Vec3::Zero());
  for (BodyState* s : {&p.A.s, &p.B.s}) {  // reverse: now separating
    s->v = -s->v;
    s->w = -s->w;
  }
  const BodyState A0 = p.A.s, B0 = p.B.s;
  const CollisionRecord rec = collide(p.A.s, p.A.mp, p.B.s, p.B.mp, p.x_C, p.n, p.r_AB);
  EXPECT_EQ(rec.J, 0.0);
  EXPECT_EQ(rec.dE, 0.0);
  EXPECT_EQ(p.A.s.v, A0.v);
  EXPECT_EQ(p.B.s.w, B0.w);
}

TEST(RigidCollision, GrowthReversesTheGapRateAndAddsJTimesGrow) {
  std::mt19937_64 g(kSeed + 4);
  std::uniform_real_distribution<double> U(0.0, 0.5);
  double maxRev = 0, maxdE = 0;
  for (int i = 0; i < 2000; ++i) {
    Pair p = random_pair(g, i % 2 == 0, Vec3::Zero());
    const double grow = U(g);
    const Vec3 about(1.0, 2.0, 3.0);
    const Totals t0 = totals(p.A, p.B, p.r_AB, about);
    const Totals sc = scales(p.A, p.B, p.r_AB, about);
    const double un = contact_relative_velocity(p.A.s, p.B.s, p.x_C, p.r_AB).dot(p.n);
    const CollisionRecord rec = collide(p.A.s, p.A.mp, p.B.s, p.B.mp, p.x_C, p.n, p.r_AB, grow);
    const Totals t1 = totals(p.A, p.B, p.r_AB, about);
    const double un1 = contact_relative_velocity(p.A.s, p.B.s, p.x_C, p.r_AB).dot(p.n);
    // documented rule: u'.n = -u.n - 2 grow (the gap opens as fast as it closed)
    const double rev = std::abs(un1 - (-un - 2 * grow)) / (un + grow);
    maxRev = std::max(maxRev, rev);
    ASSERT_LT(rev, 1e-11) << "seed " << kSeed + 4 << " case " << i;
    EXPECT_GT(-un1, grow);  // rigid separation faster than the growth rate
    // momentum and angular momentum still conserved; energy rises by exactly J*grow
    EXPECT_LT((t1.P - t0.P).norm(), 1e-13 * sc.P.x());
    EXPECT_LT((t1.L - t0.L).norm(), 1e-13 * sc.L.x());
    const double dE = t1.E - t0.E;
    maxdE = std::max(maxdE, std::abs(dE - rec.J * grow) / sc.E);
    EXPECT_NEAR(dE, rec.J * grow, 1e-13 * sc.E);
    EXPECT_NEAR(rec.dE, rec.J * grow, 1e-13 * sc.E);
  }
  std::printf("[growth] max |u'.n - (-u.n - 2g)|/(u.n+g) %.2e  max |dE - J g|/E %.2e\n", maxRev,
              maxdE);
}

TEST(RigidCollision, GrowthCollidesEvenWhenRigidlySeparatingSlowly) {
  // u.n = -0.1 (rigidly separating), grow = 0.3: the gap still closes at 0.2 -> collision.
  BodyState A, B;
  B.r = Vec3(2.0, 0.0, 0.0);
  B.v = Vec3(0.1, 0.0, 0.0);
  const auto p = MassProperties::spherical_top(1.0, 0.4);
  const CollisionRecord rec = collide(A, p, B, p, Vec3(1, 0, 0), Vec3(1, 0, 0), B.r - A.r, 0.3);
  // J = 2 (u.n + g) / (1/m + 1/m) = 0.2
  EXPECT_NEAR(rec.J, 0.2, 1e-15);
  const double un1 = (A.v - B.v).x();
  EXPECT_NEAR(un1, 0.1 - 0.6, 1e-15);
  EXPECT_NEAR(rec.dE, 0.2 * 0.3, 1e-15);
}

TEST(RigidCollision, RejectsBadInput) {
  BodyState A, B;
  const auto p = MassProperties::spherical_top(1.0, 0.4);
  EXPECT_THROW(collide(A, p, B, p, Vec3::Zero(), Vec3::Zero(), Vec3(1, 0, 0)),
               std::invalid_argument);
  EXPECT_THROW(collide(A, p, B, p, Vec3::Zero(), Vec3(1, 0, 0), Vec3(1, 0, 0), -1.0),
               std::invalid_argument);
  EXPECT_THROW(MassProperties::spherical_top(0.0, 1.0), std::invalid_argument);
  Mat3 bad = Mat3::Identity();
  bad(2, 2) = -1.0;
  EXPECT_THROW(MassProperties::from_tensor(1.0, bad), std::invalid_argument);
}

TEST(RigidCollision, InertiaTensorTurnsWithTheBody) {
  // I_lab = Q I_body Q^T: a body rotated by 90 deg about z swaps its x and y moments.
  const auto p = MassProperties::from_tensor(1.0, Vec3(1.0, 2.0, 3.0).asDiagonal().toDenseMatrix());
  const Quat q(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitZ()));
  EXPECT_NEAR(p.apply_inertia(q, Vec3::UnitX()).x(), 2.0, 1e-15);
  EXPECT_NEAR(p.apply_inertia(q, Vec3::UnitY()).y(), 1.0, 1e-15);
  EXPECT_NEAR(p.apply_inv_inertia(q, Vec3::UnitX()).x(), 0.5, 1e-15);
}

}  // namespace
}  // namespace hb
