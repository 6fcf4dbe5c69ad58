// Issue 13: every unknown key of a config in one message, --set errors named by the option, the
// resolved config's floats in shortest round-trip form, resource estimates, and the cell grid
// of a dilute box bounded. Each test failed before its fix.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "io/config.hpp"
#include "io/resources.hpp"
#include "neighbors/cell_list.hpp"
#include "shapes/codec.hpp"
#include "config_test_util.hpp"

using namespace hb;

namespace {

using testing_config::error_of;
const char* const kGood = testing_config::kGoodSpheres;

const char* kMixture = R"([system]
packing_fraction = 0.35
seed = 2
[[species]]
name = "big"
count = 100
shape = { type = "ellipsoid", semi_axes = [1.0, 0.5, 0.3333333333333333] }
polydispersity = { distribution = "gaussian", width = 0.1 }
[[species]]
name = "small"
count = 50
mass = 0.1
inertia = [0.1, 0.2, 0.3]
shape = { type = "sphere", radius = 0.3 }
[run]
time = 0.1
)";

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(ConfigChecks, EveryUnknownKeyInOneMessageWithPlaceAndSuggestion) {
  const std::string text = std::string(kGood) +
                           "tme = 3.0\n"          // line 11: a typo of run.time
                           "[output]\n"
                           "colour = 1\n"         // line 13: nothing near
                           "[sytem]\n"            // line 14: a typo of a section
                           "x = 1\n";
  std::string text2 = text;
  text2.replace(text2.find("seed = 7"), 8, "time = 7");  // line 4: a key of another section
  const std::string msg = error_of(text2);
  EXPECT_TRUE(has(msg, "cfg.toml:4: unknown key 'system.time' (did you mean 'run.time'?)")) << msg;
  EXPECT_TRUE(has(msg, "cfg.toml:11: unknown key 'run.tme' (did you mean 'run.time'?)")) << msg;
  EXPECT_TRUE(has(msg, "cfg.toml:13: unknown key 'output.colour'")) << msg;
  EXPECT_FALSE(has(msg, "'output.colour' (did you mean")) << msg;
  EXPECT_TRUE(has(msg, "cfg.toml:14: unknown section or key 'sytem' (did you mean [system]?)")) << msg;
  // in the order of the file, one line
  EXPECT_LT(msg.find(":4:"), msg.find(":11:"));
  EXPECT_LT(msg.find(":11:"), msg.find(":13:"));
  EXPECT_EQ(msg.find('\n'), std::string::npos);
}

TEST(ConfigChecks, UnknownKeysOfSpeciesAreReportedTogether) {
  std::string m = kMixture;
  m.replace(m.find("mass = 0.1"), 10, "mas = 0.1");
  m.replace(m.find("width = 0.1"), 11, "widht = 0.1");
  m.replace(m.find("radius = 0.3"), 12, "raduis = 0.3");
  const std::string msg = error_of(m);
  EXPECT_TRUE(has(msg, "unknown key 'species[1].mas' (did you mean 'species[1].mass'?)")) << msg;
  EXPECT_TRUE(has(msg, "unknown key 'species[0].polydispersity.widht' (did you mean "
                       "'species[0].polydispersity.width'?)")) << msg;
  EXPECT_TRUE(has(msg, "unknown key 'species[1].shape.raduis' (did you mean 'species[1].shape.radius'?)")) << msg;
}

TEST(ConfigChecks, SetErrorsNameTheOptionNotALineOfTheFile) {
  for (const auto& [ov, expect] : std::vector<std::pair<std::string, std::string>>{
           {"system.seed=abc", "--set system.seed=abc: key 'system.seed': must be an integer"},
           {"system.packing_fraction=0.9", "--set system.packing_fraction=0.9: key 'system.packing_fraction'"},
           {"system.temperature=-1", "--set system.temperature=-1: key 'system.temperature': must be positive"},
           {"shape.radius=[1, 2]", "--set shape.radius=[1, 2]: key 'shape.radius'"},
           {"system.sed=4", "--set system.sed=4: unknown key 'system.sed' (did you mean 'system.seed'?)"},
       }) {
    const std::string msg = error_of(kGood, {ov});
    EXPECT_EQ(msg.rfind(expect, 0), 0u) << ov << " -> " << msg;
    EXPECT_FALSE(has(msg, "cfg.toml:")) << msg;
  }
  // an unknown key of the file and one of --set, in one message
  const std::string both = error_of(std::string(kGood) + "colour = 2\n", {"run.tim=1"});
  EXPECT_TRUE(has(both, "cfg.toml:11: unknown key 'run.colour'; --set run.tim=1: unknown key 'run.tim'"))
      << both;
}

TEST(ConfigChecks, DirectoryOrMissingConfigIsOneClearLine) {
  const auto dir = std::filesystem::temp_directory_path();
  try {
    load_config(dir.string());
    FAIL() << "a directory was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), dir.string() + ": is a directory, not a config file");
  }
  try {
    load_config("/nonexistent/x.toml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/x.toml: cannot open config file (No such file or directory)");
  }
}

namespace {

// Every double of a shape, in the codec's order.
std::vector<double> shape_numbers(const AnyShape& s) {
  struct W final : ParamWriter {
    std::vector<double> v;
    void number(std::string_view, double x) override { v.push_back(x); }
    void triple(std::string_view, const Vec3& x) override { v.insert(v.end(), {x.x(), x.y(), x.z()}); }
  } w;
  encode_shape(s, w);
  return w.v;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

#define EXPECT_BITS(a, b) EXPECT_TRUE(same_bits(a, b)) << #a << ": " << (a) << " vs " << (b)

void expect_identical(const Config& a, const Config& b) {
  EXPECT_EQ(a.particles, b.particles);
  EXPECT_BITS(a.packing_fraction, b.packing_fraction);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_BITS(a.temperature, b.temperature);
  ASSERT_EQ(a.species.size(), b.species.size());
  for (std::size_t k = 0; k < a.species.size(); ++k) {
    const Species &x = a.species[k], &y = b.species[k];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.count, y.count);
    EXPECT_EQ(shape_name(x.shape), shape_name(y.shape));
    const auto sx = shape_numbers(x.shape), sy = shape_numbers(y.shape);
    ASSERT_EQ(sx.size(), sy.size());
    for (std::size_t i = 0; i < sx.size(); ++i) EXPECT_BITS(sx[i], sy[i]);
    EXPECT_BITS(x.mass, y.mass);
    for (int i = 0; i < 3; ++i) EXPECT_BITS(x.inertia[i], y.inertia[i]);
    EXPECT_EQ(x.poly.distribution, y.poly.distribution);
    EXPECT_BITS(x.poly.width, y.poly.width);
  }
  EXPECT_EQ(a.species_given, b.species_given);
  EXPECT_BITS(a.equilibrate_time, b.equilibrate_time);
  EXPECT_BITS(a.time, b.time);
  EXPECT_EQ(a.max_collisions, b.max_collisions);
  EXPECT_EQ(a.neighbors_method, b.neighbors_method);
  EXPECT_BITS(a.shell, b.shell);
  EXPECT_BITS(a.eps_d, b.eps_d);
  EXPECT_BITS(a.log_interval, b.log_interval);
  EXPECT_BITS(a.snapshot_interval, b.snapshot_interval);
  EXPECT_BITS(a.checkpoint_interval, b.checkpoint_interval);
  EXPECT_EQ(a.trajectory, b.trajectory);
  EXPECT_BITS(a.max_output_gb, b.max_output_gb);
  EXPECT_EQ(a.init_method, b.init_method);
  EXPECT_BITS(a.init_phi0, b.init_phi0);
  EXPECT_BITS(a.init_growth_rate, b.init_growth_rate);
  EXPECT_BITS(a.obs_interval, b.obs_interval);
  EXPECT_EQ(a.obs_origin_every, b.obs_origin_every);
  EXPECT_BITS(a.obs_max_lag, b.obs_max_lag);
  EXPECT_BITS(a.obs_q, b.obs_q);
  EXPECT_EQ(a.obs_q_vectors, b.obs_q_vectors);
  EXPECT_BITS(a.gr_interval, b.gr_interval);
  EXPECT_EQ(a.gr_bins, b.gr_bins);
}

}  // namespace

TEST(ConfigChecks, ResolvedFloatsAreShortestAndRoundTripBitwise) {
  const Config c = parse_config(kGood, "cfg.toml",
                                {"system.packing_fraction=0.1", "system.temperature=0.3333333333333333",
                                 "output.log_interval=0.05", "run.time=1e-7", "observables.q=1e300"});
  const std::string text = to_toml(c);
  EXPECT_TRUE(has(text, "packing_fraction = 0.1\n")) << text;
  EXPECT_TRUE(has(text, "temperature = 0.3333333333333333\n")) << text;
  EXPECT_TRUE(has(text, "log_interval = 0.05\n")) << text;
  EXPECT_TRUE(has(text, "phi0 = 0.1\n")) << text;  // a default
  EXPECT_TRUE(has(text, "equilibrate_time = 1.0\n")) << text;  // a float stays a float
  EXPECT_FALSE(has(text, "0000000000")) << text;
  expect_identical(c, parse_config(text, "resolved.toml"));
  const Config m = parse_config(kMixture, "mix.toml");
  const std::string mt = to_toml(m);
  EXPECT_TRUE(has(mt, "semi_axes = [ 1.0, 0.5, 0.3333333333333333 ]")) << mt;
  EXPECT_TRUE(has(mt, "inertia = [ 0.1, 0.2, 0.3 ]")) << mt;
  expect_identical(m, parse_config(mt, "resolved.toml"));
}

TEST(ConfigChecks, MemoryBeyondWhatIsAvailableIsRefusedWithBothFigures) {
  Config c = parse_config(kGood, "cfg.toml", {"system.particles=100000000"});
  const ResourceEstimate e = estimate_resources(c);
  EXPECT_GT(e.memory_bytes, 100000000 * 100.0);  // at least 100 bytes a body
  try {
    check_resources(c, 4e9);
    FAIL() << "1e8 bodies accepted in 4 GB";
  } catch (const ConfigError& err) {
    const std::string msg = err.what();
    EXPECT_TRUE(has(msg, "cfg.toml: key 'system.particles'")) << msg;
    EXPECT_TRUE(has(msg, "4 GB available")) << msg;
    EXPECT_TRUE(has(msg, fmt::format("{:.3g} GB", e.memory_bytes / 1e9))) << msg;
  }
  c.max_output_gb = 1000.0;  // (its checkpoint alone is ~50 GB)
  check_resources(c, 1e15);  // fits a big machine
  check_resources(parse_config(kGood, "cfg.toml"), 1e9);
}

TEST(ConfigChecks, OutputBeyondTheLimitIsRefusedNamingTheKey) {
  const Config c = parse_config(kGood, "cfg.toml", {"run.time=50", "output.snapshot_interval=1e-9"});
  const ResourceEstimate e = estimate_resources(c);
  EXPECT_GT(e.frames, 5e10 - 1);
  try {
    check_resources(c, 0.0);
    FAIL() << "a trajectory of 5e10 frames accepted";
  } catch (const ConfigError& err) {
    const std::string msg = err.what();
    EXPECT_TRUE(has(msg, "cfg.toml: output.snapshot_interval = 1e-09")) << msg;
    EXPECT_TRUE(has(msg, "more than output.max_output_gb = 20")) << msg;
  }
  // the limit can be raised; the log is its own figure
  Config raised = c;
  raised.max_output_gb = 1e12;
  check_resources(raised, 0.0);
  const Config rows = parse_config(kGood, "cfg.toml", {"run.time=1e6", "output.log_interval=1e-6"});
  try {
    check_resources(rows, 0.0);
    FAIL();
  } catch (const ConfigError& err) {
    EXPECT_TRUE(has(err.what(), "output.log_interval = 1e-06")) << err.what();
  }
}

TEST(ConfigChecks, DilutePackingFractionsKeepTheCellGridSmall) {
  // phi = 1e-9 for 256 unit spheres: a box of ~5100 cells a side (1.3e11 cells) before the cap
  const double L = std::cbrt(256 * kPi / 6 / 1e-9);
  CellList cells(Vec3::Constant(L), 1.0, 256);
  EXPECT_LE(double(cells.n_cells()), 64.0 * 256);
  EXPECT_GE(cells.width().minCoeff(), 1.0);
  cells.insert(0, Vec3::Constant(L * 0.999));
  EXPECT_EQ(cells.coord_of(0)[0], cells.dims()[0] - 1);
  // ordinary densities keep their grid
  const CellList dense(Vec3(10.0, 12.5, 30.0), 1.0, 4000);
  EXPECT_EQ(dense.dims(), (std::array<int, 3>{10, 12, 30}));
}

TEST(ConfigChecks, EndlessRunTimesAreRefused) {
  // the fuzz corpus' equilibrate_time = 2^63 - 1 ran for ever
  const std::string msg = error_of(kGood, {"run.equilibrate_time=9223372036854775807"});
  EXPECT_EQ(msg.rfind("--set run.equilibrate_time=9223372036854775807: key 'run.equilibrate_time': "
                      "run.equilibrate_time + run.time = 9.22e+18 is 1.84e+19 thermal times", 0), 0u) << msg;
  EXPECT_EQ(error_of(kGood, {"run.time=1e6"}), "");
}
