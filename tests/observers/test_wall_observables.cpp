// The observers of confined systems (observers/wall_observables.hpp): wall pressure against hand
// sums and block errors, density profiles on constructed states (known counts, shell volumes),
// the flat profile of an ideal gas in a slit, the order profile of aligned bodies, checkpoint
// round trips, and the contact extrapolation on exactly quadratic profiles.
#include <gtest/gtest.h>

#include <cmath>
#include <pcg_random.hpp>
#include <random>
#include <sstream>

#include "observers/wall_observables.hpp"

using namespace hb;

namespace {

// The observers read only the box's sides (the walls come from the WallSpec).
Box box_of(Vec3 L) {
  Box b;
  b.L = L;
  return b;
}

WallSpec planes(bool x, bool y, bool z) {
  WallSpec w;
  w.planes = {x, y, z};
  return w;
}

WallSpec container(double R) {
  WallSpec w;
  w.sphere_radius = R;
  return w;
}

struct Body {
  Vec3 r;
  std::uint16_t species = 0;
  Quat q = Quat::Identity();
};

State state_of(const std::vector<Body>& bodies) {
  State s;
  s.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    s.r[i] = bodies[i].r;
    s.species[i] = bodies[i].species;
    s.q[i] = bodies[i].q;
  }
  return s;
}

std::vector<ProfileSpecies> two_species(bool spheres = true) {
  return {{"A", spheres, 0}, {"B", spheres, 0}};
}

// Rows of a TSV table (comment lines dropped), split at tabs.
std::vector<std::vector<std::string>> rows_of(const std::string& tsv) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(tsv);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::istringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, '\t')) f.push_back(cell);
    rows.push_back(f);
  }
  return rows;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// WallPressure

TEST(WallPressure, AreaOfPlanesAndContainer) {
  const Box b = box_of(Vec3(2.0, 3.0, 5.0));
  EXPECT_DOUBLE_EQ(wall_area(planes(false, false, true), b), 2.0 * 2.0 * 3.0);
  EXPECT_DOUBLE_EQ(wall_area(planes(true, false, true), b), 2.0 * 3.0 * 5.0 + 2.0 * 2.0 * 3.0);
  EXPECT_DOUBLE_EQ(wall_area(planes(true, true, true), b), 2.0 * (15.0 + 10.0 + 6.0));
  EXPECT_DOUBLE_EQ(wall_area(container(1.5), box_of(Vec3::Constant(3.0))),
                   4.0 * kPi * 2.25);
  EXPECT_EQ(wall_area(WallSpec{}, b), 0.0);
}

TEST(WallPressure, BlocksMeanAndErrorAreTheHandSums) {
  const double A = 6.0;
  WallPressure wp(A);
  // Block 1: dt = 2, kT = 1, J = 1 + 2 + 3.
  wp.add(0.1, 1.0), wp.add(0.5, 2.0), wp.add(1.9, 3.0);
  wp.close_block(2.0, 1.0);
  EXPECT_DOUBLE_EQ(wp.last(), 6.0 / (A * 2.0 * 1.0));
  EXPECT_FALSE(wp.pressure().error_known());  // one block: unknown, never 0
  EXPECT_EQ(wp.pressure().blocks, 1u);
  // Block 2: dt = 2, kT = 1.5, J = 4.5. Block 3: dt = 1, kT = 1, J = 0.3 + 0.9.
  wp.add(2.5, 4.5);
  wp.close_block(2.0, 1.5);
  wp.add(4.2, 0.3), wp.add(4.4, 0.9);
  wp.close_block(1.0, 1.0);
  wp.close_block(0.0, 1.0);  // an empty block of no duration is ignored
  const std::vector<double> blocks{0.5, 4.5 / (A * 3.0), 1.2 / A};
  ASSERT_EQ(wp.blocks().size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(wp.blocks()[k], blocks[k]);
  const MeanError p = wp.pressure();
  // mean: the ratio of the sums, sum J / (A sum kT dt)
  EXPECT_DOUBLE_EQ(p.mean, (6.0 + 4.5 + 1.2) / (A * (2.0 + 3.0 + 1.0)));
  // error: the standard error of the three block values (fewer than 32 blocks: one level)
  const double m = (blocks[0] + blocks[1] + blocks[2]) / 3.0;
  double q = 0.0;
  for (double x : blocks) q += (x - m) * (x - m);
  EXPECT_NEAR(p.error, std::sqrt(q / 6.0), 1e-15);
  EXPECT_EQ(p.blocks, 3u);
  EXPECT_EQ(wp.impulses(), 6u);
  EXPECT_DOUBLE_EQ(wp.measured_time(), 5.0);
  EXPECT_DOUBLE_EQ(wp.last_impulse_time(), 4.4);
}

TEST(WallPressure, ErrorIsTheBlockAverageOfManyBlocks) {
  // 64 blocks: the blocking transformation of block_average(), not a plain standard error.
  WallPressure wp(2.0);
  std::vector<double> expect;
  for (int k = 0; k < 64; ++k) {
    const double J = k % 2 ? 3.0 : 1.0;
    wp.add(double(k), J);
    wp.close_block(1.0, 1.0);
    expect.push_back(J / 2.0);
  }
  const MeanError p = wp.pressure(), ref = block_average(expect);
  EXPECT_DOUBLE_EQ(p.mean, 1.0);
  EXPECT_DOUBLE_EQ(p.error, ref.error);
}

TEST(WallPressure, RejectsBadImpulsesAndAreas) {
  WallPressure wp(1.0);
  wp.add(0.0, 1.0);
  EXPECT_THROW(wp.add(0.1, -1.0), std::invalid_argument);
  EXPECT_THROW(wp.add(0.1, std::nan("")), std::invalid_argument);
  EXPECT_THROW(wp.add(0.1, kInf), std::invalid_argument);
  wp.close_block(1.0, 1.0);
  EXPECT_DOUBLE_EQ(wp.last(), 1.0);  // the rejected impulses left nothing behind
  EXPECT_THROW(WallPressure(0.0), std::invalid_argument);
  EXPECT_THROW(WallPressure(-1.0), std::invalid_argument);
}

TEST(WallPressure, SaveLoadContinuesExactly) {
  WallPressure a(3.5), b(3.5);
  for (int k = 0; k < 5; ++k) {
    a.add(k + 0.1, 0.7 * k + 0.1);
    a.close_block(1.0, 1.0 + 0.01 * k);
  }
  a.add(5.3, 0.4);  // an open block is part of the record
  b.load(a.save());
  EXPECT_EQ(b.save(), a.save());
  a.add(5.6, 1.1), b.add(5.6, 1.1);
  a.close_block(1.0, 1.0), b.close_block(1.0, 1.0);
  EXPECT_EQ(b.pressure().mean, a.pressure().mean);
  EXPECT_EQ(b.pressure().error, a.pressure().error);
  EXPECT_EQ(b.impulses(), 7u);
  WallPressure other_area(4.0);
  EXPECT_THROW(other_area.load(a.save()), std::invalid_argument);
  auto bad = a.save();
  bad.pop_back();
  EXPECT_THROW(b.load(bad), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// DensityProfiles

TEST(DensityProfiles, SlabCountsGiveTheDensities) {
  // Box 3 x 4 x 10 with walls on z, bins of 1: bin k holds k + 1 bodies of A and 2 of B.
  const Box box = box_of(Vec3(3.0, 4.0, 10.0));
  std::vector<Body> bodies;
  for (int k = 0; k < 10; ++k) {
    for (int j = 0; j <= k; ++j) bodies.push_back({Vec3(0.1 * j, 0.2, k + 0.25 + 0.05 * j), 0});
    bodies.push_back({Vec3(1.0, 1.0, k + 0.5), 1});
    bodies.push_back({Vec3(2.0, 3.9, k + 0.99), 1});
  }
  DensityProfiles prof(planes(false, false, true), box, two_species(), 1.0);
  ASSERT_EQ(prof.axes().size(), 1u);
  EXPECT_EQ(prof.axes()[0].bins, 10u);
  EXPECT_EQ(prof.axes()[0].name(), 'z');
  const State s = state_of(bodies);
  prof.sample(0.0, s, box);
  prof.sample(1.0, s, box);  // the same bodies again (velocities 0): densities unchanged
  const auto rhoA = prof.density(0, 0), rhoB = prof.density(0, 1), rho = prof.density(0);
  for (int k = 0; k < 10; ++k) {
    EXPECT_DOUBLE_EQ(rhoA[k], (k + 1) / 12.0) << k;
    EXPECT_DOUBLE_EQ(rhoB[k], 2.0 / 12.0) << k;
    EXPECT_DOUBLE_EQ(rho[k], (k + 3) / 12.0) << k;
    EXPECT_DOUBLE_EQ(prof.counts(0)[k], 2.0 * (k + 3));
  }
  // The table: header, then one row per bin, positions from the box centre.
  const auto rows = rows_of(prof.to_tsv());
  ASSERT_EQ(rows.size(), 11u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"axis", "position", "density", "density_A", "density_B"}));
  for (int k = 0; k < 10; ++k) {
    ASSERT_EQ(rows[k + 1].size(), 5u);
    EXPECT_EQ(rows[k + 1][0], "z");
    EXPECT_DOUBLE_EQ(std::stod(rows[k + 1][1]), k + 0.5 - 5.0);
    EXPECT_NEAR(std::stod(rows[k + 1][2]), (k + 3) / 12.0, 1e-10);
    EXPECT_NEAR(std::stod(rows[k + 1][3]), (k + 1) / 12.0, 1e-10);
  }
  EXPECT_NE(prof.to_tsv().find("# samples=2 "), std::string::npos);
  EXPECT_FALSE(prof.has_order());
}

TEST(DensityProfiles, BinsTileTheAxisAndEdgesCount) {
  // A requested width that does not divide L: ceil(L / bin) bins of L / bins; a centre on or
  // just beyond a wall (rounding) counts in the end bin.
  const Box box = box_of(Vec3(2.0, 2.0, 7.0));
  DensityProfiles prof(planes(true, false, true), box, {{"A", true, 0}}, 0.3);
  ASSERT_EQ(prof.axes().size(), 2u);
  EXPECT_EQ(prof.axes()[0].name(), 'x');
  EXPECT_EQ(prof.axes()[0].bins, 7u);   // 2 / 0.3 = 6.67
  EXPECT_EQ(prof.axes()[1].bins, 24u);  // 7 / 0.3 = 23.3
  EXPECT_DOUBLE_EQ(prof.axes()[1].width, 7.0 / 24.0);
  EXPECT_DOUBLE_EQ(prof.axes()[0].area, 14.0);
  EXPECT_DOUBLE_EQ(prof.axes()[1].area, 4.0);
  EXPECT_EQ(DensityProfiles(planes(false, false, true), box, {{"A", true, 0}}, 0.7).axes()[0].bins, 10u);
  prof.sample(0.0, state_of({{Vec3(0.0, 1.0, 7.0)}, {Vec3(2.0 + 1e-15, 1.0, -1e-15)}}), box);
  const auto cx = prof.counts(0), cz = prof.counts(1);
  EXPECT_EQ(cx.front(), 1.0);
  EXPECT_EQ(cx.back(), 1.0);
  EXPECT_EQ(cz.front(), 1.0);
  EXPECT_EQ(cz.back(), 1.0);
  // One block of rows per axis, x first.
  const auto rows = rows_of(prof.to_tsv());
  ASSERT_EQ(rows.size(), 1u + 7u + 24u);
  EXPECT_EQ(rows[1][0], "x");
  EXPECT_EQ(rows[8][0], "z");
}

TEST(DensityProfiles, RadialShellsUseTheShellVolumes) {
  const double R = 5.0;
  const Box box = box_of(Vec3::Constant(2.0 * R));
  DensityProfiles prof(container(R), box, two_species(), 1.0);
  ASSERT_EQ(prof.axes().size(), 1u);
  const ProfileAxis& a = prof.axes()[0];
  EXPECT_TRUE(a.radial());
  EXPECT_EQ(a.name(), 'r');
  EXPECT_EQ(a.bins, 5u);
  // shell k holds 3 (k + 1) bodies of species B, in different directions from the centre
  std::vector<Body> bodies;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 3 * (k + 1); ++j) {
      const double th = 0.37 * j, ph = 1.1 * j;
      const Vec3 dir(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      bodies.push_back({Vec3::Constant(R) + (k + 0.3 + 0.01 * j) * dir, 1});
    }
  prof.sample(0.0, state_of(bodies), box);
  const auto rho = prof.density(0, 1);
  for (int k = 0; k < 5; ++k) {
    const double shell = 4.0 / 3.0 * kPi * (std::pow(k + 1.0, 3) - std::pow(k, 3));
    EXPECT_DOUBLE_EQ(a.volume(std::size_t(k)), shell);
    EXPECT_NEAR(rho[k], 3.0 * (k + 1) / shell, 1e-14);
    EXPECT_EQ(prof.density(0, 0)[k], 0.0);
    EXPECT_DOUBLE_EQ(a.position(std::size_t(k)), k + 0.5);  // the shell's mid-radius
  }
  const auto rows = rows_of(prof.to_tsv());
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[1][0], "r");
}

TEST(DensityProfiles, UniformGasInASlitIsFlatWithinPoissonErrors) {
  pcg32 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Box box = box_of(Vec3(10.0, 10.0, 20.0));
  const std::size_t n = 2000;
  const int samples = 50;
  DensityProfiles prof(planes(false, false, true), box, {{"A", true, 0}}, 0.5);
  for (int s = 0; s < samples; ++s) {
    std::vector<Body> bodies(n);
    for (auto& b : bodies) b.r = Vec3(u(rng), u(rng), u(rng)).cwiseProduct(box.L);
    prof.sample(double(s), state_of(bodies), box);
  }
  const double rho0 = double(n) / box.volume();
  const auto rho = prof.density(0);
  const ProfileAxis& a = prof.axes()[0];
  ASSERT_EQ(rho.size(), 40u);
  double worst = 0.0, chi2 = 0.0;
  for (std::size_t k = 0; k < rho.size(); ++k) {
    // binomial count of mean n samples / 40: sd of the density sqrt(expected) / (V_bin samples)
    const double expected = rho0 * a.volume(k) * samples;
    const double sd = std::sqrt(expected * (1.0 - 1.0 / 40.0)) / (a.volume(k) * samples);
    const double z = (rho[k] - rho0) / sd;
    worst = std::max(worst, std::abs(z));
    chi2 += z * z;
  }
  EXPECT_LT(worst, 4.0);  // in standard deviations, over 40 bins
  EXPECT_LT(chi2, 40.0 + 5.0 * std::sqrt(80.0));
  RecordProperty("slit_worst_bin_sigmas", std::to_string(worst));
  // The contact extrapolation of a flat profile: rho0 within its own error bar.
  const ContactValue c = contact_density(prof, 'z', 0.5, -1, {6, 2});
  EXPECT_GT(c.poisson_error, 0.0);
  EXPECT_LT(std::abs(c.density - rho0), 4.0 * c.error);
  EXPECT_EQ(c.points, 12);
}

TEST(DensityProfiles, OrderProfileOfAlignedBodies) {
  const Box box = box_of(Vec3(4.0, 4.0, 8.0));
  // species 0: spheres (left out); 1: long axis body x; 2: long axis body z
  std::vector<ProfileSpecies> sp{{"S", true, 0}, {"X", false, 0}, {"Z", false, 2}};
  DensityProfiles prof(planes(false, false, true), box, sp, 1.0);
  ASSERT_TRUE(prof.has_order());
  const Quat x_to_z = Quat(Eigen::AngleAxisd(-0.5 * kPi, Vec3::UnitY()));  // body x -> lab z
  ASSERT_NEAR((x_to_z * Vec3::UnitX() - Vec3::UnitZ()).norm(), 0.0, 1e-15);
  const Quat spin_z = Quat(Eigen::AngleAxisd(0.7, Vec3::UnitZ()));
  std::vector<Body> bodies;
  for (int j = 0; j < 5; ++j) {
    bodies.push_back({Vec3(0.5 * j, 1.0, 0.5), 1, Quat::Identity()});  // bin 0: X along x
    bodies.push_back({Vec3(0.5 * j, 1.0, 0.6), 2, Quat(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()))});  // bin 0: Z along -y
    bodies.push_back({Vec3(0.5 * j, 2.0, 3.5), 1, x_to_z});                  // bin 3: along the normal
    bodies.push_back({Vec3(0.5 * j, 2.0, 3.7), 2, spin_z});                  // bin 3: along the normal
    bodies.push_back({Vec3(0.5 * j, 2.0, 5.5), 1, spin_z});                  // bin 5: in the plane, one direction
    bodies.push_back({Vec3(0.5 * j, 2.0, 6.5), 0, x_to_z});                  // bin 6: a sphere only
  }
  prof.sample(0.0, state_of(bodies), box);
  const auto s2 = prof.s2(0), p2 = prof.p2_normal(0), cnt = prof.order_counts(0);
  // bin 0: half along x, half along y: in the plane but not aligned with each other
  EXPECT_EQ(cnt[0], 10.0);
  EXPECT_NEAR(p2[0], -0.5, 1e-14);
  EXPECT_NEAR(s2[0], 0.25, 1e-14);  // Q = diag(1/4, 1/4, -1/2)
  EXPECT_NEAR(s2[3], 1.0, 1e-14);
  EXPECT_NEAR(p2[3], 1.0, 1e-14);
  EXPECT_NEAR(s2[5], 1.0, 1e-14);
  EXPECT_NEAR(p2[5], -0.5, 1e-14);
  EXPECT_EQ(cnt[6], 0.0);  // spheres are left out
  EXPECT_TRUE(std::isnan(s2[6]) && std::isnan(p2[6]));
  EXPECT_EQ(prof.counts(0)[6], 5.0);  // but counted in the density
  // order_profile.tsv
  const auto rows = rows_of(prof.order_tsv());
  ASSERT_EQ(rows.size(), 9u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"axis", "position", "count", "s2", "p2_normal"}));
  EXPECT_EQ(rows[4][0], "z");
  EXPECT_DOUBLE_EQ(std::stod(rows[4][1]), -0.5);
  EXPECT_EQ(rows[4][2], "10");
  EXPECT_NEAR(std::stod(rows[4][3]), 1.0, 1e-9);
  EXPECT_EQ(rows[7][3], "nan");
}

TEST(DensityProfiles, RadialOrderIsAgainstTheLocalNormal) {
  const double R = 4.0;
  const Box box = box_of(Vec3::Constant(2.0 * R));
  DensityProfiles prof(container(R), box, {{"E", false, 0}}, 1.0);
  pcg32 rng(7);
  std::normal_distribution<double> g;
  std::vector<Body> radial, tangential;
  for (int j = 0; j < 200; ++j) {
    const Vec3 n = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 t = n.cross(Vec3(g(rng), g(rng), g(rng))).normalized();
    // body x along n (radial) or along t (tangential), at radius 2.5 (shell 2)
    radial.push_back({Vec3::Constant(R) + 2.5 * n, 0, Quat::FromTwoVectors(Vec3::UnitX(), n)});
    tangential.push_back({Vec3::Constant(R) + 2.5 * n, 0, Quat::FromTwoVectors(Vec3::UnitX(), t)});
  }
  prof.sample(0.0, state_of(radial), box);
  EXPECT_NEAR(prof.p2_normal(0)[2], 1.0, 1e-12);
  EXPECT_LT(prof.s2(0)[2], 0.3);  // radial axes point every way: no common director
  prof.reset();
  prof.sample(0.0, state_of(tangential), box);
  EXPECT_NEAR(prof.p2_normal(0)[2], -0.5, 1e-12);
}

TEST(DensityProfiles, OrientationsOfBodiesBehindAreStreamed) {
  // A body stored at t = 0 spinning about z at pi/2 per unit time, sampled at t = 1: its long
  // axis x has turned to y, and it has moved by v.
  const Box box = box_of(Vec3(4.0, 4.0, 4.0));
  DensityProfiles prof(planes(false, true, false), box, {{"E", false, 0}}, 0.5);
  State s = state_of({{Vec3(1.0, 0.2, 1.0), 0, Quat::Identity()}});
  s.v[0] = Vec3(0.0, 1.0, 0.0);
  s.w[0] = Vec3(0.0, 0.0, 0.5 * kPi);
  prof.sample(1.0, s, box);
  EXPECT_EQ(prof.counts(0)[2], 1.0);  // y = 1.2
  EXPECT_NEAR(prof.p2_normal(0)[2], 1.0, 1e-12);
}

TEST(DensityProfiles, SaveLoadRoundTrip) {
  pcg32 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g;
  const Box box = box_of(Vec3(5.0, 6.0, 7.0));
  auto sp = two_species(false);
  sp[0].sphere = true;
  DensityProfiles a(planes(true, false, true), box, sp, 0.25), b(planes(true, false, true), box, sp, 0.25);
  auto draw = [&] {
    std::vector<Body> bodies(300);
    for (auto& x : bodies) {
      x.r = Vec3(u(rng), u(rng), u(rng)).cwiseProduct(box.L);
      x.species = u(rng) < 0.5 ? 0 : 1;
      x.q = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    }
    return state_of(bodies);
  };
  for (int k = 0; k < 3; ++k) a.sample(k, draw(), box);
  b.load(a.save());
  EXPECT_EQ(b.save(), a.save());
  EXPECT_EQ(b.to_tsv(), a.to_tsv());
  EXPECT_EQ(b.order_tsv(), a.order_tsv());
  const State more = draw();
  a.sample(3.0, more, box), b.sample(3.0, more, box);
  EXPECT_EQ(b.to_tsv(), a.to_tsv());
  EXPECT_EQ(b.samples(), 4);
  // Another layout refuses the record.
  DensityProfiles other_bins(planes(true, false, true), box, sp, 0.5);
  DensityProfiles other_axes(planes(false, false, true), box, sp, 0.25);
  DensityProfiles other_species(planes(true, false, true), box, {{"A", true, 0}}, 0.25);
  EXPECT_THROW(other_bins.load(a.save()), std::invalid_argument);
  EXPECT_THROW(other_axes.load(a.save()), std::invalid_argument);
  EXPECT_THROW(other_species.load(a.save()), std::invalid_argument);
}

TEST(DensityProfiles, RejectsWhatItCannotSample) {
  const Box box = box_of(Vec3(4.0, 4.0, 4.0));
  EXPECT_THROW(DensityProfiles(WallSpec{}, box, {{"A", true, 0}}, 0.1), std::invalid_argument);
  EXPECT_THROW(DensityProfiles(planes(false, false, true), box, {{"A", true, 0}}, 0.0), std::invalid_argument);
  EXPECT_THROW(DensityProfiles(planes(false, false, true), box, {}, 0.1), std::invalid_argument);
  EXPECT_THROW(DensityProfiles(planes(false, false, true), box, {{"A", true, 0}}, 1e-9), std::invalid_argument);
  DensityProfiles prof(planes(false, false, true), box, {{"A", true, 0}}, 0.1);
  EXPECT_THROW(prof.sample(0.0, state_of({{Vec3(1, 1, 1), 1}}), box), std::invalid_argument);  // species 1
  EXPECT_THROW(prof.sample(0.0, state_of({{Vec3(1, 1, 1), 0}}), box_of(Vec3(4, 4, 5))),
               std::invalid_argument);
  EXPECT_EQ(prof.samples(), 0);
  EXPECT_THROW(prof.axis_index('x'), std::invalid_argument);
  EXPECT_THROW(contact_density(prof, 'z', 0.5), std::invalid_argument);  // no samples
}

TEST(DensityProfiles, SpeciesFromTheTable) {
  SpeciesTable t(3);
  t[0].name = "S";
  t[0].shape = Sphere{0.5};
  t[1].name = "P";
  t[1].shape = Ellipsoid{1.5, 0.5, 0.5};
  t[2].name = "O";
  t[2].shape = Ellipsoid{0.4, 0.4, 1.2};
  const auto p = profile_species(t);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_TRUE(p[0].sphere);
  EXPECT_FALSE(p[1].sphere);
  EXPECT_EQ(p[1].long_axis, 0);
  EXPECT_EQ(p[2].long_axis, 2);
  EXPECT_EQ(p[2].name, "O");
  EXPECT_DOUBLE_EQ(default_profile_bin(t), 0.02 * 1.0);
}

// ---------------------------------------------------------------------------------------------
// Contact values

TEST(ContactDensity, ExactOnAQuadraticSlabProfile) {
  // rho(d) = a + b d + c d^2 in the distance d from the nearer wall, built from bodies: bins of
  // width 1 in a 3 x 4 x 20 slit (cross-section 12), so bin [d0, d0 + 1] holds
  // 12 (a + b d_m + c (d_m^2 + 1/12)) bodies (its average density, an integer), d_m its centre.
  const double a = 20.0, b = -3.0, c = 1.0;
  const Box box = box_of(Vec3(3.0, 4.0, 20.0));
  std::vector<Body> bodies;
  for (int k = 1; k < 19; ++k) {  // the bins at the walls stay empty: below contact
    const double dm = std::min(k, 19 - k) + 0.5;
    const double n = 12.0 * a + 12.0 * b * dm + c * (12.0 * dm * dm + 1.0);  // exact in doubles
    ASSERT_EQ(n, std::round(n));
    for (int j = 0; j < int(n); ++j) bodies.push_back({Vec3(0.001 * j, 1.0, k + 0.5), 0});
  }
  DensityProfiles prof(planes(false, false, true), box, {{"A", true, 0}}, 1.0);
  prof.sample(0.0, state_of(bodies), box);
  for (double xc : {0.5, 1.0}) {
    const ContactValue v = contact_density(prof, 'z', xc, -1, {6, 2});
    EXPECT_NEAR(v.density, a + b * xc + c * xc * xc, 1e-10) << xc;
    EXPECT_NEAR(v.residual_error, 0.0, 1e-9);
    EXPECT_GT(v.poisson_error, 0.0);
    EXPECT_EQ(v.error, std::max(v.poisson_error, v.residual_error));
    EXPECT_EQ(v.points, 12);  // 6 bins beyond contact at each wall
  }
  // A line is not exact on it, and says so in its residual error.
  const ContactValue lin = contact_density(prof, 'z', 0.5, -1, {6, 1});
  EXPECT_GT(std::abs(lin.density - (a + 0.5 * b + 0.25 * c)), 0.1);
  EXPECT_GT(lin.residual_error, 0.1);
  // Too many bins for the half slit.
  EXPECT_THROW(contact_density(prof, 'z', 0.5, -1, {10, 2}), std::invalid_argument);
}

TEST(ContactDensity, ExactOnAQuadraticRadialProfile) {
  // rho(x) = a + b x + c x^2 in the distance x = R - r from the container's wall; the shells'
  // counts are their exact averages (weight r^2, integrated here by a fine Simpson rule) times
  // the shell volume, loaded as a record.
  const double R = 6.0, a = 2.0, b = 0.5, c = -0.25, xc = 0.5;
  const Box box = box_of(Vec3::Constant(2.0 * R));
  DensityProfiles prof(container(R), box, {{"A", true, 0}}, 0.5);
  const ProfileAxis& ax = prof.axes()[0];
  const int samples = 3;
  std::vector<double> rec = prof.save();
  rec[1] = samples;
  const std::size_t first = 4 + 2;  // header, one axis
  for (std::size_t k = 0; k < ax.bins; ++k) {
    const double r0 = k * ax.width, r1 = (k + 1) * ax.width;
    const int m = 2000;
    double s = 0.0;
    for (int i = 0; i <= m; ++i) {
      const double r = r0 + (r1 - r0) * i / m, x = R - r;
      s += (i == 0 || i == m ? 1.0 : i % 2 ? 4.0 : 2.0) * (a + b * x + c * x * x) * 4.0 * kPi * r * r;
    }
    rec[first + k] = s * (r1 - r0) / (3.0 * m) * samples;  // particles = integral of rho dV
  }
  prof.load(rec);
  const ContactValue v = contact_density(prof, 'r', xc, -1, {5, 2});
  EXPECT_NEAR(v.density, a + b * xc + c * xc * xc, 1e-9);
  EXPECT_EQ(v.points, 5);
  // The same bins with their centres standing for them (ignoring the r^2 weight and the
  // curvature within a bin) would be off: the moments matter.
  std::vector<ContactBin> naive;
  for (int k = 0; k < 5; ++k) {
    ContactBin cb;
    const double dm = 0.5 * ax.width + (k + 1) * ax.width - xc;  // bins beyond contact
    cb.moment = {1.0, dm, dm * dm, dm * dm * dm};
    cb.density = prof.density(0)[ax.bins - 2 - std::size_t(k)];
    naive.push_back(cb);
  }
  EXPECT_GT(std::abs(fit_contact(naive, 2).density - v.density), 1e-4);
}

TEST(ContactDensity, FitErrorsAreTheLinearPropagation) {
  // A straight line through 4 bins of equal variance: the intercept's Poisson error is
  // sqrt(var x sum w_i^2) with the least-squares weights w of the intercept.
  std::vector<ContactBin> bins;
  for (int i = 0; i < 4; ++i) {
    ContactBin cb;
    const double x = 1.0 + i;
    cb.moment = {1.0, x, x * x, x * x * x};
    cb.density = 5.0 - x + (i % 2 ? 0.1 : -0.1);  // residuals +-0.1
    cb.variance = 0.04;
    bins.push_back(cb);
  }
  const ContactValue v = fit_contact(bins, 1);
  // x = 1..4: mean 2.5, Sxx = 5; intercept variance per unit noise 1/4 + 2.5^2 / 5 = 1.5
  EXPECT_NEAR(v.poisson_error, std::sqrt(0.04 * 1.5), 1e-12);
  // residuals of the fitted line (slope -1 + 0.2 * 3/5... computed): RSS / (n - 2) x 1.5
  double sx = 0, sy = 0, sxy = 0, sxx = 0;
  for (const auto& cb : bins) sx += cb.moment[1], sy += cb.density, sxy += cb.moment[1] * cb.density, sxx += cb.moment[1] * cb.moment[1];
  const double slope = (4 * sxy - sx * sy) / (4 * sxx - sx * sx), icpt = (sy - slope * sx) / 4;
  double rss = 0;
  for (const auto& cb : bins) rss += std::pow(cb.density - icpt - slope * cb.moment[1], 2);
  EXPECT_NEAR(v.density, icpt, 1e-12);
  EXPECT_NEAR(v.residual_error, std::sqrt(rss / 2.0 * 1.5), 1e-12);
  EXPECT_THROW(fit_contact(bins, 4), std::invalid_argument);
  bins.resize(1);
  EXPECT_THROW(fit_contact(bins, 1), std::invalid_argument);
}
