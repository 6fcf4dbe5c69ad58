// The shape registry and its codec entries: every engine shape round-trips through its
// parameters, unknown names and foreign keys are errors, and the reproducer JSON is exact.
#include <gtest/gtest.h>

#include <map>
#include <stdexcept>

#include "shapes/codec.hpp"

using namespace hb;

namespace {

// Parameters held in maps: the slow, obvious reader/writer the file formats must agree with.
struct MapParams final : ParamReader, ParamWriter {
  std::map<std::string, double, std::less<>> num;
  std::map<std::string, Vec3, std::less<>> tri;
  bool has(std::string_view k) const override { return num.count(k) || tri.count(k); }
  double number(std::string_view k) const override {
    auto it = num.find(k);
    if (it == num.end()) fail(k, "missing");
    return it->second;
  }
  Vec3 triple(std::string_view k) const override {
    auto it = tri.find(k);
    if (it == tri.end()) fail(k, "missing");
    return it->second;
  }
  [[noreturn]] void fail(std::string_view k, const std::string& what) const override {
    throw std::invalid_argument(std::string(k) + ": " + what);
  }
  void number(std::string_view k, double v) override { num[std::string(k)] = v; }
  void triple(std::string_view k, const Vec3& v) override { tri[std::string(k)] = v; }
};

std::string error_of(std::string_view type, const MapParams& p) {
  try {
    decode_shape(type, p);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Registry, NamesAndCount) {
  EXPECT_EQ(shape_names(), "sphere, ellipsoid, superquadric");
  EXPECT_TRUE(is_shape_name("superquadric"));
  EXPECT_FALSE(is_shape_name("cube"));
  EXPECT_FALSE(is_shape_name(""));
  EXPECT_EQ(shape_name(AnyShape(Ellipsoid{1, 2, 3})), "ellipsoid");
  EXPECT_EQ(all_shape_keys(), (std::vector<std::string>{"radius", "semi_axes", "exponents"}));
  EXPECT_TRUE(is_shape_key("superquadric", "exponents"));
  EXPECT_FALSE(is_shape_key("ellipsoid", "exponents"));
  EXPECT_FALSE(is_shape_key("cube", "radius"));
  EXPECT_EQ(shape_keys("superquadric"), "semi_axes, exponents");
}

TEST(Registry, EveryShapeRoundTripsThroughItsCodec) {
  const AnyShape shapes[] = {Sphere{0.7}, Ellipsoid{1.5, 1.0, 0.6},
                             Superquadric{1.0, 0.8, 0.5, 2.0, 3.5, 12.0}};
  for (const AnyShape& s : shapes) {
    MapParams p;
    encode_shape(s, p);
    const AnyShape back = decode_shape(shape_name(s), p);
    ASSERT_EQ(back.index(), s.index());
    EXPECT_EQ(volume(back), volume(s));
    EXPECT_EQ(half_extents(back), half_extents(s));
    EXPECT_EQ(bounding_radius(back), bounding_radius(s));
    EXPECT_EQ(shape_json(back), shape_json(s));
  }
}

TEST(Registry, BadParametersAreNamed) {
  MapParams p;
  EXPECT_NE(error_of("cube", p).find("unknown shape type 'cube' (sphere, ellipsoid, superquadric)"),
            std::string::npos);
  EXPECT_NE(error_of("sphere", p).find("radius: missing"), std::string::npos);
  p.num["radius"] = -1.0;
  EXPECT_NE(error_of("sphere", p).find("radius: must be positive"), std::string::npos);
  p.tri["semi_axes"] = Vec3(1, 0, 1);
  EXPECT_NE(error_of("ellipsoid", p).find("semi_axes: every semi-axis must be positive"), std::string::npos);
  p.tri["semi_axes"] = Vec3(1, 1, 1);
  EXPECT_NE(error_of("superquadric", p).find("exponents: missing"), std::string::npos);
  p.tri["exponents"] = Vec3(2, 1.9, 4);
  EXPECT_NE(error_of("superquadric", p).find("exponents: every exponent must be >= 2"), std::string::npos);
}

TEST(Registry, ReproducerJsonIsFullPrecision) {
  EXPECT_EQ(shape_json(Sphere{0.1}), R"({"type": "sphere", "radius": 0.10000000000000001})");
  EXPECT_EQ(shape_json(Superquadric{1, 2, 3, 2, 2, 8}),
            R"({"type": "superquadric", "semi_axes": [1, 2, 3], "exponents": [2, 2, 8]})");
}

TEST(Registry, PackingLimits) {
  EXPECT_EQ(packing_limit(Sphere{1}).phi, 0.74);
  EXPECT_EQ(packing_limit(Ellipsoid{1, 2, 3}).phi, 0.7707);
  EXPECT_EQ(packing_limit(Superquadric{}).phi, 0.7707);
}
