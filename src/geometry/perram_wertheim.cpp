// Perram–Wertheim contact function: see perram_wertheim.hpp for the derivation.
#include "geometry/perram_wertheim.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <stdexcept>
#include <string>

namespace hb {
namespace {

void check(const EllipsoidPose& E, const char* which) {
  const Vec3& s = E.semi_axes;
  if (!(s.minCoeff() > 0.0) || !s.allFinite())
    throw std::invalid_argument(std::string("perram_wertheim: semi-axes of ") + which +
                                " must be finite and > 0");
  const double qn = E.q.coeffs().norm();
  if (!(qn > 0.0) || !std::isfinite(qn))
    throw std::invalid_argument(std::string("perram_wertheim: orientation of ") + which +
                                " must be a non-zero finite quaternion");
}

// The pair reduced to the frame of A scaled by A's semi-axes (see "Evaluation" in the header):
// F(lambda) = lambda (1 - lambda) sum_i z_i^2 / (1 - lambda + lambda sigma_i^2).  The SVD of the
// graded matrix G = S_A^-1 R_A^T R_B S_B keeps small singular values to high relative accuracy.
struct Reduced {
  Mat3 RA;       // body -> lab of A
  Vec3 sa;       // semi-axes of A
  Mat3 U;        // left singular vectors of G
  Vec3 sigma2;   // sigma_i^2
  Vec3 z2;       // z_i^2
  Vec3 z;
};

Reduced reduce(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r) {
  Reduced p;
  p.RA = A.q.normalized().toRotationMatrix();
  const Mat3 RB = B.q.normalized().toRotationMatrix();
  p.sa = A.semi_axes;
  const Vec3 inv_sa = p.sa.cwiseInverse();
  const Mat3 G = inv_sa.asDiagonal() * (p.RA.transpose() * RB) * B.semi_axes.asDiagonal();
  const Eigen::JacobiSVD<Mat3> svd(G, Eigen::ComputeFullU);
  p.U = svd.matrixU();
  p.sigma2 = svd.singularValues().cwiseAbs2();
  p.z = p.U.transpose() * (inv_sa.asDiagonal() * (p.RA.transpose() * r));
  p.z2 = p.z.cwiseAbs2();
  return p;
}

struct Eval {
  double F, dF, d2F;
};

// F, F', F'' at lambda: with g = sum z_i^2 / d_i, g' = -sum z_i^2 (sigma_i^2 - 1) / d_i^2,
// g'' = 2 sum z_i^2 (sigma_i^2 - 1)^2 / d_i^3 and F = l g, l = lambda (1 - lambda):
// F' = (1 - 2 lambda) g + l g',  F'' = -2 g + 2 (1 - 2 lambda) g' + l g''.
Eval evaluate(const Reduced& p, double lambda) {
  double g = 0.0, g1 = 0.0, g2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double e = p.sigma2[i] - 1.0;
    const double inv_d = 1.0 / ((1.0 - lambda) + lambda * p.sigma2[i]);
    const double t = p.z2[i] * inv_d;
    g += t;
    g1 -= t * e * inv_d;
    g2 += 2.0 * t * e * e * inv_d * inv_d;
  }
  const double l = lambda * (1.0 - lambda);
  return {l * g, (1.0 - 2.0 * lambda) * g + l * g1, -2.0 * g + 2.0 * (1.0 - 2.0 * lambda) * g1 + l * g2};
}

}  // namespace

double perram_wertheim_at(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r_AB,
                          double lambda) {
  check(A, "A");
  check(B, "B");
  return evaluate(reduce(A, B, r_AB), lambda).F;
}

PerramWertheim perram_wertheim(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r_AB,
                               double tol) {
  check(A, "A");
  check(B, "B");
  if (!r_AB.allFinite()) throw std::invalid_argument("perram_wertheim: r_AB must be finite");

  PerramWertheim out;
  if (r_AB.squaredNorm() == 0.0) {  // concentric: F = 0, overlap
    out.F = 0.0;
    out.point = A.r;
    out.overlap = true;
    return out;
  }
  const Reduced p = reduce(A, B, r_AB);

  // Initial guess, exact for two spheres (lambda* = R_A / (R_A + R_B)): in the reduced frame A
  // is the unit sphere and B's support value along z is h_B = sqrt(sum zhat_i^2 sigma_i^2).
  const double hB = std::sqrt(p.z2.dot(p.sigma2) / p.z2.sum());
  double lambda = 1.0 / (1.0 + hB);
  double lo = 0.0, hi = 1.0;  // F'(lo) > 0 > F'(hi)

  constexpr int kMaxIter = 200;  // bisection alone needs ~60; Newton ~5
  Eval e = evaluate(p, lambda);
  int it = 0;
  while (it < kMaxIter) {
    ++it;
    if (e.dF > 0.0)
      lo = lambda;
    else if (e.dF < 0.0)
      hi = lambda;
    else
      break;  // exact stationary point
    const bool newton = e.d2F < 0.0;
    double next = newton ? lambda - e.dF / e.d2F : 0.5 * (lo + hi);
    // Quadratic convergence: once a Newton step is this small, the error after it is far
    // below rounding.  Take it (if it stays in the closed bracket) and stop.  This test comes
    // before the bracket safeguard, since near the maximum F' is rounding noise and a tiny
    // step may touch the bracket end that was just set to lambda.
    if (newton && std::abs(next - lambda) <= 1e-10 * std::min(lambda, 1.0 - lambda)) {
      if (next != lambda && next >= lo && next <= hi) {
        lambda = next;
        e = evaluate(p, lambda);
      }
      break;
    }
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // safeguard (also catches NaN)
    if (next == lambda) break;                               // bracket at rounding level
    lambda = next;
    e = evaluate(p, lambda);
    if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon()) break;
  }

  out.F = e.F;
  out.lambda = lambda;
  out.iterations = it;
  // C'^-1 y in the reduced frame; lab: C^-1 r = R_A S_A^-1 U w, M_A C^-1 r = R_A S_A U w.
  Vec3 w;
  for (int i = 0; i < 3; ++i) w[i] = p.z[i] / ((1.0 - lambda) + lambda * p.sigma2[i]);
  const Vec3 Uw = p.U * w;
  out.point = A.r + (1.0 - lambda) * (p.RA * p.sa.cwiseProduct(Uw));
  out.normal = (p.RA * Uw.cwiseQuotient(p.sa)).normalized();
  out.overlap = e.F < 1.0 - tol;
  return out;
}

}  // namespace hb
