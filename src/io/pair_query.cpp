#include "io/pair_query.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <variant>

#include "contact/contact_time.hpp"
#include "geometry/distance.hpp"
#include "io/run.hpp"
#include "io/shape_io.hpp"

namespace hb {

namespace {

using json = nlohmann::json;

struct Where {
  const std::string& source;
  std::size_t line;
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}", source, line, what));
  }
};

double number(const json& j, const char* key, const Where& w) {
  if (!j.contains(key)) w.fail(fmt::format("missing key '{}'", key));
  const json& v = j.at(key);
  if (!v.is_number()) w.fail(fmt::format("key '{}' must be a number", key));
  const double x = v.get<double>();
  if (!std::isfinite(x)) w.fail(fmt::format("key '{}' must be finite", key));
  return x;
}
Eigen::VectorXd numbers(const json& j, const char* key, int n, const Where& w) {
  if (!j.contains(key)) w.fail(fmt::format("missing key '{}'", key));
  const json& v = j.at(key);
  if (!v.is_array() || int(v.size()) != n)
    w.fail(fmt::format("key '{}' must be an array of {} numbers", key, n));
  Eigen::VectorXd out(n);
  for (int k = 0; k < n; ++k) {
    if (!v[k].is_number()) w.fail(fmt::format("key '{}' must be an array of {} numbers", key, n));
    out[k] = v[k].get<double>();
    if (!std::isfinite(out[k])) w.fail(fmt::format("key '{}' must be finite", key));
  }
  return out;
}

AnyShape parse_shape(const json& j, const Where& w) {
  if (!j.is_object()) w.fail("'shape' must be an object");
  return shape_from_json(j, [&](const std::string& what) { w.fail(what); });
}

struct Body {
  AnyShape shape;
  BodyState st;
};

Body parse_body(const json& j, const char* name, bool moving, const Where& w) {
  if (!j.contains(name) || !j[name].is_object()) w.fail(fmt::format("missing object '{}'", name));
  const json& b = j[name];
  Body out{parse_shape(b.contains("shape") ? b["shape"] : json(), w), {}};
  const Eigen::VectorXd p = numbers(b, "position", 3, w);
  const Eigen::VectorXd q = numbers(b, "orientation", 4, w);
  if (!(q.norm() > 0.0)) w.fail(fmt::format("{}: orientation must be a non-zero quaternion", name));
  out.st.r = Vec3(p[0], p[1], p[2]);
  out.st.q = Quat(q[0], q[1], q[2], q[3]).normalized();
  if (moving) {
    const Eigen::VectorXd v = numbers(b, "velocity", 3, w);
    const Eigen::VectorXd om = numbers(b, "angular_velocity", 3, w);
    out.st.v = Vec3(v[0], v[1], v[2]);
    out.st.w = Vec3(om[0], om[1], om[2]);
    if (b.contains("inertia")) {  // optional: principal moments; the body rotates as that top
      const Eigen::VectorXd I = numbers(b, "inertia", 3, w);
      if (!(I.minCoeff() > 0.0)) w.fail(fmt::format("{}: key 'inertia' must be 3 positive numbers", name));
      out.st.top = spherical_top(Vec3(I[0], I[1], I[2])) ? Vec3::Zero() : Vec3(I[0], I[1], I[2]);
    }
  }
  return out;
}

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

template <class F>
std::size_t for_each_line(std::istream& in, const std::string& source, F&& f) {
  std::string line;
  std::size_t n = 0, lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const Where w{source, lineno};
    json j;
    try {
      j = json::parse(line);
    } catch (const json::parse_error& e) {
      w.fail(fmt::format("malformed JSON: {}", e.what()));
    }
    if (!j.is_object()) w.fail("each line must be a JSON object");
    f(j, w);
    ++n;
  }
  return n;
}

}  // namespace

std::size_t distance_queries(std::istream& in, std::ostream& out, const std::string& source) {
  return for_each_line(in, source, [&](const json& j, const Where& w) {
    const Body a = parse_body(j, "a", false, w), b = parse_body(j, "b", false, w);
    const Pose pa{a.st.r, a.st.q.toRotationMatrix()}, pb{b.st.r, b.st.q.toRotationMatrix()};
    std::visit(
        [&](const auto& sa, const auto& sb) {
          const DistanceResult d = distance(sa, pa, sb, pb);
          if (d.status == DistanceStatus::failed)
            throw RunFailure(fmt::format("{}:{}: distance solver failed", source, w.line));
          json o;
          o["distance"] = d.distance;
          o["point_a"] = vec(d.point_a);
          o["point_b"] = vec(d.point_b);
          out << o.dump(-1, ' ', false, json::error_handler_t::strict) << "\n";
        },
        a.shape, b.shape);
  });
}

std::size_t contact_time_queries(std::istream& in, std::ostream& out, const std::string& source,
                                 double eps_d) {
  return for_each_line(in, source, [&](const json& j, const Where& w) {
    const Body a = parse_body(j, "a", true, w), b = parse_body(j, "b", true, w);
    const double t_max = number(j, "t_max", w);
    if (!(t_max >= 0.0)) w.fail("t_max must not be negative");
    std::visit(
        [&](const auto& sa, const auto& sb) {
          using SA = std::decay_t<decltype(sa)>;
          using SB = std::decay_t<decltype(sb)>;
          ContactInput<SA, SB> in_{sa, sb, a.st, b.st, 0.0, 0.0, t_max, eps_d};
          const ContactResult r = contact_time(in_);
          if (r.status == ContactStatus::failed)
            throw RunFailure(fmt::format("{}:{}: contact-time solver failed", source, w.line));
          json o;
          if (r.status == ContactStatus::hit) {
            o["time"] = r.time;
            o["point"] = vec(r.point);
            o["normal"] = vec(r.normal);
          } else {
            o["time"] = nullptr;
            o["point"] = nullptr;
            o["normal"] = nullptr;
          }
          out << o.dump() << "\n";
        },
        a.shape, b.shape);
  });
}

}  // namespace hb
