// THE list of engine shapes: the shapes `hardbody run`, the pair queries and the Python module
// simulate. Everything that depends on "which shapes exist" derives from this file:
//  - AnyShape, the value type of a shape in a config, a species table or a query;
//  - HB_FOR_EACH_ENGINE_SHAPE, which compiles the distance and contact-time solvers once per
//    pair (the ends of geometry/distance.hpp and contact/contact_time.hpp);
//  - the codecs: every file format reads and writes a shape through its ShapeCodec entry
//    (shapes/codec.hpp) found here by name, so an unknown name is an error everywhere.
// Adding a convex shape: a shape file (the Shape concept of shapes/shape.hpp, a `kName`), one
// line in the macro and the variant below, a ShapeCodec entry, and its GSD `type_shapes`
// encoding (io/shape_io.cpp: a missing one does not compile).
#pragma once
#include <string>
#include <string_view>
#include <variant>

#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

// M(args..., S) for every engine shape S.
#define HB_FOR_EACH_ENGINE_SHAPE(M, ...) \
  M(__VA_ARGS__, Sphere)                  \
  M(__VA_ARGS__, Ellipsoid)               \
  M(__VA_ARGS__, Superquadric)

namespace hb {

using AnyShape = std::variant<Sphere, Ellipsoid, Superquadric>;

namespace registry_detail {
#define HB_COUNT_SHAPE(_, S) +1
inline constexpr std::size_t kMacroShapes = 0 HB_FOR_EACH_ENGINE_SHAPE(HB_COUNT_SHAPE, _);
#undef HB_COUNT_SHAPE
}  // namespace registry_detail
static_assert(std::variant_size_v<AnyShape> == registry_detail::kMacroShapes,
              "HB_FOR_EACH_ENGINE_SHAPE and AnyShape must list the same shapes");

// Calls f(S{}) -> bool for each engine shape type in order until it returns true.
template <class F>
bool for_each_shape_type(F&& f) {
  return [&]<std::size_t... I>(std::index_sequence<I...>) {
    return (f(std::variant_alternative_t<I, AnyShape>{}) || ...);
  }(std::make_index_sequence<std::variant_size_v<AnyShape>>{});
}

inline std::string_view shape_name(const AnyShape& s) {
  return std::visit([](const auto& x) { return std::string_view(std::decay_t<decltype(x)>::kName); }, s);
}
// "sphere, ellipsoid, superquadric" (for messages).
inline std::string shape_names() {
  std::string out;
  for_each_shape_type([&](auto s) {
    out += (out.empty() ? "" : ", ") + std::string(decltype(s)::kName);
    return false;
  });
  return out;
}
inline bool is_shape_name(std::string_view name) {
  return for_each_shape_type([&](auto s) { return name == decltype(s)::kName; });
}

inline double volume(const AnyShape& s) { return std::visit([](const auto& x) { return x.volume(); }, s); }
inline double bounding_radius(const AnyShape& s) {
  return std::visit([](const auto& x) { return x.bounding_radius(); }, s);
}
inline double inscribed_radius(const AnyShape& s) {
  return std::visit([](const auto& x) { return x.inscribed_radius(); }, s);
}
inline Vec3 half_extents(const AnyShape& s) {
  return std::visit([](const auto& x) { return Vec3(x.half_extents()); }, s);
}

// The same shape scaled about its centre by s > 0, as a shape of the same type (polydispersity:
// body i of a species is its shape resized by scale_i).
inline Sphere resized(const Sphere& x, double s) { return Sphere{x.radius * s}; }
inline Ellipsoid resized(const Ellipsoid& x, double s) { return Ellipsoid{x.a * s, x.b * s, x.c * s}; }
inline Superquadric resized(const Superquadric& x, double s) { return x.resized(s); }
inline AnyShape resized(const AnyShape& x, double s) {
  return std::visit([s](const auto& y) { return AnyShape(resized(y, s)); }, x);
}

}  // namespace hb
