// Config validation: every kind of bad input gives one ConfigError naming the key (and the
// line where the file has one).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "io/config.hpp"
#include "shapes/codec.hpp"
#include "config_test_util.hpp"

using namespace hb;

namespace {
using testing_config::error_of;
using testing_config::replace;
// the shared config one line down: the line numbers asserted below count from here
const std::string kGood = std::string("\n") + testing_config::kGoodSpheres;
}  // namespace

TEST(Config, GoodConfigParsesWithDefaults) {
  const Config c = parse_config(kGood, "cfg.toml");
  EXPECT_EQ(c.particles, 256u);
  EXPECT_DOUBLE_EQ(c.packing_fraction, 0.3);
  EXPECT_EQ(c.seed, 7u);
  EXPECT_EQ(shape_name(c.one().shape), "sphere");
  EXPECT_DOUBLE_EQ(std::get<Sphere>(c.one().shape).radius, 0.5);
  EXPECT_DOUBLE_EQ(c.log_interval, 1.0);
  EXPECT_EQ(c.neighbors_method, "cells");
}

TEST(Config, ResolvedTomlRoundTrips) {
  const Config c = parse_config(kGood, "cfg.toml", {"output.log_interval=0.25"});
  const Config d = parse_config(to_toml(c), "resolved.toml");
  EXPECT_EQ(d.particles, c.particles);
  EXPECT_EQ(d.packing_fraction, c.packing_fraction);
  EXPECT_EQ(d.log_interval, 0.25);
  EXPECT_EQ(d.one().inertia, c.one().inertia);
}

TEST(Config, OverridesApply) {
  const Config c = parse_config(kGood, "cfg.toml", {"system.particles=500", "neighbors.method=nnl"});
  EXPECT_EQ(c.particles, 500u);
  EXPECT_EQ(c.neighbors_method, "nnl");
  EXPECT_NE(error_of(kGood, {"system.particles"}).find("section.key=value"), std::string::npos);
  EXPECT_NE(error_of(kGood, {"system.bogus=1"}).find("system.bogus"), std::string::npos);
}

struct BadCase {
  const char* what;
  std::string text;
  const char* expect;  // substring of the message
};

// Each case's config fails with a message containing its `expect`.
template <std::size_t N>
void expect_messages(const BadCase (&cases)[N]) {
  for (const auto& c : cases) {
    const std::string msg = error_of(c.text);
    EXPECT_NE(msg.find(c.expect), std::string::npos)
        << c.what << ": got message '" << msg << "', expected to contain '" << c.expect << "'";
  }
}

TEST(Config, BadInputNamesTheProblem) {
  const std::string g = kGood;
  const BadCase cases[] = {
      {"malformed", replace(g, "seed = 7", "seed = = 7"), "cfg.toml:5: malformed TOML"},
      {"unknown key", replace(g, "seed = 7", "sed = 7"), "cfg.toml:5: unknown key 'system.sed'"},
      {"unknown section", g + "[bogus]\nx = 1\n", "unknown section or key 'bogus'"},
      {"wrong type", replace(g, "particles = 256", "particles = \"many\""),
       "cfg.toml:3: key 'system.particles': must be an integer"},
      {"float for int", replace(g, "particles = 256", "particles = 25.6"), "system.particles"},
      {"wrong type vec", replace(g, "radius = 0.5", "radius = [1, 2]"), "shape.radius"},
      {"negative radius", replace(g, "radius = 0.5", "radius = -0.5"),
       "cfg.toml:8: key 'shape.radius': must be positive"},
      {"zero radius", replace(g, "radius = 0.5", "radius = 0.0"), "shape.radius"},
      {"nan radius", replace(g, "radius = 0.5", "radius = nan"), "must be finite"},
      {"phi too high", replace(g, "packing_fraction = 0.3", "packing_fraction = 0.74"),
       "key 'system.packing_fraction': 0.74 is not below 0.74"},
      {"N = 0", replace(g, "particles = 256", "particles = 0"), "system.particles': must be at least 1"},
      {"negative N", replace(g, "particles = 256", "particles = -3"), "system.particles"},
      {"missing key", replace(g, "particles = 256", ""), "missing key 'system.particles'"},
      {"unknown shape", replace(g, "\"sphere\"", "\"cube\""), "unknown shape type 'cube'"},
      {"time zero", replace(g, "time = 2.0", "time = 0.0"), "run.time"},
      {"method", g + "[neighbors]\nmethod = \"verlet\"\n", "neighbors.method"},
      {"init method", g + "[init]\nmethod = \"random\"\n", "init.method"},
      {"init phi0", g + "[init]\nphi0 = 0.9\n", "init.phi0"},
      {"ellipsoid without axes", replace(g, "type = \"sphere\"\nradius = 0.5", "type = \"ellipsoid\""),
       "shape.semi_axes"},
      {"ellipsoid negative axis",
       replace(g, "type = \"sphere\"\nradius = 0.5", "type = \"ellipsoid\"\nsemi_axes = [1, -1, 1]"),
       "shape.semi_axes"},
  };
  expect_messages(cases);
}

TEST(Config, MissingFileIsAConfigError) {
  try {
    load_config("/nonexistent/dir/x.toml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/x.toml: cannot open"), std::string::npos);
  }
}

TEST(Config, ShapeKeysFollowTheShapeType) {
  const std::string g = kGood;
  EXPECT_NE(error_of(replace(g, "radius = 0.5", "radius = 0.5\nexponents = [2, 2, 4]"))
                .find("cfg.toml:9: key 'shape.exponents': does not apply to shape type 'sphere' (its keys: radius)"),
            std::string::npos);
  EXPECT_NE(error_of(replace(g, "radius = 0.5", "radius = 0.5\ncolour = 1")).find("unknown key 'shape.colour'"),
            std::string::npos);
  const Config sq = parse_config(
      replace(g, "type = \"sphere\"\nradius = 0.5",
              "type = \"superquadric\"\nsemi_axes = [1.0, 0.5, 0.5]\nexponents = [2, 2, 8]"),
      "cfg.toml");
  ASSERT_TRUE(std::holds_alternative<Superquadric>(sq.one().shape));
  EXPECT_EQ(std::get<Superquadric>(sq.one().shape).p, 8.0);
  EXPECT_EQ(sq.neighbors_method, "nnl");
  EXPECT_EQ(sq.one().inertia, Vec3::Constant(0.4 * 0.25));  // 2/5 m r_min^2 by default
  // the resolved TOML round-trips the shape
  const Config back = parse_config(to_toml(sq), "resolved.toml");
  EXPECT_EQ(shape_json(back.one().shape), shape_json(sq.one().shape));
}

namespace {
const char* kMixture = R"(
[system]
packing_fraction = 0.3
[[species]]
name = "A"
count = 100
shape = { type = "sphere", radius = 0.5 }
[[species]]
name = "B"
count = 50
mass = 0.25
shape = { type = "sphere", radius = 0.25 }
polydispersity = { distribution = "gaussian", width = 0.1 }
[run]
time = 1.0
)";
}  // namespace

// --set on a key of [[species]] (an array of tables) is refused with a message, not a crash.
TEST(Config, SetCannotReachIntoSpecies) {
  EXPECT_NE(error_of(kMixture, {"species.count=3"}).find("--set 'species.count=3': 'species' is not a table"),
            std::string::npos);
}

TEST(Config, SpeciesTableParsesAndRoundTrips) {
  const Config c = parse_config(kMixture, "mix.toml");
  ASSERT_EQ(c.species.size(), 2u);
  EXPECT_TRUE(c.species_given);
  EXPECT_TRUE(c.mixture());
  EXPECT_EQ(c.particles, 150u);
  EXPECT_EQ(c.species[1].name, "B");
  EXPECT_EQ(c.species[1].mass, 0.25);
  EXPECT_EQ(c.species[1].poly.distribution, Polydispersity::Distribution::gaussian);
  // default inertia: the uniform solid (2/5 m r^2 for a sphere)
  EXPECT_DOUBLE_EQ(c.species[1].inertia.x(), 0.4 * 0.25 * 0.0625);
  const Config d = parse_config(to_toml(c), "resolved.toml");
  ASSERT_EQ(d.species.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(d.species[k].name, c.species[k].name);
    EXPECT_EQ(d.species[k].count, c.species[k].count);
    EXPECT_EQ(d.species[k].mass, c.species[k].mass);
    EXPECT_EQ(d.species[k].inertia, c.species[k].inertia);
    EXPECT_EQ(d.species[k].poly.width, c.species[k].poly.width);
    EXPECT_EQ(shape_json(d.species[k].shape), shape_json(c.species[k].shape));
  }
  // the shorthand is one species named after its shape
  const Config one = parse_config(kGood, "cfg.toml");
  ASSERT_EQ(one.species.size(), 1u);
  EXPECT_EQ(one.one().name, "sphere");
  EXPECT_FALSE(one.mixture());
}

TEST(Config, BadSpeciesNameTheKey) {
  const std::string m = kMixture;
  const BadCase cases[] = {
      {"duplicate name", replace(m, "name = \"B\"", "name = \"A\""),
       "cfg.toml:9: key 'species[1].name': duplicate species name 'A' (also species[0])"},
      {"count 0", replace(m, "count = 50", "count = 0"), "key 'species[1].count': must be at least 1"},
      {"negative mass", replace(m, "mass = 0.25", "mass = -1.0"), "key 'species[1].mass': must be positive"},
      {"inertia not positive definite", replace(m, "mass = 0.25", "mass = 0.25\ninertia = [0.1, -0.1, 0.1]"),
       "key 'species[1].inertia': principal moments must be positive"},
      {"inertia not a rigid body", replace(m, "mass = 0.25", "mass = 0.25\ninertia = [0.1, 0.1, 0.5]"),
       "key 'species[1].inertia': principal moments of a rigid body satisfy"},
      {"width 0", replace(m, "width = 0.1", "width = 0.0"), "key 'species[1].polydispersity.width': must be in (0, 0.3)"},
      {"width 0.3", replace(m, "width = 0.1", "width = 0.3"), "key 'species[1].polydispersity.width'"},
      {"distribution", replace(m, "\"gaussian\"", "\"lognormal\""), "key 'species[1].polydispersity.distribution'"},
      {"too dense", replace(m, "packing_fraction = 0.3", "packing_fraction = 0.65"),
       "key 'system.packing_fraction': 0.65 is too dense for the start of a mixture"},
      {"unknown key", replace(m, "mass = 0.25", "mass = 0.25\ncolour = 1"), "unknown key 'species[1].colour'"},
      {"sites", replace(m, "mass = 0.25", "mass = 0.25\nsites = []"), "key 'species[1].sites': square-well sites are not supported yet"},
      {"shape key", replace(m, "radius = 0.25 }", "radius = 0.25, exponents = [2, 2, 2] }"),
       "key 'species[1].shape.exponents': does not apply to shape type 'sphere'"},
      {"no name", replace(m, "name = \"B\"\n", ""), "missing key 'species[1].name'"},
      {"shape and species", m + "[shape]\ntype = \"sphere\"\nradius = 0.5\n", "[shape] and [[species]] exclude each other"},
      {"particles and species", replace(m, "packing_fraction = 0.3", "packing_fraction = 0.3\nparticles = 150"),
       "key 'system.particles': is set per species"},
      {"name with a slash", replace(m, "name = \"B\"", "name = \"B/x\""), "key 'species[1].name': must be a word"},
      {"name ..", replace(m, "name = \"B\"", "name = \"..\""), "key 'species[1].name': must be a word"},
  };
  expect_messages(cases);
}

// docs/config.md is generated from the schema: it lists every key, and it is up to date.
TEST(Config, ReferenceIsGeneratedAndUpToDate) {
  const std::string ref = config_reference();
  for (const char* key : {"`packing_fraction`", "`eps_d`", "`gr_bins`", "`growth_rate`", "`polydispersity`",
                          "type = \"superquadric\"", "`exponents`"})
    EXPECT_NE(ref.find(key), std::string::npos) << key;
  std::ifstream in(std::string(HB_SOURCE_DIR) + "/docs/config.md");
  ASSERT_TRUE(in) << "docs/config.md missing: build/apps/hardbody/hardbody config-reference > docs/config.md";
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(doc, ref) << "docs/config.md is out of date: build/apps/hardbody/hardbody config-reference > docs/config.md";
}
