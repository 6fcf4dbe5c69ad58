// Writes correlations.tsv, gr.tsv and nematic.tsv of a small free-flight system, and
// density_profile.tsv and order_profile.tsv of a two-species gas between walls on x and z, into
// the directory given as argv[1], with the observers' own writers, for the plot script's test.
#include <fstream>
#include <iostream>
#include <pcg_random.hpp>
#include <random>

#include "observers/correlations.hpp"
#include "observers/structure.hpp"
#include "observers/wall_observables.hpp"

using namespace hb;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: observer_table_writer DIR\n";
    return 2;
  }
  pcg32 rng(31);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  Box box;
  box.L = Vec3::Constant(8.0);
  State s;
  s.resize(300);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.r[i] = 8.0 * Vec3(uni(rng), uni(rng), uni(rng));
    s.v[i] = Vec3(g(rng), g(rng), g(rng));
    s.w[i] = Vec3(g(rng), g(rng), g(rng));
    s.q[i] = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
  }
  CorrelationSpec spec;
  spec.interval = 0.05;
  spec.origin_every = 4;
  spec.max_lag_samples = 40;
  TimeCorrelations corr(spec);
  RadialDistribution rdf;
  NematicOrder nematic;
  for (int k = 0; k < 80; ++k) {
    const double t = k * spec.interval;
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.advance_to(i, t);
      s.image[i] += box.wrap(s.r[i]);
    }
    corr.sample(t, s, box);
    if (k % 10 == 0) {
      rdf.sample(t, s, box);
      nematic.sample(t, s, box);
    }
  }
  const std::string dir = argv[1];
  std::ofstream(dir + "/correlations.tsv") << corr.to_tsv();
  std::ofstream(dir + "/gr.tsv") << rdf.to_tsv();
  std::ofstream(dir + "/nematic.tsv") << nematic.to_tsv();

  // Walls on x and z: ideal gas of spheres (A) and rods (B) whose long axes lean towards the
  // walls' normal near the walls.
  WallSpec walls;
  walls.planes = {true, false, true};
  DensityProfiles prof(walls, box, {{"A", true, 0}, {"B", false, 0}}, 0.2);
  for (int k = 0; k < 20; ++k) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.r[i] = 8.0 * Vec3(uni(rng), uni(rng), uni(rng));
      s.species[i] = i % 3 == 0 ? 0 : 1;
      const double near = std::exp(-std::min(s.r[i].z(), 8.0 - s.r[i].z()));
      const Vec3 u = (Vec3(g(rng), g(rng), g(rng)) + 3.0 * near * Vec3::UnitZ()).normalized();
      s.q[i] = Quat::FromTwoVectors(Vec3::UnitX(), u);
      s.t[i] = 0.0;
    }
    prof.sample(0.0, s, box);
  }
  std::ofstream(dir + "/density_profile.tsv") << prof.to_tsv();
  std::ofstream(dir + "/order_profile.tsv") << prof.order_tsv();
  return 0;
}
