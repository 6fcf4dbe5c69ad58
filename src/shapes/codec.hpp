// How a shape is read and written, independent of the file format. Each engine shape has one
// ShapeCodec entry naming its parameters (numbers and triples) and checking them; the formats
// (config TOML, JSON lines of the pair queries, summary.json, solver reproducers) implement
// ParamReader / ParamWriter, so they all accept the same keys with the same messages.
// decode_shape() finds the entry by the shape's name through the registry: an unknown name is an
// error naming the known ones.
#pragma once
#include <algorithm>
#include <array>
#include <vector>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "shapes/registry.hpp"

namespace hb {

// A shape's parameters in some file. number/triple are called only for keys the codec lists;
// a missing, non-numeric or non-finite value is reported by the reader itself (through fail).
class ParamReader {
 public:
  virtual ~ParamReader() = default;
  virtual bool has(std::string_view key) const = 0;
  virtual double number(std::string_view key) const = 0;
  virtual Vec3 triple(std::string_view key) const = 0;
  [[noreturn]] virtual void fail(std::string_view key, const std::string& what) const = 0;
};

class ParamWriter {
 public:
  virtual ~ParamWriter() = default;
  virtual void number(std::string_view key, double v) = 0;
  virtual void triple(std::string_view key, const Vec3& v) = 0;
};

template <class S>
struct ShapeCodec;

// Each entry: kKeys (its parameters), read (checked), write, the packing fraction a start must
// stay below (kPackingLimit, with the reason for messages) and kDoc (docs/config.md).
template <>
struct ShapeCodec<Sphere> {
  static constexpr std::array<std::string_view, 1> kKeys{"radius"};
  static constexpr double kPackingLimit = 0.74;
  static constexpr const char* kPackingNote = "the densest sphere packing is 0.7405";
  static constexpr const char* kDoc = "`radius` = r > 0";
  static Sphere read(const ParamReader& r) {
    const double radius = r.number("radius");
    if (!(radius > 0.0)) r.fail("radius", fmt::format("must be positive (got {})", radius));
    return Sphere{radius};
  }
  static void write(const Sphere& s, ParamWriter& w) { w.number("radius", s.radius); }
};

inline Vec3 read_semi_axes(const ParamReader& r) {
  const Vec3 a = r.triple("semi_axes");
  if (!(a.minCoeff() > 0.0)) r.fail("semi_axes", "every semi-axis must be positive");
  return a;
}

template <>
struct ShapeCodec<Ellipsoid> {
  static constexpr std::array<std::string_view, 1> kKeys{"semi_axes"};
  static constexpr double kPackingLimit = 0.7707;
  static constexpr const char* kPackingNote = "the densest known ellipsoid packing";
  static constexpr const char* kDoc = "`semi_axes` = [a, b, c] > 0 along body x, y, z";
  static Ellipsoid read(const ParamReader& r) {
    const Vec3 a = read_semi_axes(r);
    return Ellipsoid{a.x(), a.y(), a.z()};
  }
  static void write(const Ellipsoid& s, ParamWriter& w) { w.triple("semi_axes", Vec3(s.a, s.b, s.c)); }
};

template <>
struct ShapeCodec<Superquadric> {
  static constexpr std::array<std::string_view, 2> kKeys{"semi_axes", "exponents"};
  static constexpr double kPackingLimit = 0.7707;  // as ellipsoids (the p = 2 case); no tighter bound known to us
  static constexpr const char* kPackingNote = "the densest known ellipsoid packing";
  static constexpr const char* kDoc =
      "`semi_axes` = [a, b, c] > 0 and `exponents` = [n, m, p] >= 2: |x/a|^n + |y/b|^m + |z/c|^p <= 1";
  static Superquadric read(const ParamReader& r) {
    const Vec3 a = read_semi_axes(r);
    const Vec3 e = r.triple("exponents");
    if (!(e.minCoeff() >= 2.0)) r.fail("exponents", "every exponent must be >= 2 (smooth convex body)");
    return Superquadric{a.x(), a.y(), a.z(), e.x(), e.y(), e.z()};
  }
  static void write(const Superquadric& s, ParamWriter& w) {
    w.triple("semi_axes", s.axes());
    w.triple("exponents", s.exponents());
  }
};

// Whether `key` is a parameter of the shape named `type` (false for an unknown type).
inline bool is_shape_key(std::string_view type, std::string_view key) {
  bool found = false;
  for_each_shape_type([&](auto s) {
    using S = decltype(s);
    if (type != S::kName) return false;
    for (auto k : ShapeCodec<S>::kKeys) found = found || k == key;
    return true;
  });
  return found;
}
// "radius" / "semi_axes, exponents": the keys of the shape named `type`.
inline std::string shape_keys(std::string_view type) {
  std::string out;
  for_each_shape_type([&](auto s) {
    using S = decltype(s);
    if (type != S::kName) return false;
    for (auto k : ShapeCodec<S>::kKeys) out += (out.empty() ? "" : ", ") + std::string(k);
    return true;
  });
  return out;
}

// The shape named `type` from its parameters; `type_key` names the type field in messages.
inline AnyShape decode_shape(std::string_view type, const ParamReader& r,
                             std::string_view type_key = "type") {
  AnyShape out;
  const bool known = for_each_shape_type([&](auto s) {
    using S = decltype(s);
    if (type != S::kName) return false;
    out = ShapeCodec<S>::read(r);
    return true;
  });
  if (!known)
    r.fail(type_key, fmt::format("unknown shape type '{}' ({})", type, shape_names()));
  return out;
}

// Every parameter key of any engine shape (the schema of a config's shape table).
inline std::vector<std::string> all_shape_keys() {
  std::vector<std::string> out;
  for_each_shape_type([&](auto s) {
    for (auto k : ShapeCodec<decltype(s)>::kKeys)
      if (std::find(out.begin(), out.end(), k) == out.end()) out.emplace_back(k);
    return false;
  });
  return out;
}

struct PackingLimit {
  double phi;
  const char* note;
};
inline PackingLimit packing_limit(const AnyShape& s) {
  return std::visit([](const auto& x) {
    using C = ShapeCodec<std::decay_t<decltype(x)>>;
    return PackingLimit{C::kPackingLimit, C::kPackingNote};
  }, s);
}

// Writes the shape's parameters (not its type name: see shape_name).
inline void encode_shape(const AnyShape& s, ParamWriter& w) {
  std::visit([&](const auto& x) { ShapeCodec<std::decay_t<decltype(x)>>::write(x, w); }, s);
}

// One-line JSON of a shape in the `hardbody distance` input format (full precision), for
// solver-failure reproducers; a format-free writer so that the solver layers need no JSON library.
inline std::string shape_json(const AnyShape& s) {
  struct W : ParamWriter {
    std::string out;
    void number(std::string_view k, double v) override { out += fmt::format(", \"{}\": {:.17g}", k, v); }
    void triple(std::string_view k, const Vec3& v) override {
      out += fmt::format(", \"{}\": [{:.17g}, {:.17g}, {:.17g}]", k, v.x(), v.y(), v.z());
    }
  } w;
  encode_shape(s, w);
  return fmt::format("{{\"type\": \"{}\"{}}}", shape_name(s), w.out);
}

}  // namespace hb
