#include "io/pair_query.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string_view>
#include <variant>
#include <vector>

#include "contact/contact_time.hpp"
#include "geometry/distance.hpp"
#include "geometry/penetration.hpp"
#include "io/run.hpp"
#include "io/shape_io.hpp"
#include "io/suggest.hpp"
#include "shapes/codec.hpp"

namespace hb {

namespace {

using json = nlohmann::json;

// Numbers in messages: given values in the shortest form that reads back the same ("1e+200",
// "0.1"), derived limits to 3 digits.
std::string num(double x) { return fmt::format("{}", x); }
std::string approx(double x) { return fmt::format("{:.3g}", x); }

struct Where {
  const std::string& source;
  std::size_t line;
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}", source, line, what));
  }
};

// ---- unknown keys ----------------------------------------------------------------------------

// The keys of the format. The moving-body keys and t_max are known to both commands (a
// contact-time line can be given to `hardbody distance`, which ignores them).
const std::vector<std::string> kTopKeys{"a", "b", "t_max"};
const std::vector<std::string> kBodyKeys{"shape",    "position",         "orientation",
                                         "velocity", "angular_velocity", "inertia"};

std::vector<std::string> shape_key_list(const std::string& type) {
  std::vector<std::string> out{"type"};
  for_each_shape_type([&](auto s) {
    using S = decltype(s);
    if (type != S::kName) return false;
    for (auto k : ShapeCodec<S>::kKeys) out.emplace_back(k);
    return true;
  });
  return out;
}

void unknown_keys(const json& j, const std::vector<std::string>& known, const std::string& prefix,
                  std::vector<std::string>& out) {
  if (!j.is_object()) return;
  for (const auto& [k, v] : j.items())
    if (std::find(known.begin(), known.end(), k) == known.end())
      out.push_back(fmt::format("'{}{}'{}", prefix, k, did_you_mean(k, known)));
}

// Every unknown key of the line (top level, bodies, shapes of a known type), in one message.
void check_keys(const json& j, const Where& w) {
  std::vector<std::string> bad;
  unknown_keys(j, kTopKeys, "", bad);
  for (const char* name : {"a", "b"}) {
    if (!j.contains(name)) continue;
    const json& b = j[name];
    unknown_keys(b, kBodyKeys, std::string(name) + ".", bad);
    if (!b.is_object() || !b.contains("shape")) continue;
    const json& s = b["shape"];
    if (s.is_object() && s.contains("type") && s["type"].is_string() &&
        is_shape_name(s["type"].get<std::string>()))
      unknown_keys(s, shape_key_list(s["type"].get<std::string>()),
                   std::string(name) + ".shape.", bad);
  }
  if (bad.empty()) return;
  std::string list;
  for (const auto& b : bad) list += (list.empty() ? "" : ", ") + b;
  w.fail(fmt::format("unknown key{} {}", bad.size() > 1 ? "s" : "", list));
}

// ---- values ----------------------------------------------------------------------------------

double number(const json& j, const std::string& key, const std::string& name, const Where& w) {
  if (!j.contains(key)) w.fail(fmt::format("missing key '{}'", name));
  const json& v = j.at(key);
  if (!v.is_number()) w.fail(fmt::format("key '{}' must be a number", name));
  const double x = v.get<double>();
  if (!std::isfinite(x)) w.fail(fmt::format("key '{}' must be finite", name));
  return x;
}
Eigen::VectorXd numbers(const json& j, const std::string& key, int n, const std::string& name,
                        const Where& w) {
  if (!j.contains(key)) w.fail(fmt::format("missing key '{}'", name));
  const json& v = j.at(key);
  const std::string want = fmt::format("key '{}' must be an array of {} numbers", name, n);
  if (!v.is_array() || int(v.size()) != n) w.fail(want);
  Eigen::VectorXd out(n);
  for (int k = 0; k < n; ++k) {
    if (!v[k].is_number()) w.fail(want);
    out[k] = v[k].get<double>();
    if (!std::isfinite(out[k])) w.fail(fmt::format("key '{}' must be finite", name));
  }
  return out;
}
Vec3 triple(const json& j, const std::string& key, const std::string& body, const Where& w) {
  const Eigen::VectorXd v = numbers(j, key, 3, body + "." + key, w);
  return Vec3(v[0], v[1], v[2]);
}

// A unit quaternion from any non-zero one. Its components are first divided by the largest
// |component|: the squares then lie in [0, 1] with one of them 1, so the norm neither
// underflows (components ~1e-170 square to 0) nor loses digits in subnormals (~1e-160), nor
// overflows (~1e170).
Quat unit_quaternion(const Eigen::VectorXd& q, const std::string& name, const Where& w) {
  const double m = q.cwiseAbs().maxCoeff();
  if (!(m > 0.0)) w.fail(fmt::format("key '{}' must be a non-zero quaternion", name));
  const Eigen::Vector4d u = q / m;
  return Quat(u[0], u[1], u[2], u[3]).normalized();
}

struct Body {
  AnyShape shape;
  BodyState st;
};

Body parse_body(const json& j, const char* name, bool moving, const Where& w) {
  if (!j.contains(name) || !j[name].is_object()) w.fail(fmt::format("missing object '{}'", name));
  const json& b = j[name];
  if (!b.contains("shape")) w.fail(fmt::format("missing key '{}.shape'", name));
  if (!b["shape"].is_object()) w.fail(fmt::format("key '{}.shape' must be an object", name));
  Body out{shape_from_json(b["shape"], [&](const std::string& what) { w.fail(fmt::format("{}.{}", name, what)); }),
           {}};
  out.st.r = triple(b, "position", name, w);
  out.st.q = unit_quaternion(numbers(b, "orientation", 4, std::string(name) + ".orientation", w),
                             std::string(name) + ".orientation", w);
  if (moving) {
    out.st.v = triple(b, "velocity", name, w);
    out.st.w = triple(b, "angular_velocity", name, w);
    if (b.contains("inertia")) {  // optional: principal moments; the body rotates as that top
      const Vec3 I = triple(b, "inertia", name, w);
      if (!(I.minCoeff() > 0.0)) w.fail(fmt::format("key '{}.inertia' must be 3 positive numbers", name));
      out.st.top = spherical_top(I) ? Vec3::Zero() : I;
    }
  }
  return out;
}

// ---- units of the pair -----------------------------------------------------------------------
//
// A query is solved in units of the pair's size: lengths are divided by s, the power of two at or
// just below the larger bounding radius, and positions are taken relative to A's centre. Dividing
// by a power of two is exact, so a copy of a pair scaled by 2^k gives exactly the scaled answer,
// and bodies of size 1e200 or 1e-200 meet the solvers' tolerances (absolute ones among them) at
// size ~1. Times are unchanged: velocities scale like lengths, angular velocities not at all.
struct Units {
  double s = 1.0;         // length unit
  Vec3 origin;            // A's centre
  Body a, b;              // in these units
};

Units pair_units(const Body& a, const Body& b, const Where& w) {
  const double La = bounding_radius(a.shape), Lb = bounding_radius(b.shape);
  const double la = inscribed_radius(a.shape), lb = inscribed_radius(b.shape);
  for (const auto& [name, l] : {std::pair{"a", la}, std::pair{"b", lb}})
    if (!(l >= DBL_MIN))
      w.fail(fmt::format("key '{}.shape': size {} is below the smallest normal double ({}): no "
                         "digits left to compute with", name, approx(l), approx(DBL_MIN)));
  // Within a factor 1e100 the squares and inverse squares the solvers form stay far from
  // overflow and underflow in units of the pair (an ellipsoid [2, 1e150, 5e299] gave NaN).
  if (std::min(la, lb) < 1e-100 * std::max(La, Lb))
    w.fail(fmt::format("the lengths of the pair span more than a factor 1e100 (smallest "
                       "inscribed radius {}, largest bounding radius {})",
                       approx(std::min(la, lb)), approx(std::max(La, Lb))));
  Units u;
  u.s = std::ldexp(1.0, std::ilogb(std::max(La, Lb)));
  const double inv = std::ldexp(1.0, -std::ilogb(std::max(La, Lb)));
  u.origin = a.st.r;
  u.a = a;
  u.b = b;
  u.a.shape = resized(a.shape, inv);
  u.b.shape = resized(b.shape, inv);
  u.a.st.r = Vec3::Zero();
  u.b.st.r = (b.st.r - a.st.r) * inv;
  if (!(u.b.st.r.stableNorm() <= 1e100))
    w.fail(fmt::format("the bodies are {} apart, more than 1e100 times their size {}: beyond what "
                       "the solvers resolve", approx((b.st.r - a.st.r).stableNorm()), approx(std::max(La, Lb))));
  u.a.st.v *= inv;
  u.b.st.v *= inv;
  for (const auto& [name, v] : {std::pair{"a", &u.a.st.v}, std::pair{"b", &u.b.st.v}})
    if (!v->allFinite())
      w.fail(fmt::format("key '{}.velocity' overflows a double in units of the body size ({})",
                         name, approx(u.s)));
  return u;
}

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// ---- lines -----------------------------------------------------------------------------------

// A library message without its "[json.exception.parse_error.101] " tag.
std::string without_id(const std::string& what) {
  const auto end = what.find("] ");
  return what.rfind("[json.exception.", 0) == 0 && end != std::string::npos ? what.substr(end + 2) : what;
}

// Parses one line, naming the key whose value is a number too large for a double (nlohmann
// reports only the token): a parser callback follows the path of keys to the current value.
json parse_line(const std::string& line, const Where& w) {
  std::vector<std::string> path;  // keys of the enclosing objects
  std::string key;                // the key whose value is being read
  const json::parser_callback_t track = [&](int, json::parse_event_t ev, json& parsed) {
    switch (ev) {
      case json::parse_event_t::key:
        key = parsed.get<std::string>();
        break;
      case json::parse_event_t::object_start:
        path.push_back(key);
        key.clear();
        break;
      case json::parse_event_t::object_end:
        if (!path.empty()) {
          key = path.back();
          path.pop_back();
        }
        break;
      default:
        break;
    }
    return true;
  };
  try {
    return json::parse(line, track);
  } catch (const json::parse_error& e) {
    w.fail(fmt::format("malformed JSON: {}", without_id(e.what())));
  } catch (const json::exception& e) {
    std::string name;
    for (std::size_t k = 1; k < path.size(); ++k) name += path[k] + ".";
    name += key;
    std::string what = without_id(e.what());
    if (e.id == 406) {  // "number overflow parsing '1e400'"
      const auto q = what.find('\'');
      what = fmt::format("number {} is out of the range of a double (|x| < {})",
                         q == std::string::npos ? "" : what.substr(q), approx(DBL_MAX));
    }
    w.fail(name.empty() ? what : fmt::format("key '{}': {}", name, what));
  }
}

template <class F>
std::size_t for_each_line(std::istream& in, const std::string& source, F&& f) {
  std::string line;
  std::size_t n = 0, lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const Where w{source, lineno};
    const json j = parse_line(line, w);
    if (!j.is_object()) w.fail("each line must be a JSON object");
    check_keys(j, w);
    f(j, w);
    ++n;
  }
  if (in.bad()) throw InputError(fmt::format("{}: read error after line {}", source, lineno));
  return n;
}

Pose pose_of(const BodyState& b) { return Pose{b.r, b.q.toRotationMatrix()}; }

}  // namespace

std::size_t distance_queries(std::istream& in, std::ostream& out, const std::string& source) {
  return for_each_line(in, source, [&](const json& j, const Where& w) {
    const Body a = parse_body(j, "a", false, w);  // (a first: its errors are reported first)
    const Body b = parse_body(j, "b", false, w);
    const Units u = pair_units(a, b, w);
    const Pose pa = pose_of(u.a.st), pb = pose_of(u.b.st);
    DistanceResult d = std::visit(
        [&](const auto& sa, const auto& sb) { return distance(sa, pa, sb, pb); }, u.a.shape, u.b.shape);
    // Overlapping (or unsolved): the contact equations give a stationary point of the gap over
    // directions, not necessarily the deepest one; the contract asks for the penetration depth
    // (the shortest separating translation) and its points: the global maximum of the gap.
    if (d.status == DistanceStatus::failed || d.distance < 0.0) {
      std::vector<Vec3> hints;
      if (d.normal.allFinite()) hints.push_back(d.normal);
      const PenetrationResult p = penetration(u.a.shape, pa, u.b.shape, pb, hints);
      if (d.status != DistanceStatus::failed || p.certified) {
        d.status = DistanceStatus::converged;
        d.distance = p.distance;
        d.point_a = p.point_a;
        d.point_b = p.point_b;
        if (!p.certified)
          fmt::print(stderr,
                     "hardbody: warning: {}:{}: the penetration depth is certified only to lie in "
                     "[{}, {}] (the deepest pair found is reported)\n",
                     source, w.line, num(-u.s * p.upper_bound), num(-u.s * p.distance));
      }
    }
    if (d.status == DistanceStatus::failed)
      throw RunFailure(fmt::format("{}:{}: distance solver failed", source, w.line));
    json o;
    o["distance"] = u.s * d.distance;
    o["point_a"] = vec(u.origin + u.s * d.point_a);
    o["point_b"] = vec(u.origin + u.s * d.point_b);
    if (!std::isfinite(u.s * d.distance) || !d.point_a.allFinite() || !d.point_b.allFinite())
      throw RunFailure(fmt::format("{}:{}: the distance solver returned a non-finite result", source, w.line));
    out << o.dump(-1, ' ', false, json::error_handler_t::strict) << "\n";
  });
}

namespace {

// End of the time the bodies can touch: |r_AB(t)| <= L_A + L_B (bounding spheres), within
// [0, t_max]; -1 when they cannot meet at all. With u the unit relative velocity and speed c,
// |r + c u t|^2 = R^2 has the roots t = (-r.u +- sqrt((r.u)^2 - (|r|^2 - R^2))) / c.
double meeting_end(const Units& u, double t_max) {
  const Vec3 r = u.b.st.r - u.a.st.r, v = u.b.st.v - u.a.st.v;
  const double R = bounding_radius(u.a.shape) + bounding_radius(u.b.shape);
  const double c = v.stableNorm();
  if (!(c > 0.0)) return r.stableNorm() <= R ? t_max : -1.0;
  const Vec3 e = v / c;
  const double ru = r.dot(e), disc = ru * ru - (r.squaredNorm() - R * R);
  if (disc < 0.0) return -1.0;
  const double hi = (-ru + std::sqrt(disc)) / c;
  return hi < 0.0 ? -1.0 : std::min(hi, t_max);
}

// Inputs whose contact the solver cannot resolve to eps_d are refused (a silent `null`, or a
// search of 10^7 steps that fails after minutes, was what they gave). In units of the pair:
//  - eps_d: the search's distance accuracy. It must be well below the bodies (<= 0.1 l, l the
//    smaller inscribed radius): above, one step spans the whole approach and a contact between
//    two samples is looked for only as a single minimum of d(t). It must be above the rounding
//    of the distance (>= 1e-13 l, the solver's tolerances being ~1e-12 of the size).
//  - angular velocity: the orientation at time t comes from the angle |w| t, rounded to
//    2.2e-16 |w| t, which moves the surface by that times L. Over the time the bodies can touch
//    (t_end, bounding spheres) this must stay below eps_d. A top that is not spherical spins at
//    most |w| I_max / I_min.
//  - positions: r_B - r_A at time t carries the rounding 2.2e-16 (|r_AB(0)| + |v_AB| t_end),
//    which must stay below eps_d too.
void check_resolvable(const Units& u, double eps_d, double t_max, const Where& w) {
  const double l = std::min(inscribed_radius(u.a.shape), inscribed_radius(u.b.shape));
  const double e = eps_d / u.s;
  if (!(e <= 0.1 * l))
    w.fail(fmt::format("--eps-d {} is not small against the bodies: it must be at most 0.1 x the "
                       "smaller inscribed radius {}, i.e. <= {}", num(eps_d), num(u.s * l), approx(0.1 * u.s * l)));
  if (!(e >= 1e-13 * l))
    w.fail(fmt::format("--eps-d {} is below the rounding of distances between these bodies: it "
                       "must be at least 1e-13 x the smaller inscribed radius {}, i.e. >= {}",
                       num(eps_d), num(u.s * l), approx(1e-13 * u.s * l)));
  const double t_end = meeting_end(u, t_max);
  if (!(t_end > 0.0)) return;  // they cannot meet after t = 0 (t = 0 itself needs no motion)
  constexpr double eps = DBL_EPSILON;
  for (const auto& [name, b] : {std::pair{"a", &u.a}, std::pair{"b", &u.b}}) {
    const Vec3 I = b->st.top;
    const double w0 = b->st.w.stableNorm();  // (no overflow for |w| ~ 1e300)
    const double spin = w0 * (spherical_top(I) ? 1.0 : I.maxCoeff() / I.minCoeff());
    const double L = bounding_radius(b->shape);
    if (eps * spin * t_end * L > e)
      w.fail(fmt::format("key '{}.angular_velocity': |w| = {} turns the body by {} rad while the "
                         "bodies can touch (until t = {}); at that angle rounding moves its surface "
                         "by more than eps_d = {} (it needs |w| t < {} rad)", name,
                         approx(w0), approx(spin * t_end), approx(t_end), num(eps_d),
                         approx(e / (eps * L))));
  }
  const Vec3 r = u.b.st.r - u.a.st.r, v = u.b.st.v - u.a.st.v;
  if (eps * (r.stableNorm() + v.stableNorm() * t_end) > e)
    w.fail(fmt::format("key 'b.position': the bodies start {} apart and meet only after moving that "
                       "far; the rounding of their positions then exceeds eps_d = {}",
                       approx(u.s * r.stableNorm()), num(eps_d)));
}

}  // namespace

std::size_t contact_time_queries(std::istream& in, std::ostream& out, const std::string& source,
                                 double eps_d) {
  if (!(eps_d > 0.0) || !std::isfinite(eps_d))
    throw InputError(fmt::format("--eps-d must be a positive number (got {})", num(eps_d)));
  return for_each_line(in, source, [&](const json& j, const Where& w) {
    const Body a = parse_body(j, "a", true, w), b = parse_body(j, "b", true, w);
    const double t_max = number(j, "t_max", "t_max", w);
    if (!(t_max >= 0.0)) w.fail(fmt::format("key 't_max' must not be negative (got {})", num(t_max)));
    Units u = pair_units(a, b, w);
    check_resolvable(u, eps_d, t_max, w);
    // Time unit: the power of two at or below 1 / K, K = |v_B - v_A| + |w_A| L_A + |w_B| L_B
    // the distance-rate bound in units of the pair, so that the solver sees rates ~1 whatever
    // the speeds (2e299 body sizes per unit time failed). Exact, like the length unit: velocities
    // and angular velocities are multiplied by tau, t_max divided by it, the time multiplied back.
    const double K = (u.b.st.v - u.a.st.v).stableNorm() +
                     u.a.st.w.stableNorm() * bounding_radius(u.a.shape) +
                     u.b.st.w.stableNorm() * bounding_radius(u.b.shape);
    if (!std::isfinite(K)) w.fail("the velocities overflow a double in units of the bodies' size");
    const int k = K > 0.0 ? std::ilogb(K) : 0;
    const double tau = std::ldexp(1.0, -k);
    for (BodyState* st : {&u.a.st, &u.b.st}) {
      st->v *= tau;
      st->w *= tau;
    }
    const double t_end = t_max * std::ldexp(1.0, k);  // (inf if it overflows: an open window)
    // An empty window [0, 0]: the separating-axis advancement would drop a touching pair (its
    // gap 0 is not below the reach K (t_max - t) = 0); without it the solver looks at t = 0
    // only, where touching and approaching is a contact.
    ContactOptions opt;
    if (t_max == 0.0) opt.separating_axis = false;
    std::visit(
        [&](const auto& sa, const auto& sb) {
          using SA = std::decay_t<decltype(sa)>;
          using SB = std::decay_t<decltype(sb)>;
          ContactInput<SA, SB> in_{sa, sb, u.a.st, u.b.st, 0.0, 0.0, t_end, eps_d / u.s};
          const ContactResult r = contact_time(in_, opt);
          if (r.status == ContactStatus::failed) {
            // The search evaluates distances along the way; from a deep overlap (the contract's
            // bad input) the contact equations need not converge.
            const Pose pa = pose_of(u.a.st), pb = pose_of(u.b.st);
            const DistanceResult d0 = distance(sa, pa, sb, pb);
            if (d0.status == DistanceStatus::failed || d0.distance < 0.0)
              w.fail(fmt::format("the bodies overlap at t = 0 (distance {}): the contact-time search "
                                 "needs a start without overlap", approx(u.s * d0.distance)));
            throw RunFailure(fmt::format("{}:{}: contact-time solver failed", source, w.line));
          }
          json o;
          if (r.status == ContactStatus::hit) {
            o["time"] = r.time * tau;
            o["point"] = vec(u.origin + u.s * r.point);
            o["normal"] = vec(r.normal);
          } else {
            o["time"] = nullptr;
            o["point"] = nullptr;
            o["normal"] = nullptr;
          }
          out << o.dump() << "\n";
        },
        u.a.shape, u.b.shape);
  });
}

}  // namespace hb
