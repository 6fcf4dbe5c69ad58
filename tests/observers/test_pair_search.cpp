// The g(r) pair search against its slow twin (tests/observers/pair_twin.hpp), its bounded work
// for large boxes, the automatic r_max cap, and all-or-nothing sampling under interrupts.
#include <gtest/gtest.h>

#include <csignal>
#include <pcg_random.hpp>
#include <random>
#include <set>

#include "core/interrupt.hpp"
#include "observers/pair_twin.hpp"
#include "observers/structure.hpp"

using namespace hb;
using hb::test::all_pairs_histogram;
using hb::test::centre_pairs_histogram;

namespace {

std::vector<Vec3> uniform_points(std::size_t n, const Vec3& L, pcg32& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(u(rng), u(rng), u(rng)).cwiseProduct(L);
  return p;
}

State state_at(const std::vector<Vec3>& p, std::size_t species = 1) {
  State s;
  s.resize(p.size());
  s.r = p;
  for (std::size_t i = 0; i < p.size(); ++i) s.species[i] = static_cast<std::uint16_t>((i * 7 + i / 3) % species);
  return s;
}

Box box_of(const Vec3& L) {
  Box b;
  b.L = L;
  return b;
}

// Clears a stop request however the test ends.
struct StopRequest {
  explicit StopRequest(int sig) { request_stop(sig); }
  ~StopRequest() { clear_stop(); }
};

}  // namespace

TEST(PairSearch, AllPairsMatchTheTwinForAnyCellGrid) {
  pcg32 rng(41);
  struct Case {
    Vec3 L;
    std::size_t n;
    double r_max_frac;  // of min(L)/2
    double side_frac;   // cell side as a fraction of min(L) (0: automatic)
  };
  const std::vector<Case> cases = {
      {Vec3(10, 10, 10), 600, 1.0, 1.0},     // 1 cell per side
      {Vec3(10, 10, 10), 600, 1.0, 0.5},     // 2 cells per side, r_max = L/2
      {Vec3(10, 10, 10), 600, 0.66, 1.0 / 3},  // 3 cells per side
      {Vec3(10, 10, 10), 600, 1.0, 0.0},     // automatic, r_max = L/2
      {Vec3(10, 10, 10), 2500, 0.3, 0.0},    // automatic, wider stencil
      {Vec3(6, 9, 17), 900, 1.0, 0.0},       // non-cubic, r_max = L_min/2
      {Vec3(6, 9, 17), 900, 0.5, 0.5},       // non-cubic: 2, 3, 5 cells
      {Vec3(6, 9, 17), 900, 0.9, 1.0 / 3},   // non-cubic: 3, 4, 8 cells
      {Vec3(4, 30, 31), 700, 0.8, 0.0},      // a slab
      {Vec3(12, 12, 12), 1500, 0.2, 0.05},   // cells of r_max / 2: k = 3 with the margin
      {Vec3(7, 8, 9), 2, 1.0, 0.0},          // two bodies
      {Vec3(7, 8, 9), 1, 1.0, 0.0},
      {Vec3(7, 8, 9), 0, 1.0, 0.0},
  };
  std::set<int> cells_seen;
  for (const Case& c : cases) {
    const Box box = box_of(c.L);
    auto p = uniform_points(c.n, c.L, rng);
    if (c.n > 10) {  // bodies on the faces and corners
      p[0] = Vec3::Zero();
      p[1] = Vec3(c.L.x() * (1 - 1e-15), 0.0, c.L.z() * 0.5);
      p[2] = Vec3(c.L.x() * 0.5, c.L.y() * (1 - 1e-12), c.L.z() * (1 - 1e-15));
    }
    const double r_max = 0.5 * c.L.minCoeff() * c.r_max_frac;
    PairSearch search;
    search.cell_side = c.side_frac * c.L.minCoeff();
    for (std::size_t bins : {std::size_t(1), std::size_t(37), std::size_t(300)}) {
      std::vector<std::uint64_t> fast(bins, 0), slow(bins, 0);
      const PairCount pc = pair_histogram(p, box, r_max, fast, search);
      all_pairs_histogram(p, box, r_max, slow);
      EXPECT_TRUE(pc.all_pairs);
      EXPECT_EQ(fast, slow) << "L = " << c.L.transpose() << " n = " << c.n << " bins = " << bins;
      for (int d = 0; d < 3; ++d) cells_seen.insert(pc.cells[std::size_t(d)]);
    }
  }
  for (int k : {1, 2, 3}) EXPECT_TRUE(cells_seen.count(k)) << k << " cells per side not covered";
}

TEST(PairSearch, CentreSubsetMatchesTheTwin) {
  pcg32 rng(42);
  for (const Vec3& L : {Vec3(10, 10, 10), Vec3(6, 9, 17)}) {
    const Box box = box_of(L);
    const auto p = uniform_points(1200, L, rng);
    const double r_max = 0.5 * L.minCoeff();
    for (std::size_t offset : {0, 1, 5, 1000}) {
      PairSearch search;
      search.max_pairs = 20000;  // far below N^2 / 2: a subset of centres
      search.offset = offset;
      std::vector<std::uint64_t> fast(64, 0), slow(64, 0);
      const PairCount pc = pair_histogram(p, box, r_max, fast, search);
      ASSERT_FALSE(pc.all_pairs);
      EXPECT_GE(pc.stride, 2u);
      EXPECT_EQ(pc.offset, offset % pc.stride);
      EXPECT_EQ(pc.centres, (p.size() - pc.offset + pc.stride - 1) / pc.stride);
      centre_pairs_histogram(p, box, r_max, pc.offset, pc.stride, slow);
      EXPECT_EQ(fast, slow) << "offset " << offset;
      // The work follows the budget (expected counts, so a margin for the fluctuation).
      EXPECT_LE(double(pc.distances), 1.2 * search.max_pairs);
    }
  }
}

// Regression: a large box whose r_max = L/2 leaves fewer than 3 cells per edge used to fall
// into an all-pairs loop (N = 1e5: 5e9 distances per sample). The work is now bounded by the
// budget and the result is still the right g(r).
TEST(PairSearch, WorkIsBoundedWhateverNAndRmax) {
  pcg32 rng(43);
  const std::size_t n = 100000;
  const Vec3 L = Vec3::Constant(46.0);
  const Box box = box_of(L);
  const auto p = uniform_points(n, L, rng);
  PairSearch search;
  search.max_pairs = 3e6;
  std::vector<std::uint64_t> h(50, 0);
  const PairCount pc = pair_histogram(p, box, 0.5 * L.minCoeff(), h, search);
  EXPECT_FALSE(pc.all_pairs);
  EXPECT_LE(double(pc.distances), 1.2 * search.max_pairs);
  EXPECT_GT(double(pc.distances), 0.5 * search.max_pairs);
  // One centre per call at worst: the work is at most max(max_pairs, N).
  search.max_pairs = 1.0;
  std::vector<std::uint64_t> h1(50, 0);
  const PairCount one = pair_histogram(p, box, 0.5 * L.minCoeff(), h1, search);
  EXPECT_EQ(one.centres, 1u);
  EXPECT_EQ(one.distances, n - 1);

  // Through the observer: automatic r_max, capped at max_neighbours ideal-gas neighbours.
  RdfSpec spec;
  spec.bins = 40;
  spec.max_pairs = 3e6;
  RadialDistribution rdf(spec);
  for (int k = 0; k < 3; ++k) rdf.sample(0.0, state_at(uniform_points(n, L, rng)), box);
  const double cap = std::cbrt(spec.max_neighbours * box.volume() / (4.0 / 3.0 * kPi * double(n - 1)));
  EXPECT_NEAR(rdf.r_max(), cap, 1e-9 * cap);
  EXPECT_LT(rdf.r_max(), 0.5 * L.minCoeff());
  EXPECT_EQ(rdf.subset_samples(), 3);
  // Uniform points: g = 1 in every bin within its binomial error; n(r_max) = max_neighbours.
  const auto g = rdf.g();
  const auto& pairs = rdf.pair_counts();
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double expected = double(pairs[k]) / g[k];
    EXPECT_LT(std::abs(g[k] - 1.0) * std::sqrt(expected), 5.0) << "bin " << k;
  }
  EXPECT_NEAR(rdf.coordination().back(), spec.max_neighbours, 0.01 * spec.max_neighbours);
  const std::string tsv = rdf.to_tsv();
  EXPECT_NE(tsv.find("pair_search=subset"), std::string::npos);
  EXPECT_NE(tsv.find("# r_max is below half the box: capped at 10000"), std::string::npos);
}

TEST(PairSearch, SmallSystemsKeepHalfTheBoxAndEveryPair) {
  pcg32 rng(44);
  const Vec3 L(10, 11, 12);
  RadialDistribution rdf;
  rdf.sample(0.0, state_at(uniform_points(3000, L, rng)), box_of(L));
  EXPECT_DOUBLE_EQ(rdf.r_max(), 5.0);
  EXPECT_EQ(rdf.subset_samples(), 0);
  EXPECT_DOUBLE_EQ(rdf.centres(), 3000.0);
  const std::string tsv = rdf.to_tsv();
  EXPECT_NE(tsv.find("pair_search=all centres_per_sample=3000"), std::string::npos);
  EXPECT_EQ(tsv.find("capped"), std::string::npos);
}

TEST(PairSearch, RecordsWrittenBeforeTheSubsetSearchStillLoad) {
  RdfSpec spec;
  spec.bins = 3;
  RadialDistribution rdf(spec);
  // r_max, samples, N, pair density sum, N sum, bins, 3 bins (the old layout)
  rdf.load({2.0, 2.0, 100.0, 9.9, 200.0, 3.0, 5.0, 6.0, 7.0});
  EXPECT_EQ(rdf.samples(), 2);
  EXPECT_EQ(rdf.subset_samples(), 0);
  EXPECT_DOUBLE_EQ(rdf.centres(), 200.0);
  EXPECT_EQ(rdf.pair_counts(), (std::vector<std::uint64_t>{5, 6, 7}));
  RadialDistribution again(spec);
  again.load(rdf.save());
  EXPECT_EQ(again.to_tsv(), rdf.to_tsv());
}

TEST(PartialRdf, CentreSubsetMatchesALabelledTwin) {
  pcg32 rng(45);
  const Vec3 L(7, 8, 9);
  const Box box = box_of(L);
  const auto p = uniform_points(900, L, rng);
  const State s = state_at(p, 3);
  const int bins = 30;
  const double r_max = 3.5;
  PartialRadialDistribution part(3, bins, 5000.0);  // budget far below N^2 / 2
  part.sample(0.0, s, box, r_max);
  // The same centres as pair_histogram chooses with this budget and offset 0.
  std::vector<std::uint64_t> probe(std::size_t(bins), 0);
  PairSearch search;
  search.max_pairs = 5000.0;
  const PairCount pc = pair_histogram(p, box, r_max, probe, search);
  ASSERT_FALSE(pc.all_pairs);
  std::vector<std::vector<std::uint64_t>> ref(6, std::vector<std::uint64_t>(std::size_t(bins), 0));
  for (std::size_t i = pc.offset; i < p.size(); i += pc.stride)
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (j == i) continue;
      const long k = hb::test::twin_bin(p, std::min(i, j), std::max(i, j), box, r_max, std::size_t(bins));
      if (k < 0) continue;
      const auto a = std::min(s.species[i], s.species[j]), b = std::max(s.species[i], s.species[j]);
      ++ref[part.pair_index(a, b)][std::size_t(k)];
    }
  std::vector<std::uint64_t> sum(std::size_t(bins), 0);
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t b = a; b < 3; ++b) {
      EXPECT_EQ(part.pair_counts(a, b), ref[part.pair_index(a, b)]) << a << b;
      for (int k = 0; k < bins; ++k) sum[std::size_t(k)] += part.pair_counts(a, b)[std::size_t(k)];
    }
  EXPECT_EQ(sum, probe);
}

// A stop request during a sample throws hb::Interrupted and leaves the observer as it was, so a
// checkpoint written then holds whole samples only.
TEST(PairSearch, InterruptLeavesTheObserversUnchanged) {
  pcg32 rng(46);
  const Vec3 L = Vec3::Constant(9.0);
  const Box box = box_of(L);
  const State s = state_at(uniform_points(500, L, rng), 2);
  RadialDistribution rdf;
  PartialRadialDistribution part(2, 200);
  {
    StopRequest stop(SIGINT);  // at the first sample: not even the automatic r_max is fixed
    EXPECT_THROW(rdf.sample(0.0, s, box), Interrupted);
    EXPECT_EQ(rdf.r_max(), 0.0);
    EXPECT_EQ(rdf.save(), RadialDistribution().save());
  }
  EXPECT_DOUBLE_EQ(rdf.r_max_for(box, s.size()), 4.5);
  rdf.sample(0.0, s, box);
  part.sample(0.0, s, box, rdf.r_max());
  const auto before = rdf.save();
  const auto before_part = part.save();
  {
    StopRequest stop(SIGTERM);
    try {
      rdf.sample(1.0, s, box);
      ADD_FAILURE() << "g(r) ignored the stop request";
    } catch (const Interrupted& e) {
      EXPECT_EQ(e.signal, SIGTERM);
    }
    EXPECT_THROW(part.sample(1.0, s, box, rdf.r_max()), Interrupted);
    std::vector<std::uint64_t> h(10, 0);
    EXPECT_THROW(pair_histogram(s.r, box, 4.0, h), Interrupted);
    EXPECT_EQ(h, std::vector<std::uint64_t>(10, 0));
  }
  EXPECT_EQ(rdf.save(), before);
  EXPECT_EQ(part.save(), before_part);
  rdf.commit();  // nothing pending
  EXPECT_EQ(rdf.save(), before);
  // prepare + commit is sample
  RadialDistribution twin;
  twin.load(before);
  rdf.prepare(1.0, s, box);
  EXPECT_EQ(rdf.save(), before);
  rdf.commit();
  twin.sample(1.0, s, box);
  EXPECT_EQ(rdf.save(), twin.save());
}
