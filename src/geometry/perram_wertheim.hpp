// Perram–Wertheim contact function of two ellipsoids: an overlap test that is independent of
// the project's distance solver (it is the check the solver's results are tested against).
//
// Definitions.  An ellipsoid with centre r, body->lab rotation Q and semi-axes (a, b, c) is
// { x : (x - r)^T A (x - r) <= 1 },  A = Q diag(a^-2, b^-2, c^-2) Q^T,  A^-1 = M = Q diag(a^2,
// b^2, c^2) Q^T.  For the centre separation r_AB = r_B - r_A,
//     F(lambda) = lambda (1 - lambda) r_AB^T C(lambda)^-1 r_AB,
//     C(lambda) = (1 - lambda) M_A + lambda M_B,                       lambda in [0, 1],
//     F(A, B)   = max_lambda F(lambda).
// Equivalently F(lambda) = min_x [lambda f_A(x) + (1 - lambda) f_B(x)] with the quadratic forms
// f_X(x) = (x - r_X)^T X (x - r_X): a minimum of functions affine in lambda, hence concave, with
// F(0) = F(1) = 0, F'(0) = r^T M_A^-1 r > 0 and F'(1) = -r^T M_B^-1 r < 0, so the maximiser is
// unique and interior.  F < 1: overlap, F = 1: touching, F > 1: disjoint.
//
// Evaluation.  In the frame of A scaled by A's semi-axes (y = S_A^-1 R_A^T x) A is the unit
// sphere and C becomes (1 - lambda) I + lambda G G^T, G = S_A^-1 R_A^T R_B S_B.  With the SVD
// G = U diag(sigma) V^T and z = U^T S_A^-1 R_A^T r_AB:
//     F(lambda) = lambda (1 - lambda) sum_i z_i^2 / (1 - lambda + lambda sigma_i^2),
// a sum of positive terms with closed-form F' and F''.  (Forming Q diag(a^2) Q^T in the lab
// frame and solving with C instead loses ~cond(C) eps: 2e-10 in F for a 50 x 0.5 x 0.02 body.)
// The maximiser is found by Newton's method on F' = 0, safeguarded by the bracket [lo, hi] on
// which F' changes sign (a step leaving the bracket is replaced by bisection); it stops when
// a Newton step is below 1e-10 min(lambda, 1 - lambda) (the error after it is below rounding).
// Typically 1-10 iterations, at most ~25 for aspect ratios 1e4; it cannot fail on valid input.
//
// Scaling.  lambda* does not depend on |r_AB|, so F(s r_AB) = s^2 F(r_AB): the pair touches
// when the centres are separated by s r_AB with s = 1 / sqrt(F) (touching_scale).  An
// overlapping pair has s > 1 ("move the centres apart by the factor s to resolve it").
//
// Contact point.  The minimising x at lambda* is x* = r_A + (1 - lambda*) M_A C^-1 r_AB, where
// f_A(x*) = f_B(x*) = F: it is the point where the two ellipsoids touch once each is scaled by
// sqrt(F) about its own centre; the common normal there is parallel to C^-1 r_AB.
//
// Tolerance.  overlap = F < 1 - tol.  With F = s^-2 this means the centres would have to move
// apart by more than the relative amount ~tol/2 of |r_AB| to touch.  The rounding error of F
// at touching is measured below 1e-14 (random pairs with semi-axes 0.2..3, and 100:1 rods and
// 1:100 discs against each other), so the default 1e-10 leaves a margin of 1e4: an exactly
// touching pair is never reported as overlapping, any overlap deeper than ~5e-11 |r_AB| is.
#pragma once
#include "math/types.hpp"

namespace hb {

// One posed ellipsoid: semi-axes along the body x, y, z axes, centre and body->lab rotation.
struct EllipsoidPose {
  Vec3 semi_axes = Vec3::Ones();
  Vec3 r = Vec3::Zero();
  Quat q = Quat::Identity();
};

inline constexpr double kPerramWertheimTol = 1e-10;

struct PerramWertheim {
  double F = 0.0;            // contact function: < 1 overlap, 1 touching, > 1 disjoint
  double lambda = 0.5;       // maximiser in (0, 1)
  Vec3 point = Vec3::Zero(); // x*: touching point of the pair scaled by sqrt(F) (A's image)
  Vec3 normal = Vec3::Zero();// unit normal at x*, from A into B (zero if r_AB = 0)
  bool overlap = true;       // F < 1 - tol
  int iterations = 0;        // Newton/bisection iterations used
};

// F(lambda) at one lambda (for tests and diagnostics), with B's centre at A.r + r_AB.
double perram_wertheim_at(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r_AB,
                          double lambda);

// The contact function with B's centre at A.r + r_AB (minimum image; B.r is not used).
// Throws std::invalid_argument for non-positive / non-finite semi-axes, a non-finite r_AB or
// a zero quaternion.  r_AB = 0 gives F = 0 (overlap).
PerramWertheim perram_wertheim(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r_AB,
                               double tol = kPerramWertheimTol);

// Same with r_AB = B.r - A.r.
inline PerramWertheim perram_wertheim(const EllipsoidPose& A, const EllipsoidPose& B,
                                      double tol = kPerramWertheimTol) {
  return perram_wertheim(A, B, B.r - A.r, tol);
}

inline bool ellipsoids_overlap(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r_AB,
                               double tol = kPerramWertheimTol) {
  return perram_wertheim(A, B, r_AB, tol).overlap;
}

inline bool ellipsoids_overlap(const EllipsoidPose& A, const EllipsoidPose& B,
                               double tol = kPerramWertheimTol) {
  return perram_wertheim(A, B, tol).overlap;
}

// s such that centres separated by s * r_AB touch (orientations fixed): s = 1/sqrt(F).
// s > 1 overlap (how far apart the centres must move), s < 1 disjoint; +inf when r_AB = 0.
inline double touching_scale(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r_AB) {
  const double F = perram_wertheim(A, B, r_AB).F;
  return F > 0.0 ? 1.0 / std::sqrt(F) : kInf;
}

inline double touching_scale(const EllipsoidPose& A, const EllipsoidPose& B) {
  return touching_scale(A, B, B.r - A.r);
}

}  // namespace hb
