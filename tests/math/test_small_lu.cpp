// SmallLU (math/small_lu.hpp) against its slow twin, Eigen::PartialPivLU: the same factors and
// solutions on random, ill-conditioned, scaled and singular matrices of the sizes the solvers
// use (5 and 8), and residuals that show the solve is right on its own.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cstring>
#include <pcg_random.hpp>
#include <random>

#include "math/small_lu.hpp"

namespace {

template <int N>
using Mat = Eigen::Matrix<double, N, N>;
template <int N>
using Vec = Eigen::Matrix<double, N, 1>;

// Largest |a - b| / max(1, |b|) over the entries.
template <class A, class B>
double rel_diff(const A& a, const B& b) {
  double m = 0.0;
  for (int i = 0; i < a.size(); ++i)
    m = std::max(m, std::abs(a.data()[i] - b.data()[i]) / std::max(1.0, std::abs(b.data()[i])));
  return m;
}

// Bit for bit (NaN of an exactly singular draw included).
template <class A>
bool same_bits(const A& a, const A& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

enum class Kind { uniform, graded, near_singular, structured };

template <int N>
Mat<N> draw(pcg32& rng, Kind kind) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat<N> a;
  for (int i = 0; i < N * N; ++i) a.data()[i] = u(rng);
  if (kind == Kind::graded) {  // rows and columns scaled over 12 decades
    for (int i = 0; i < N; ++i) {
      a.row(i) *= std::pow(10.0, 6.0 * u(rng));
      a.col(i) *= std::pow(10.0, 6.0 * u(rng));
    }
  } else if (kind == Kind::near_singular) {  // last row a combination of the others + 1e-13
    Vec<N> c;
    for (int i = 0; i < N; ++i) c[i] = u(rng);
    a.row(N - 1) = c.head(N - 1).transpose() * a.topRows(N - 1);
    a.row(N - 1) += 1e-13 * Eigen::Matrix<double, 1, N>::Random();
  } else if (kind == Kind::structured) {  // the distance/contact systems' shape: a zero block
    a.template bottomRightCorner<2, 2>().setZero();
    a(N - 2, N - 1) = u(rng);
  }
  return a;
}

template <int N>
void compare(std::uint64_t seed, int count) {
  pcg32 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int identical = 0;
  double worst_lu = 0.0, worst_x = 0.0, worst_res = 0.0;
  for (int n = 0; n < count; ++n) {
    const Kind kind = static_cast<Kind>(n % 4);
    const Mat<N> a = draw<N>(rng, kind);
    Vec<N> b;
    for (int i = 0; i < N; ++i) b[i] = u(rng);
    const Eigen::PartialPivLU<Mat<N>> slow(a);
    const hb::SmallLU<N> fast(a);
    const Vec<N> xs = slow.solve(b), xf = fast.solve(b);
    identical += same_bits(fast.matrixLU(), slow.matrixLU()) && same_bits(xf, xs);
    worst_lu = std::max(worst_lu, rel_diff(fast.matrixLU(), slow.matrixLU()));
    // near-singular systems amplify rounding: compare the solutions relative to their size
    worst_x = std::max(worst_x, (xf - xs).norm() / std::max(1.0, xs.norm()) /
                                    (kind == Kind::near_singular ? 1e4 : 1.0));
    if (kind != Kind::near_singular)  // the residual of the solve, scaled by |A| |x|
      worst_res = std::max(worst_res, (a * xf - b).norm() /
                                          (a.norm() * xf.norm() + b.norm()));
    // the permutation: P A = L U
    Mat<N> pa, l = Mat<N>::Identity(), up = Mat<N>::Zero();
    for (int i = 0; i < N; ++i) pa.row(i) = a.row(fast.perm(i));
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) (j < i ? l(i, j) : up(i, j)) = fast.matrixLU()(i, j);
    EXPECT_LT((l * up - pa).norm(), 1e-13 * a.norm()) << "P A != L U, matrix " << n;
  }
  std::printf("[ SmallLU<%d> ] %d matrices: bit-identical to Eigen %d; worst relative difference "
              "of the factors %.1e, of the solutions %.1e; worst scaled residual %.1e\n",
              N, count, identical, worst_lu, worst_x, worst_res);
  EXPECT_EQ(worst_lu, 0.0);  // the same arithmetic in the same order
  EXPECT_EQ(worst_x, 0.0);
  EXPECT_LT(worst_res, 1e-14);
  EXPECT_EQ(identical, count);
}

TEST(SmallLU, SameFactorsAndSolutionsAsEigenPartialPivLU5) { compare<5>(1, 20000); }
TEST(SmallLU, SameFactorsAndSolutionsAsEigenPartialPivLU8) { compare<8>(2, 20000); }

TEST(SmallLU, SingularMatrixGivesANonFiniteSolveAndAZeroPivot) {
  Mat<5> a = Mat<5>::Identity();
  a.col(2).setZero();  // exactly singular: a zero column
  const hb::SmallLU<5> lu(a);
  EXPECT_EQ(lu.matrixLU()(2, 2), 0.0);
  EXPECT_FALSE(lu.solve(Vec<5>::Ones()).allFinite());
  const Eigen::PartialPivLU<Mat<5>> slow(a);
  EXPECT_TRUE(lu.matrixLU() == slow.matrixLU());
}

TEST(SmallLU, PivotsOnTheLargestEntryOfEachColumn) {
  Mat<5> a = Mat<5>::Identity();
  a(0, 0) = 0.5;
  a(3, 0) = 2.0;  // column 0's pivot is row 3
  const hb::SmallLU<5> lu(a);
  EXPECT_EQ(lu.perm(0), 3);
  EXPECT_EQ(lu.matrixLU()(0, 0), 2.0);
  const Vec<5> b(1.0, 2.0, 3.0, 4.0, 5.0);
  EXPECT_LT((a * lu.solve(b) - b).norm(), 1e-15 * b.norm());
}

}  // namespace
