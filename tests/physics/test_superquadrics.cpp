// Superquadric simulations end to end: short runs through `hardbody run` (lattice start with
// neighbour lists, grown start with cell lists) checked by the sampling overlap test and the
// energy drift, and a superquadric with all exponents 2 reproducing the collisions of the
// ellipsoid with the same semi-axes.
#include <gtest/gtest.h>

#include <cstdio>
#include <tuple>
#include <vector>

#include "observers/overlap_sampling.hpp"
#include "physics/run_helper.hpp"
#include "setup/rigid_setup.hpp"

using hbtest::run_config;
using namespace hb;

namespace {

std::string superquadric_config(int n, double phi, const std::string& axes,
                                const std::string& exponents, const std::string& neighbors,
                                const std::string& init, double teq, double t, int seed) {
  return "[system]\nparticles = " + std::to_string(n) + "\npacking_fraction = " +
         std::to_string(phi) + "\nseed = " + std::to_string(seed) +
         "\n[shape]\ntype = \"superquadric\"\nsemi_axes = " + axes + "\nexponents = " + exponents +
         "\n[init]\nmethod = \"" + init + "\"\n[run]\nequilibrate_time = " + std::to_string(teq) +
         "\ntime = " + std::to_string(t) + "\n[neighbors]\nmethod = \"" + neighbors +
         "\"\n[output]\nlog_interval = 0.25\nsnapshot_interval = 0.5\n[observables]\n"
         "interval = 0.0\ngr_interval = 0.0\n";
}

void expect_clean_run(const nlohmann::json& s, const char* name, std::uint64_t min_collisions) {
  const auto coll = s["collisions"].get<std::uint64_t>();
  std::printf("%s: collisions=%llu overlaps=%d snapshot_overlaps=%d (frames %d) min_gap=%.3g "
              "energy_drift=%.3g Z=%.4f +- %.4f tau_c=%.0f us solver_fallbacks=%d\n",
              name, (unsigned long long)coll, s["overlaps"].get<int>(),
              s["snapshot_overlaps"].get<int>(), s["trajectory_frames"].get<int>(),
              s["min_distance"].get<double>(), s["energy_drift"].get<double>(),
              s["Z"].get<double>(), s["Z_error"].get<double>(), s["tau_c_us"].get<double>(),
              s["solver_fallbacks"].get<int>());
  EXPECT_GE(coll, min_collisions);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_EQ(s["snapshot_overlaps"].get<int>(), 0);
  EXPECT_GT(s["trajectory_frames"].get<int>(), 2);
  EXPECT_GT(s["min_distance"].get<double>(), 0.0);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-10);
  EXPECT_EQ(s["shape"]["type"], "superquadric");
}

// (i, j, time) of the first `count` collisions.
template <class Sim>
std::vector<std::tuple<std::uint32_t, std::uint32_t, double>> first_collisions(Sim sim, int count) {
  std::vector<std::tuple<std::uint32_t, std::uint32_t, double>> out;
  while (int(out.size()) < count) {
    const StepInfo s = sim.step(kInf);
    if (s.type == EventType::Collision && !s.stale)
      out.emplace_back(std::min(s.record.a, s.record.b), std::max(s.record.a, s.record.b), sim.now());
  }
  return out;
}

}  // namespace

// p = 8 ("boat", X0 = 2): the paper's code failed above p = 4 with neighbour lists.
TEST(SuperquadricRun, LatticeStartNeighbourListsNoOverlaps) {
  const auto s = run_config("sq-nnl", superquadric_config(256, 0.256, "[1.0, 0.5, 0.5]",
                                                          "[8.0, 8.0, 8.0]", "nnl", "lattice",
                                                          0.2, 2.0, 5));
  expect_clean_run(s, "p=8 X0=2 nnl lattice", 1500);
  EXPECT_EQ(s["neighbors"], "nnl");
}

// The paper's family (n = m = 2, b = c = 0.8, X0 = 2) with p = 4, grown from phi = 0.1.
TEST(SuperquadricRun, GrownStartCellListsNoOverlaps) {
  const auto s = run_config("sq-cells-grow", superquadric_config(256, 0.256, "[1.6, 0.8, 0.8]",
                                                                 "[2.0, 2.0, 4.0]", "cells",
                                                                 "grow", 0.2, 2.0, 6));
  expect_clean_run(s, "n=m=2 p=4 X0=2 cells grown", 1500);
  EXPECT_EQ(s["init"]["method"], "grow");
  EXPECT_GT(s["init"]["min_distance_after_growth"].get<double>(), 0.0);
  EXPECT_EQ(s["neighbors"], "cells");
}

// All exponents 2: the superquadric is the ellipsoid (another implicit function of the same
// surface), so the event sequence is the same: pairs equal, times to 1e-9.
TEST(SuperquadricExponentTwo, SameCollisionsAsEllipsoid) {
  RigidSystemSpec spec;
  spec.n = 256;
  spec.phi = 0.3;
  spec.semi_axes = Vec3(1.0, 0.5, 0.5);
  spec.exponents = Vec3(2.0, 2.0, 2.0);
  spec.inertia = Vec3::Constant(0.1);
  spec.seed = 8;
  Box box;
  const State st = ellipsoid_start(spec, box);
  for (const bool nnl : {false, true}) {
    std::vector<std::tuple<std::uint32_t, std::uint32_t, double>> e, q;
    if (nnl) {
      const auto em = ellipsoid_model(spec);
      const auto qm = superquadric_model(spec);
      e = first_collisions(EllipsoidListSim(box, st, em, ObbNeighbors<Ellipsoid>(em.shape, 0.15)), 200);
      q = first_collisions(SuperquadricListSim(box, st, qm, ObbNeighbors<Superquadric>(qm.shape, 0.15)), 200);
    } else {
      const auto em = ellipsoid_model(spec);
      const auto qm = superquadric_model(spec);
      e = first_collisions(EllipsoidCellSim(box, st, em, CellNeighbors(em.interaction_range())), 200);
      q = first_collisions(SuperquadricCellSim(box, st, qm, CellNeighbors(qm.interaction_range())), 200);
    }
    double worst = 0.0;
    for (int k = 0; k < 200; ++k) {
      ASSERT_EQ(std::get<0>(e[k]), std::get<0>(q[k])) << (nnl ? "nnl" : "cells") << " collision " << k;
      ASSERT_EQ(std::get<1>(e[k]), std::get<1>(q[k])) << (nnl ? "nnl" : "cells") << " collision " << k;
      worst = std::max(worst, std::abs(std::get<2>(e[k]) - std::get<2>(q[k])));
    }
    std::printf("%s: 200 collisions, same pairs, largest time difference %.3g (t = %.4g)\n",
                nnl ? "nnl" : "cells", worst, std::get<2>(e.back()));
    EXPECT_LE(worst, 1e-9);
  }
}
