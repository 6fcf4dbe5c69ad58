#include "io/shape_io.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/gsd_hoomd.hpp"
#include "shapes/codec.hpp"

namespace hb {

namespace {

using json = nlohmann::json;

struct JsonParams final : ParamReader {
  const json& j;
  const std::function<void(const std::string&)>& report;
  JsonParams(const json& jj, const std::function<void(const std::string&)>& f) : j(jj), report(f) {}

  [[noreturn]] void fail(std::string_view key, const std::string& what) const override {
    report(fmt::format("shape: key '{}': {}", key, what));
    throw std::logic_error("shape_from_json: the fail callback must throw");
  }
  bool has(std::string_view key) const override { return j.contains(key); }
  const json& need(std::string_view key) const {
    if (!j.contains(key)) fail(key, "missing");
    return j.at(std::string(key));
  }
  double finite(std::string_view key, const json& v) const {
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(key, "must be finite");
    return x;
  }
  double number(std::string_view key) const override {
    const json& v = need(key);
    if (!v.is_number()) fail(key, "must be a number");
    return finite(key, v);
  }
  Vec3 triple(std::string_view key) const override {
    const json& v = need(key);
    if (!v.is_array() || v.size() != 3) fail(key, "must be an array of 3 numbers");
    Vec3 out;
    for (int k = 0; k < 3; ++k) {
      if (!v[k].is_number()) fail(key, "must be an array of 3 numbers");
      out[k] = finite(key, v[k]);
    }
    return out;
  }
};

std::array<double, 3> arr(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

// GSD encodings: one overload per engine shape (a missing one is a compile error in the visit).
std::string gsd_of(const Sphere& s) { return gsd::sphere_shape(2.0 * s.radius); }
std::string gsd_of(const Ellipsoid& e) { return gsd::ellipsoid_shape(e.a, e.b, e.c); }
std::string gsd_of(const Superquadric& q) { return gsd::superquadric_shape(arr(q.axes()), arr(q.exponents())); }

}  // namespace

AnyShape shape_from_json(const json& j, const std::function<void(const std::string&)>& fail) {
  const JsonParams params(j, fail);
  if (!j.is_object()) {
    fail("'shape' must be an object");
    throw std::logic_error("shape_from_json: the fail callback must throw");
  }
  if (!j.contains("type") || !j["type"].is_string()) params.fail("type", "missing (a string)");
  const std::string type = j["type"];
  if (!is_shape_name(type))
    params.fail("type", fmt::format("unknown shape type '{}' ({})", type, shape_names()));
  for (const auto& [k, v] : j.items())
    if (k != "type" && !is_shape_key(type, k))
      params.fail(k, fmt::format("does not apply to shape type '{}' (its keys: {})", type, shape_keys(type)));
  return decode_shape(type, params);
}

json shape_to_json(const AnyShape& s) {
  struct W final : ParamWriter {
    json j;
    void number(std::string_view k, double v) override { j[std::string(k)] = v; }
    void triple(std::string_view k, const Vec3& v) override { j[std::string(k)] = {v.x(), v.y(), v.z()}; }
  } w;
  w.j["type"] = std::string(shape_name(s));
  encode_shape(s, w);
  return w.j;
}

std::string gsd_type_shape(const AnyShape& s) {
  return std::visit([](const auto& x) { return gsd_of(x); }, s);
}

}  // namespace hb
