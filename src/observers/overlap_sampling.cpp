#include "observers/overlap_sampling.hpp"

namespace hb {

namespace sampling_detail {

std::vector<Vec3> fibonacci_sphere(int n) {
  std::vector<Vec3> v;
  v.reserve(std::size_t(std::max(n, 0)));
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double rxy = std::sqrt(std::max(0.0, 1.0 - z * z));
    v.emplace_back(rxy * std::cos(golden * i), rxy * std::sin(golden * i), z);
  }
  return v;
}

}  // namespace sampling_detail

OverlapReport superquadric_overlaps(FieldView<Vec3> r, FieldView<Quat> q,
                                    const Box& box, const Superquadric& shape, double tol) {
  const SurfaceSampling<Superquadric> check(shape, SurfaceSampling<Superquadric>::kDefaultSamples, tol);
  return sampled_overlaps(r, q, box, check);
}

}  // namespace hb
