#include "setup/init.hpp"

#include <cmath>
#include <pcg_random.hpp>
#include <random>

namespace hb {

namespace {
int fcc_cells(std::size_t n) {
  int m = 1;
  while (4ull * m * m * m < n) ++m;
  return m;
}
}  // namespace

std::vector<Vec3> fcc_lattice(std::size_t n, double L, double* nn_distance) {
  const int m = fcc_cells(n);
  const double a = L / m;
  if (nn_distance) *nn_distance = a / std::sqrt(2.0);
  static const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<Vec3> r;
  r.reserve(n);
  for (int z = 0; z < m && r.size() < n; ++z)
    for (int y = 0; y < m && r.size() < n; ++y)
      for (int x = 0; x < m && r.size() < n; ++x)
        for (int b = 0; b < 4 && r.size() < n; ++b)
          // offset by a quarter cell so no site lies on a cell or box boundary
          r.emplace_back(a * (x + basis[b][0] + 0.25), a * (y + basis[b][1] + 0.25),
                         a * (z + basis[b][2] + 0.25));
  return r;
}

double fcc_max_packing_fraction(std::size_t n) {
  const int m = fcc_cells(n);
  // touching spheres of diameter a/sqrt(2) in a cube of side m a
  const double sigma = 1.0 / std::sqrt(2.0);
  return n * (kPi / 6.0) * sigma * sigma * sigma / (double(m) * m * m);
}

void maxwell_boltzmann(State& s, double kT, double mass, std::uint64_t seed) {
  pcg64 rng(seed, 0x68617264626f6479ull);  // stream "hardbody"
  std::normal_distribution<double> gauss(0.0, std::sqrt(kT / mass));
  const std::size_t n = s.size();
  Vec3 mean = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    s.v[i] = Vec3(gauss(rng), gauss(rng), gauss(rng));
    mean += s.v[i];
  }
  mean /= double(n);
  for (auto& v : s.v) v -= mean;
  const double k = kinetic_energy(s, mass);
  if (k > 0.0) {
    const double scale = std::sqrt(1.5 * n * kT / k);
    for (auto& v : s.v) v *= scale;
  }
}

void maxwell_boltzmann_spin(State& s, double kT, double inertia, std::uint64_t seed) {
  pcg64 rng(seed, 0x7370696e73706e31ull);  // a stream of its own
  std::normal_distribution<double> gauss(0.0, std::sqrt(kT / inertia));
  double k = 0.0;
  for (auto& w : s.w) {
    w = Vec3(gauss(rng), gauss(rng), gauss(rng));
    k += 0.5 * inertia * w.squaredNorm();
  }
  if (k > 0.0) {
    const double scale = std::sqrt(1.5 * s.size() * kT / k);
    for (auto& w : s.w) w *= scale;
  }
}

void maxwell_boltzmann_spin(State& s, double kT, const Vec3& inertia, std::uint64_t seed) {
  if (spherical_top(inertia)) return maxwell_boltzmann_spin(s, kT, inertia[0], seed);
  pcg64 rng(seed, 0x7370696e73706e31ull);  // the same stream as the spherical top's
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Vec3 sd = (kT / inertia.array()).sqrt().matrix();
  double k = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3 W(sd[0] * gauss(rng), sd[1] * gauss(rng), sd[2] * gauss(rng));  // body frame
    s.w[i] = s.q[i] * W;
    k += 0.5 * W.dot(inertia.cwiseProduct(W));
  }
  if (k > 0.0) {
    const double scale = std::sqrt(1.5 * s.size() * kT / k);
    for (auto& w : s.w) w *= scale;
  }
}

double kinetic_energy(const State& s, double mass) {
  double k = 0.0;
  for (const auto& v : s.v) k += v.squaredNorm();
  return 0.5 * mass * k;
}

Vec3 total_momentum(const State& s, double mass) {
  Vec3 p = Vec3::Zero();
  for (const auto& v : s.v) p += mass * v;
  return p;
}

}  // namespace hb
