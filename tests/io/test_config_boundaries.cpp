// The config side of boxes, walls and the thermostat (DESIGN.md "Boxes and walls",
// "Thermostat"): [box] aspect, [walls] planes / sphere and [thermostat] type / rate / during parse,
// reach --set, round-trip through config.resolved.toml, and every bad value is one ConfigError
// naming its key; box_for and packing_fraction (setup/box_setup.hpp) give the box and phi.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/config.hpp"
#include "setup/box_setup.hpp"
#include "setup/mixture_setup.hpp"
#include "setup/sphere_setup.hpp"
#include "config_test_util.hpp"

using namespace hb;

namespace {

using testing_config::error_of;
using testing_config::replace;
const std::string kGood = testing_config::kGoodSpheres;  // 256 spheres r = 0.5, phi 0.3; [system] line 1

// 256 spheres of radius 0.5 (v = pi / 6) in a container of radius 6: phi = 256 v / (4 pi 216 / 3).
const std::string kContainer = replace(kGood, "packing_fraction = 0.3\n", "") + "[walls]\nsphere = 6.0\n";
const double kSphereVolume = kPi / 6.0;
const double kContainerPhi = 256.0 * kSphereVolume / (4.0 / 3.0 * kPi * 216.0);

// The message of a config that must fail (a ConfigError: error_of lets any other exception
// through, which fails the test); "" (and a test failure) when it parses.
std::string refused(const std::string& text, const std::vector<std::string>& ov = {}) {
  const std::string msg = error_of(text, ov);
  EXPECT_FALSE(msg.empty()) << "parsed:\n" << text;
  return msg;
}

bool has(const std::string& msg, const std::string& part) { return msg.find(part) != std::string::npos; }

}  // namespace

TEST(ConfigBoundaries, DefaultsAreAPeriodicCubeWithoutThermostat) {
  const Config c = parse_config(kGood, "cfg.toml");
  EXPECT_EQ(c.boundaries.aspect, Vec3::Ones());
  EXPECT_FALSE(c.boundaries.walls.any());
  EXPECT_EQ(c.boundaries.walls.sphere_radius, 0.0);
  EXPECT_EQ(c.thermostat.type, ThermostatSpec::Type::none);
  EXPECT_EQ(c.thermostat.rate, 0.0);
  EXPECT_EQ(c.thermostat.during, ThermostatSpec::During::always);
  // the default box is cubic_box_for's cube (bit for bit), periodic along every axis
  const Box b = box_for(c);
  const Box cube = cubic_box_for(256, volume(c.one().shape), 0.3);
  EXPECT_EQ(b.L, cube.L);
  EXPECT_TRUE(b.fully_periodic());
  EXPECT_EQ(packing_fraction(c), 0.3);
  // the resolved config lists the new sections with their defaults
  const std::string t = to_toml(c);
  for (const char* part : {"[box]\naspect = [ 1.0, 1.0, 1.0 ]\n", "[walls]\nplanes = []\n", "[thermostat]\n",
                           "\ntype = 'none'\n", "\nrate = 0.0\n", "\nduring = 'always'\n"})
    EXPECT_TRUE(has(t, part)) << part << "\nnot in\n" << t;
}

TEST(ConfigBoundaries, EveryKeyParsesAndRoundTrips) {
  const std::string text = kGood + "[box]\naspect = [1.0, 1.5, 2.0]\n[walls]\nplanes = [\"z\", \"x\"]\n"
                                   "[thermostat]\ntype = \"andersen\"\nrate = 0.5\nduring = \"equilibration\"\n";
  const Config c = parse_config(text, "cfg.toml");
  EXPECT_EQ(c.boundaries.aspect, Vec3(1.0, 1.5, 2.0));
  EXPECT_EQ(c.boundaries.walls.planes, (std::array<bool, 3>{true, false, true}));
  EXPECT_FALSE(c.boundaries.walls.container());
  EXPECT_EQ(c.thermostat.type, ThermostatSpec::Type::andersen);
  EXPECT_EQ(c.thermostat.rate, 0.5);
  EXPECT_EQ(c.thermostat.during, ThermostatSpec::During::equilibration);
  const std::string t = to_toml(c);
  EXPECT_TRUE(has(t, "planes = [ 'x', 'z' ]")) << t;  // in axis order
  const Config d = parse_config(t, "resolved.toml");
  EXPECT_EQ(d.boundaries.aspect, c.boundaries.aspect);
  EXPECT_EQ(d.boundaries.walls.planes, c.boundaries.walls.planes);
  EXPECT_EQ(d.boundaries.walls.sphere_radius, 0.0);
  EXPECT_EQ(d.thermostat.type, c.thermostat.type);
  EXPECT_EQ(d.thermostat.rate, c.thermostat.rate);
  EXPECT_EQ(d.thermostat.during, c.thermostat.during);
  EXPECT_EQ(d.packing_fraction, c.packing_fraction);
  EXPECT_EQ(to_toml(d), t);  // a fixed point

  // an empty list is no walls; a rate may stand beside type "none" (unused)
  const Config e = parse_config(kGood + "[walls]\nplanes = []\n[thermostat]\nrate = 2.0\n", "cfg.toml");
  EXPECT_FALSE(e.boundaries.walls.any());
  EXPECT_FALSE(e.thermostat.active());
  EXPECT_EQ(parse_config(to_toml(e), "resolved.toml").thermostat.rate, 2.0);
}

TEST(ConfigBoundaries, ContainerSetsPhiAndRoundTrips) {
  const Config c = parse_config(kContainer, "cfg.toml");
  EXPECT_TRUE(c.boundaries.walls.container());
  EXPECT_EQ(c.boundaries.walls.sphere_radius, 6.0);
  EXPECT_NEAR(c.packing_fraction, kContainerPhi, 1e-15);
  EXPECT_EQ(packing_fraction(c), c.packing_fraction);
  const std::string t = to_toml(c);
  EXPECT_TRUE(has(t, "[walls]\nsphere = 6.0\n")) << t;
  EXPECT_FALSE(has(t, "planes")) << t;
  const Config d = parse_config(t, "resolved.toml");  // the written phi agrees with the container
  EXPECT_EQ(d.boundaries.walls.sphere_radius, 6.0);
  EXPECT_EQ(d.packing_fraction, c.packing_fraction);
  EXPECT_EQ(to_toml(d), t);
  // a given phi within 1e-6 (relative) is accepted and replaced by the container's exact one
  const Config g = parse_config(
      replace(kContainer, "seed = 7", fmt::format("seed = 7\npacking_fraction = {:.9g}", kContainerPhi * (1 + 5e-7))),
      "cfg.toml");
  EXPECT_EQ(g.packing_fraction, c.packing_fraction);
  // planes = [] beside the container is no planar walls, not a conflict
  EXPECT_TRUE(parse_config(kContainer + "planes = []\n", "cfg.toml").boundaries.walls.container());
}

TEST(ConfigBoundaries, SetReachesEveryKey) {
  const Config c = parse_config(kGood, "cfg.toml",
                                {"walls.planes=[\"z\"]", "box.aspect=[1,1,2]", "thermostat.type=andersen",
                                 "thermostat.rate=0.5", "thermostat.during=equilibration"});
  EXPECT_EQ(c.boundaries.walls.planes, (std::array<bool, 3>{false, false, true}));
  EXPECT_EQ(c.boundaries.aspect, Vec3(1, 1, 2));
  EXPECT_TRUE(c.thermostat.active());
  EXPECT_EQ(c.thermostat.rate, 0.5);
  EXPECT_EQ(c.thermostat.during, ThermostatSpec::During::equilibration);
  const Config s = parse_config(replace(kGood, "packing_fraction = 0.3\n", ""), "cfg.toml", {"walls.sphere=6"});
  EXPECT_EQ(s.boundaries.walls.sphere_radius, 6.0);
  EXPECT_NEAR(s.packing_fraction, kContainerPhi, 1e-15);
  // --set can also empty the list of a file
  EXPECT_FALSE(parse_config(kGood + "[walls]\nplanes = [\"x\"]\n", "cfg.toml", {"walls.planes=[]"})
                   .boundaries.walls.any());
  // errors of a --set value name the option, not the file
  const std::string m = refused(kGood, {"walls.planes=[\"q\"]"});
  EXPECT_TRUE(has(m, "--set walls.planes=[\"q\"]: key 'walls.planes'")) << m;
  EXPECT_FALSE(has(m, "cfg.toml")) << m;
  EXPECT_TRUE(has(refused(kGood, {"thermostat.rate=-0.5"}), "--set thermostat.rate=-0.5: key 'thermostat.rate'"));
  EXPECT_TRUE(has(refused(kGood, {"walls.plane=[\"z\"]"}), "unknown key 'walls.plane' (did you mean 'walls.planes'?)"));
}

TEST(ConfigBoundaries, BadValuesNameTheirKey) {
  const std::string g = kGood;
  struct Case {
    const char* what;
    std::string text;
    std::vector<const char*> expect;  // substrings of the message
  };
  const Case cases[] = {
      // [box]
      {"aspect zero", g + "[box]\naspect = [1, 1, 0]\n", {"cfg.toml:12: key 'box.aspect'", "positive"}},
      {"aspect negative", g + "[box]\naspect = [1, -1, 1]\n", {"key 'box.aspect'"}},
      {"aspect two numbers", g + "[box]\naspect = [1, 2]\n", {"key 'box.aspect'", "3 numbers"}},
      {"aspect nan", g + "[box]\naspect = [1, nan, 1]\n", {"key 'box.aspect'", "finite"}},
      {"aspect inf", g + "[box]\naspect = [1, inf, 1]\n", {"key 'box.aspect'", "finite"}},
      {"aspect a number", g + "[box]\naspect = 2.0\n", {"key 'box.aspect'"}},
      {"aspect thin periodic side", g + "[box]\naspect = [1, 1, 100]\n",
       {"key 'box.aspect'", "periodic box side along x", "two body lengths"}},
      // [walls] planes
      {"planes a string", g + "[walls]\nplanes = \"z\"\n", {"cfg.toml:12: key 'walls.planes'", "list of axis names"}},
      {"planes unknown axis", g + "[walls]\nplanes = [\"z\", \"w\"]\n", {"key 'walls.planes'", "\"w\" is not an axis"}},
      {"planes upper case", g + "[walls]\nplanes = [\"Z\"]\n", {"key 'walls.planes'"}},
      {"planes twice", g + "[walls]\nplanes = [\"z\", \"z\"]\n", {"key 'walls.planes'", "twice"}},
      {"planes not strings", g + "[walls]\nplanes = [3]\n", {"key 'walls.planes'"}},
      {"walled side too short", g + "[box]\naspect = [1, 1, 0.1]\n[walls]\nplanes = [\"z\"]\n",
       // V = 256 (pi/6) / 0.3; Lz = 0.1 cbrt(V / 0.1) = 1.64705; two body lengths = 2
       {"key 'walls.planes'", "along z", "1.64705", "shorter than two body lengths (2"}},
      // [walls] sphere
      {"sphere negative", replace(kContainer, "sphere = 6.0", "sphere = -6.0"), {"cfg.toml:11: key 'walls.sphere'", "positive"}},
      {"sphere zero", replace(kContainer, "sphere = 6.0", "sphere = 0.0"), {"key 'walls.sphere'", "positive"}},
      {"sphere inf", replace(kContainer, "sphere = 6.0", "sphere = inf"), {"key 'walls.sphere'", "finite"}},
      {"sphere a string", replace(kContainer, "sphere = 6.0", "sphere = \"big\""), {"key 'walls.sphere'"}},
      {"sphere and planes", kContainer + "planes = [\"z\"]\n",
       {"key 'walls.sphere'", "walls.planes and walls.sphere exclude each other"}},
      {"sphere and aspect", kContainer + "[box]\naspect = [1, 1, 2]\n", {"key 'box.aspect'", "walls.sphere"}},
      {"sphere too small for phi", g + "[walls]\nsphere = 4.5\n",
       {"key 'walls.sphere'", "the container is too small for 256 bodies at phi = 0.3: it needs radius 4.742524"}},
      {"sphere too large for phi", g + "[walls]\nsphere = 6.0\n",
       {"key 'walls.sphere'", "the container is larger than 256 bodies at phi = 0.3 need (radius 4.742524",
        "omit system.packing_fraction or set walls.sphere = 4.742524"}},
      {"sphere below two body lengths", replace(replace(kContainer, "particles = 256", "particles = 2"), "6.0", "1.9"),
       {"key 'walls.sphere'", "1.9", "below two body lengths (2"}},
      {"sphere too dense", replace(kContainer, "sphere = 6.0", "sphere = 3.5"),
       {"key 'walls.sphere'", "fill phi", "is not below"}},
      // [thermostat]
      {"type unknown", g + "[thermostat]\ntype = \"berendsen\"\n", {"cfg.toml:12: key 'thermostat.type'", "berendsen"}},
      {"type not a string", g + "[thermostat]\ntype = 1\n", {"key 'thermostat.type'"}},
      {"rate negative, type none", g + "[thermostat]\nrate = -0.1\n", {"cfg.toml:12: key 'thermostat.rate'", "negative"}},
      {"rate negative, andersen", g + "[thermostat]\ntype = \"andersen\"\nrate = -0.1\n", {"key 'thermostat.rate'"}},
      {"rate zero, andersen", g + "[thermostat]\ntype = \"andersen\"\nrate = 0.0\n", {"key 'thermostat.rate'", "positive"}},
      {"rate missing, andersen", g + "[thermostat]\ntype = \"andersen\"\n", {"key 'thermostat.rate'"}},
      {"rate inf", g + "[thermostat]\ntype = \"andersen\"\nrate = inf\n", {"key 'thermostat.rate'", "finite"}},
      {"rate nan", g + "[thermostat]\nrate = nan\n", {"key 'thermostat.rate'", "finite"}},
      {"during unknown", g + "[thermostat]\nduring = \"production\"\n", {"key 'thermostat.during'", "production"}},
      {"during equilibration without one",
       replace(g, "equilibrate_time = 1.0", "equilibrate_time = 0.0") +
           "[thermostat]\ntype = \"andersen\"\nrate = 1.0\nduring = \"equilibration\"\n",
       {"key 'thermostat.during'", "run.equilibrate_time"}},
      // phi is still required without a container
      {"no phi", replace(g, "packing_fraction = 0.3\n", ""), {"missing key 'system.packing_fraction'"}},
      {"no phi, planes", replace(g, "packing_fraction = 0.3\n", "") + "[walls]\nplanes = [\"z\"]\n",
       {"missing key 'system.packing_fraction'"}},
  };
  for (const Case& c : cases) {
    const std::string m = refused(c.text);
    for (const char* part : c.expect) EXPECT_TRUE(has(m, part)) << c.what << ": '" << m << "' lacks '" << part << "'";
    EXPECT_EQ(m.find('\n'), std::string::npos) << c.what << ": one line: " << m;
  }
}

TEST(ConfigBoundaries, BoxForFollowsAspectPlanesAndContainer) {
  const double V = 256.0 * kSphereVolume / 0.3;
  {
    const Config c = parse_config(kGood + "[box]\naspect = [1, 1, 2]\n[walls]\nplanes = [\"z\"]\n", "cfg.toml");
    const Box b = box_for(c);
    const double s = std::cbrt(V / 2.0);
    EXPECT_NEAR(b.L.x(), s, 1e-12 * s);
    EXPECT_NEAR(b.L.y(), s, 1e-12 * s);
    EXPECT_NEAR(b.L.z(), 2.0 * s, 1e-12 * s);
    EXPECT_NEAR(b.volume(), V, 1e-12 * V);
    EXPECT_EQ(b.periodic, (std::array<bool, 3>{true, true, false}));
  }
  {
    // the aspect's scale does not matter: [2, 4, 6] is [1, 2, 3]
    const Config c = parse_config(kGood + "[box]\naspect = [2, 4, 6]\n[walls]\nplanes = [\"x\", \"y\"]\n", "cfg.toml");
    const Box b = box_for(c);
    const double s = std::cbrt(V / 6.0);
    EXPECT_NEAR(b.L.x(), s, 1e-12 * s);
    EXPECT_NEAR(b.L.y(), 2.0 * s, 1e-12 * s);
    EXPECT_NEAR(b.L.z(), 3.0 * s, 1e-12 * s);
    EXPECT_EQ(b.periodic, (std::array<bool, 3>{false, false, true}));
  }
  {
    const Config c = parse_config(kContainer, "cfg.toml");
    const Box b = box_for(c);
    EXPECT_EQ(b.L, Vec3::Constant(12.0));
    EXPECT_EQ(b.periodic, (std::array<bool, 3>{false, false, false}));
    EXPECT_NEAR(packing_fraction(c), kContainerPhi, 1e-15);
    EXPECT_NEAR(container_radius_for(c, packing_fraction(c)), 6.0, 1e-12);
  }
  {
    // a polydisperse mixture: the volume of the sizes the start draws, so the grown box holds phi
    const std::string mix = R"([system]
packing_fraction = 0.2
seed = 5
[[species]]
name = "A"
count = 200
shape = { type = "ellipsoid", semi_axes = [1.0, 0.5, 0.5] }
polydispersity = { distribution = "uniform", width = 0.1 }
[[species]]
name = "B"
count = 100
shape = { type = "sphere", radius = 0.3 }
[run]
time = 1.0
[box]
aspect = [1, 1, 3]
[walls]
planes = ["z"]
)";
    const Config c = parse_config(mix, "mix.toml");
    const double v = body_volume(c.species, species_state(c.species, c.seed));
    EXPECT_EQ(total_body_volume(c), v);
    EXPECT_NE(v, 200 * volume(c.species[0].shape) + 100 * volume(c.species[1].shape));
    const Box b = box_for(c);
    EXPECT_NEAR(b.volume(), v / 0.2, 1e-12 * v / 0.2);
    EXPECT_NEAR(b.L.z() / b.L.x(), 3.0, 1e-12);
    // the body length: the largest bounding diameter at the largest drawn scale
    EXPECT_NEAR(body_length(c), 2.0 * (1.0 + std::sqrt(3.0) * 0.1), 1e-12);
  }
}

TEST(ConfigBoundaries, CheckBoundariesThrowsNamingTheKey) {
  Config c = parse_config(kGood, "cfg.toml");
  EXPECT_NO_THROW(check_boundaries(c));
  c.boundaries.walls.planes[0] = true;
  c.boundaries.aspect = Vec3(0.05, 1, 1);
  try {
    check_boundaries(c);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(has(e.what(), "cfg.toml: key 'walls.planes'")) << e.what();
  }
  c.boundaries.walls.planes[0] = false;
  c.boundaries.aspect = Vec3::Ones();
  c.boundaries.walls.sphere_radius = 1.5;
  try {
    check_boundaries(c);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(has(e.what(), "cfg.toml: key 'walls.sphere'")) << e.what();
  }
}

TEST(ConfigBoundaries, ReferenceListsTheKeys) {
  const std::string ref = config_reference();
  for (const char* part : {"## [box]", "| `aspect` | 3 numbers | [1, 1, 1] |", "## [walls]",
                           "| `planes` | list of strings | [] |", "| `sphere` | number | none |", "## [thermostat]",
                           "| `type` | string | \"none\" |", "| `rate` | number | 0 |", "| `during` | string | \"always\" |",
                           "walls.planes and walls.sphere exclude each other"})
    EXPECT_TRUE(has(ref, part)) << part;
}
