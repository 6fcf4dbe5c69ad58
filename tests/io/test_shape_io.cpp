// Shapes in JSON and GSD through the registry's codec: round trips, messages, and the GSD
// type_shapes entry of every engine shape (OVITO draws them).
#include <gtest/gtest.h>

#include <stdexcept>

#include "io/gsd_hoomd.hpp"
#include "io/shape_io.hpp"
#include "shapes/codec.hpp"

using namespace hb;
using nlohmann::json;

namespace {
std::string error_of(const json& j) {
  try {
    shape_from_json(j, [](const std::string& m) { throw std::invalid_argument(m); });
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ShapeIo, JsonRoundTrip) {
  const AnyShape shapes[] = {Sphere{0.3}, Ellipsoid{1.5, 1.0, 0.6},
                             Superquadric{1.0, 0.8, 0.5, 2.0, 3.5, 12.0}};
  for (const AnyShape& s : shapes) {
    const json j = shape_to_json(s);
    EXPECT_EQ(j["type"], std::string(shape_name(s)));
    const AnyShape back = shape_from_json(j, [](const std::string& m) { throw std::invalid_argument(m); });
    EXPECT_EQ(shape_json(back), shape_json(s));
    // the reproducer string is the same object
    EXPECT_EQ(json::parse(shape_json(s)), j);
  }
}

TEST(ShapeIo, JsonErrorsNameTheKey) {
  EXPECT_NE(error_of(json{{"type", "cube"}}).find("unknown shape type 'cube'"), std::string::npos);
  EXPECT_NE(error_of(json{{"radius", 1}}).find("key 'type'"), std::string::npos);
  EXPECT_NE(error_of(json{{"type", "sphere"}, {"radius", -1}}).find("key 'radius': must be positive"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"type", "sphere"}, {"radius", "big"}}).find("key 'radius': must be a number"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"type", "ellipsoid"}, {"semi_axes", {1, 2}}}).find("array of 3 numbers"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"type", "ellipsoid"}, {"semi_axes", {1, 2, 3}}, {"exponents", {2, 2, 2}}})
                .find("key 'exponents': does not apply to shape type 'ellipsoid'"),
            std::string::npos);
  EXPECT_NE(error_of(json{{"type", "superquadric"}, {"semi_axes", {1, 2, 3}}}).find("key 'exponents': missing"),
            std::string::npos);
}

TEST(ShapeIo, GsdTypeShapes) {
  EXPECT_EQ(gsd_type_shape(Sphere{0.5}), gsd::sphere_shape(1.0));
  EXPECT_EQ(gsd_type_shape(Ellipsoid{1.5, 1.0, 0.6}), gsd::ellipsoid_shape(1.5, 1.0, 0.6));
  EXPECT_EQ(gsd_type_shape(Superquadric{1.0, 0.8, 0.5, 2.0, 3.5, 12.0}),
            gsd::superquadric_shape({1.0, 0.8, 0.5}, {2.0, 3.5, 12.0}));
}
