// LU factorisation with partial (row) pivoting of a small fixed-size matrix, and its solve: the
// Newton steps of the distance solver (5 and 8 equations, geometry/distance.hpp) and of the
// contact system (5 equations, contact/contact_time.hpp).
//
// Why not Eigen::PartialPivLU: for fixed sizes of 5 and 8 it runs its general unblocked kernel
// with run-time loop bounds and a permutation object; measured with callgrind on the ellipsoid
// benchmark (bench_rigid X0 = 2, phi = 0.5, N = 256, NNL), its factorisation alone cost about
// 1,400 instructions per 5x5 matrix and 17 % of the whole run.  Here every loop bound is a
// compile-time constant and the compiler unrolls the whole factorisation.
//
// The arithmetic is Eigen's, in Eigen's order, so results agree with it to the last bit on
// matrices without ties in the pivot search (tests/math/test_small_lu.cpp compares the two):
//  * column k: the pivot is the first row i >= k of largest |a_ik|; rows k and p are swapped
//    whole; the column below the pivot is divided by it (skipped for a zero pivot, whose column
//    is then all zero); the trailing block takes the rank-1 update a_ij -= a_ik a_kj;
//  * solve: the row permutation, then Eigen's triangular solves (unit lower, then upper).
// A zero pivot is not an error: the solve then gives non-finite values, which the callers test
// (allFinite) to switch to their singular-value step.
#pragma once
#include <Eigen/Core>
#include <cmath>
#include <utility>

namespace hb {

template <int N>
class SmallLU {
 public:
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;

  explicit SmallLU(const Mat& a) : lu_(a) {
    for (int i = 0; i < N; ++i) perm_[i] = i;
    for (int k = 0; k < N; ++k) {
      int p = k;
      double big = std::abs(lu_(k, k));
      for (int i = k + 1; i < N; ++i) {
        const double v = std::abs(lu_(i, k));
        if (v > big) big = v, p = i;
      }
      if (big != 0.0) {
        if (p != k) {
          for (int j = 0; j < N; ++j) std::swap(lu_(k, j), lu_(p, j));
          std::swap(perm_[k], perm_[p]);
        }
        const double d = lu_(k, k);
        for (int i = k + 1; i < N; ++i) lu_(i, k) /= d;
      }
      for (int j = k + 1; j < N; ++j) {
        const double r = lu_(k, j);
        for (int i = k + 1; i < N; ++i) lu_(i, j) -= lu_(i, k) * r;
      }
    }
  }

  // x with A x = b: the permutation, then Eigen's own triangular solves on the factors (for
  // these sizes they are unrolled already, and so the solution is Eigen's to the last bit).
  Vec solve(const Vec& b) const {
    Vec x;
    for (int i = 0; i < N; ++i) x[i] = b[perm_[i]];
    lu_.template triangularView<Eigen::UnitLower>().solveInPlace(x);
    lu_.template triangularView<Eigen::Upper>().solveInPlace(x);
    return x;
  }

  // The factors packed as Eigen's matrixLU(): U on and above the diagonal, L below it.
  const Mat& matrixLU() const { return lu_; }
  // Row i of P A is row perm(i) of A.
  int perm(int i) const { return perm_[i]; }

 private:
  Mat lu_;
  int perm_[N];
};

}  // namespace hb
