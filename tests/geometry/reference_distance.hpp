// Independent reference for the signed distance of two convex bodies with a closed-form support
// function (tests only; slow and simple).  It shares no code with the Newton-Raphson solver of
// geometry/distance.hpp beyond the shapes' support functions.
//
// For convex bodies A, B the separation along a unit direction n is
//     s(n) = n.(r_B - r_A) - h_A(n) - h_B(-n),
// and the signed distance is  d = max_{|n| = 1} s(n)  (the separating-axis theorem: positive =
// the gap, negative = minus the penetration depth, the minimum translation to separate them).
// s is positively homogeneous of degree 1, its gradient in R^3 is x_B - x_A (x_A, x_B the
// support points of A along n and of B along -n) and its Hessian -(H_A(n) + H_B(-n)).
// We maximise s on the unit sphere by a Riemannian Newton method (tangent-plane Newton step,
// gradient step when the tangent Hessian is not negative definite, backtracking so that s never
// decreases), from the hint (if any) and the centre-line direction and then, if the result is
// not positive, from `extra_starts` (default 48) more directions spread over the sphere
// (Fibonacci lattice), keeping the best.
// Certification: when the bodies are separated, every local maximum with s > 0 is the global one
// (h_K is convex for the Minkowski difference K, so the minimum of h_K on the unit ball is a
// convex problem whose negative minimum lies on the sphere), so one positive result is final.
#pragma once
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "geometry/posed.hpp"
#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb::ref {

struct RefDistance {
  double distance = 0.0;
  Vec3 n = Vec3::UnitX();  // unit direction from A to B
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();
  int iterations = 0;
  int starts = 0;
};

template <SupportShape SA, SupportShape SB>
struct Separation {
  const SA& a;
  const SB& b;
  Pose pa, pb;

  double value(const Vec3& n) const {
    return n.dot(pb.r - pa.r) - a.support(pa.R.transpose() * n) -
           b.support(-(pb.R.transpose() * n));
  }
  Vec3 xa(const Vec3& n) const { return pa.r + pa.R * a.support_point(pa.R.transpose() * n); }
  Vec3 xb(const Vec3& n) const {
    return pb.r + pb.R * b.support_point(-(pb.R.transpose() * n));
  }
  Vec3 gradient(const Vec3& n) const { return xb(n) - xa(n); }
  Mat3 hessian(const Vec3& n) const {
    return -(pa.R * a.support_hessian(pa.R.transpose() * n) * pa.R.transpose() +
             pb.R * b.support_hessian(-(pb.R.transpose() * n)) * pb.R.transpose());
  }
};

// Local maximisation of s on the unit sphere from n (updated in place); returns s(n).
template <class Sep>
double maximise_on_sphere(const Sep& S, Vec3& n, double scale, int& iterations) {
  n.normalize();
  double s = S.value(n);
  for (int it = 0; it < 200; ++it) {
    ++iterations;
    const Vec3 g = S.gradient(n);
    // orthonormal tangent basis
    Vec3 e1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    Vec3 e2 = n.cross(e1);
    Eigen::Matrix<double, 3, 2> E;
    E << e1, e2;
    const Eigen::Vector2d g2 = E.transpose() * g;
    if (g2.norm() <= 1e-15 * scale) break;
    const Eigen::Matrix2d Hr =
        E.transpose() * S.hessian(n) * E - n.dot(g) * Eigen::Matrix2d::Identity();
    Eigen::Vector2d step;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(Hr);
    if (es.eigenvalues().maxCoeff() < 0.0) {
      step = -Hr.ldlt().solve(g2);
    } else {
      step = g2 / std::max(es.eigenvalues().cwiseAbs().maxCoeff(), 1e-3 * scale);
    }
    if (step.norm() > 0.5) step *= 0.5 / step.norm();  // at most ~0.5 rad per iteration
    double t = 1.0;
    bool moved = false;
    for (int ls = 0; ls < 60; ++ls, t *= 0.5) {
      const Vec3 m = (n + t * (E * step)).normalized();
      const double sm = S.value(m);
      if (sm >= s) {
        moved = (m != n);
        n = m;
        s = sm;
        break;
      }
    }
    if (!moved) break;
    if (t * step.norm() <= 1e-16) break;
  }
  return s;
}

template <SupportShape SA, SupportShape SB>
RefDistance reference_distance(const SA& a, const Pose& pa, const SB& b, const Pose& pb,
                               const Vec3* hint = nullptr, int extra_starts = 48) {
  const Separation<SA, SB> S{a, b, pa, pb};
  const double scale = a.bounding_radius() + b.bounding_radius() + (pb.r - pa.r).norm();
  RefDistance out;
  out.distance = -kInf;
  auto try_from = [&](Vec3 n) {
    if (!(n.squaredNorm() > 0.0)) return;
    ++out.starts;
    const double s = maximise_on_sphere(S, n, scale, out.iterations);
    if (s > out.distance) {
      out.distance = s;
      out.n = n;
    }
  };
  if (hint) try_from(*hint);
  try_from(pb.r - pa.r);
  if (!(out.distance > 0.0)) {
    const int m = extra_starts;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < m; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / m;
      const double rxy = std::sqrt(1.0 - z * z);
      try_from(Vec3(rxy * std::cos(golden * i), rxy * std::sin(golden * i), z));
    }
  }
  out.point_a = S.xa(out.n);
  out.point_b = S.xb(out.n);
  return out;
}

}  // namespace hb::ref
