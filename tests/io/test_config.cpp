// Config validation: every kind of bad input gives one ConfigError naming the key (and the
// line where the file has one).
#include <gtest/gtest.h>

#include <string>

#include "io/config.hpp"
#include "shapes/codec.hpp"

using namespace hb;

namespace {
const char* kGood = R"(
[system]
particles = 256
packing_fraction = 0.3
seed = 7
[shape]
type = "sphere"
radius = 0.5
[run]
equilibrate_time = 1.0
time = 2.0
)";

std::string error_of(const std::string& text, const std::vector<std::string>& ov = {}) {
  try {
    parse_config(text, "cfg.toml", ov);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto p = s.find(a);
  EXPECT_NE(p, std::string::npos) << a;
  return s.replace(p, a.size(), b);
}
}  // namespace

TEST(Config, GoodConfigParsesWithDefaults) {
  const Config c = parse_config(kGood, "cfg.toml");
  EXPECT_EQ(c.particles, 256u);
  EXPECT_DOUBLE_EQ(c.packing_fraction, 0.3);
  EXPECT_EQ(c.seed, 7u);
  EXPECT_EQ(shape_name(c.shape), "sphere");
  EXPECT_DOUBLE_EQ(std::get<Sphere>(c.shape).radius, 0.5);
  EXPECT_DOUBLE_EQ(c.log_interval, 1.0);
  EXPECT_EQ(c.neighbors_method, "cells");
}

TEST(Config, ResolvedTomlRoundTrips) {
  const Config c = parse_config(kGood, "cfg.toml", {"output.log_interval=0.25"});
  const Config d = parse_config(to_toml(c), "resolved.toml");
  EXPECT_EQ(d.particles, c.particles);
  EXPECT_EQ(d.packing_fraction, c.packing_fraction);
  EXPECT_EQ(d.log_interval, 0.25);
  EXPECT_EQ(d.inertia, c.inertia);
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
  for (const auto& c : cases) {
    const std::string msg = error_of(c.text);
    EXPECT_NE(msg.find(c.expect), std::string::npos)
        << c.what << ": got message '" << msg << "', expected to contain '" << c.expect << "'";
  }
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
  ASSERT_TRUE(std::holds_alternative<Superquadric>(sq.shape));
  EXPECT_EQ(std::get<Superquadric>(sq.shape).p, 8.0);
  EXPECT_EQ(sq.neighbors_method, "nnl");
  EXPECT_DOUBLE_EQ(sq.inertia, 0.4 * 0.25);  // 2/5 m r_min^2 by default
  // the resolved TOML round-trips the shape
  const Config back = parse_config(to_toml(sq), "resolved.toml");
  EXPECT_EQ(shape_json(back.shape), shape_json(sq.shape));
}
