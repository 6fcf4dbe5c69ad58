// Writes correlations.tsv, gr.tsv and nematic.tsv of a small free-flight system into the
// directory given as argv[1], with the observers' own to_tsv(), for the plot script's test.
#include <fstream>
#include <iostream>
#include <pcg_random.hpp>
#include <random>

#include "observers/correlations.hpp"
#include "observers/structure.hpp"

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
  return 0;
}
