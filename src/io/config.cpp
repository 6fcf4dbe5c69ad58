#include "io/config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "shapes/codec.hpp"

#include <fmt/format.h>

namespace hb {

namespace {

// The schema: section -> key -> kind.
enum class Kind { Int, Float, String, Bool, Vec3 };
const std::map<std::string, std::map<std::string, Kind>>& schema() {
  static const std::map<std::string, std::map<std::string, Kind>> s = {
      {"system",
       {{"particles", Kind::Int}, {"packing_fraction", Kind::Float}, {"seed", Kind::Int},
        {"temperature", Kind::Float}, {"mass", Kind::Float}}},
      {"run", {{"equilibrate_time", Kind::Float}, {"time", Kind::Float}, {"max_collisions", Kind::Int}}},
      {"neighbors", {{"method", Kind::String}, {"shell", Kind::Float}}},
      {"solver", {{"eps_d", Kind::Float}}},
      {"output",
       {{"log_interval", Kind::Float}, {"snapshot_interval", Kind::Float},
        {"checkpoint_interval", Kind::Float}, {"trajectory", Kind::Bool}}},
      {"init", {{"method", Kind::String}, {"phi0", Kind::Float}, {"growth_rate", Kind::Float}}},
      {"observables",
       {{"interval", Kind::Float}, {"origin_every", Kind::Int}, {"max_lag", Kind::Float},
        {"q", Kind::Float}, {"q_vectors", Kind::Int}, {"gr_interval", Kind::Float},
        {"gr_bins", Kind::Int}}},
  };
  return s;
}

// Keys of [shape]: its type, the scalar inertia, and the parameters of every registered shape
// (which ones apply to the chosen type is checked when the shape is decoded).
bool is_shape_section_key(const std::string& key) {
  if (key == "type" || key == "inertia") return true;
  const auto keys = all_shape_keys();
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::Int: return "an integer";
    case Kind::Float: return "a number";
    case Kind::String: return "a string";
    case Kind::Bool: return "true or false";
    case Kind::Vec3: return "an array of 3 numbers";
  }
  return "?";
}

std::string where(const std::string& file, const toml::node& n) {
  const auto& src = n.source();
  if (src.begin.line > 0) return fmt::format("{}:{}", file, src.begin.line);
  return file;
}

struct Reader {
  const std::string& file;
  const toml::table& root;

  [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& what) const {
    throw ConfigError(fmt::format("{}: key '{}': {}", n ? where(file, *n) : file, key, what));
  }

  const toml::node* get(const std::string& sec, const std::string& key) const {
    const auto* t = root.get_as<toml::table>(sec);
    return t ? t->get(key) : nullptr;
  }
  double num(const toml::node* n, const std::string& key) const {
    double v;
    if (auto f = n->value_exact<double>()) v = *f;
    else if (auto i = n->value_exact<int64_t>()) v = double(*i);
    else fail(n, key, "must be a number");
    if (!std::isfinite(v)) fail(n, key, "must be finite (got NaN or infinity)");
    return v;
  }
  void real(const std::string& sec, const std::string& key, double& out) const {
    if (const auto* n = get(sec, key)) out = num(n, sec + "." + key);
  }
  void integer(const std::string& sec, const std::string& key, std::uint64_t& out) const {
    if (const auto* n = get(sec, key)) {
      auto i = n->value_exact<int64_t>();
      if (!i) fail(n, sec + "." + key, "must be an integer");
      if (*i < 0) fail(n, sec + "." + key, fmt::format("must not be negative (got {})", *i));
      out = static_cast<std::uint64_t>(*i);
    }
  }
  void string(const std::string& sec, const std::string& key, std::string& out) const {
    if (const auto* n = get(sec, key)) {
      auto s = n->value_exact<std::string>();
      if (!s) fail(n, sec + "." + key, "must be a string");
      out = *s;
    }
  }
  void boolean(const std::string& sec, const std::string& key, bool& out) const {
    if (const auto* n = get(sec, key)) {
      auto b = n->value_exact<bool>();
      if (!b) fail(n, sec + "." + key, "must be true or false");
      out = *b;
    }
  }
  void vec3(const std::string& sec, const std::string& key, Vec3& out) const {
    if (const auto* n = get(sec, key)) {
      const auto* a = n->as_array();
      if (!a || a->size() != 3) fail(n, sec + "." + key, "must be an array of 3 numbers");
      for (int k = 0; k < 3; ++k) out[k] = num(a->get(k), sec + "." + key);
    }
  }
  const toml::node* node(const std::string& sec, const std::string& key) const {
    return get(sec, key);
  }
};

// The [shape] table as the shape codec's parameters; messages name the key and its line.
struct TomlShapeParams final : ParamReader {
  const Reader& r;
  std::string type;
  TomlShapeParams(const Reader& rr, std::string t) : r(rr), type(std::move(t)) {}
  bool has(std::string_view key) const override { return r.get("shape", std::string(key)) != nullptr; }
  const toml::node* need(std::string_view key) const {
    const auto* n = r.get("shape", std::string(key));
    if (!n) throw ConfigError(fmt::format("{}: missing key 'shape.{}'", r.file, key));
    return n;
  }
  double number(std::string_view key) const override {
    return r.num(need(key), "shape." + std::string(key));
  }
  Vec3 triple(std::string_view key) const override {
    Vec3 v;
    need(key);
    r.vec3("shape", std::string(key), v);
    return v;
  }
  [[noreturn]] void fail(std::string_view key, const std::string& what) const override {
    r.fail(r.get("shape", std::string(key)), "shape." + std::string(key), what);
  }
};

// The shape's type and parameters as a TOML table (to_toml).
toml::table shape_to_toml(const AnyShape& s) {
  struct W final : ParamWriter {
    toml::table t;
    void number(std::string_view k, double v) override { t.insert(k, v); }
    void triple(std::string_view k, const Vec3& v) override { t.insert(k, toml::array{v.x(), v.y(), v.z()}); }
  } w;
  w.t.insert("type", std::string(shape_name(s)));
  encode_shape(s, w);
  return std::move(w.t);
}

AnyShape read_shape(const Reader& r, const std::string& type) {
  const TomlShapeParams params(r, type);
  if (!is_shape_name(type)) params.fail("type", fmt::format("unknown shape type '{}' ({})", type, shape_names()));
  if (const auto* t = r.root.get_as<toml::table>("shape"))
    for (const auto& [k, v] : *t) {
      const std::string key(k.str());
      if (key != "type" && key != "inertia" && !is_shape_key(type, key))
        params.fail(key, fmt::format("does not apply to shape type '{}' (its keys: {})", type,
                                     shape_keys(type)));
    }
  return decode_shape(type, params);
}

void check_unknown_keys(const std::string& file, const toml::table& root) {
  const auto& s = schema();
  for (const auto& [k, v] : root) {
    const std::string sec(k.str());
    if (sec == "shape") {
      const auto* t = v.as_table();
      if (!t) throw ConfigError(fmt::format("{}: 'shape' must be a table [shape]", where(file, v)));
      for (const auto& [kk, vv] : *t)
        if (!is_shape_section_key(std::string(kk.str())))
          throw ConfigError(fmt::format("{}: unknown key 'shape.{}'", where(file, vv), kk.str()));
      continue;
    }
    auto it = s.find(sec);
    if (it == s.end()) {
      throw ConfigError(fmt::format("{}: unknown section or key '{}'", where(file, v), sec));
    }
    const auto* t = v.as_table();
    if (!t) throw ConfigError(fmt::format("{}: '{}' must be a table [{}]", where(file, v), sec, sec));
    for (const auto& [kk, vv] : *t) {
      const std::string key(kk.str());
      if (!it->second.count(key))
        throw ConfigError(fmt::format("{}: unknown key '{}.{}'", where(file, vv), sec, key));
    }
  }
}

// Applies one --set override "section.key=value" to the parsed table.
void apply_override(toml::table& root, const std::string& ov) {
  const auto eq = ov.find('=');
  const auto dot = ov.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq)
    throw ConfigError(fmt::format("--set '{}': expected section.key=value", ov));
  const std::string sec = ov.substr(0, dot), key = ov.substr(dot + 1, eq - dot - 1);
  std::string value = ov.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse(std::string_view("v = " + value), std::string_view("--set"));
  } catch (const toml::parse_error&) {
    // bare words are strings: --set neighbors.method=cells
    try {
      parsed = toml::parse(std::string_view("v = \"" + value + "\""), std::string_view("--set"));
    } catch (const toml::parse_error& e) {
      throw ConfigError(fmt::format("--set '{}': cannot parse value: {}", ov, e.description()));
    }
  }
  auto* t = root.get_as<toml::table>(sec);
  if (!t) {
    root.insert(sec, toml::table{});
    t = root.get_as<toml::table>(sec);
  }
  t->insert_or_assign(key, *parsed.get("v"));
}

Config validate(const std::string& file, const toml::table& root) {
  check_unknown_keys(file, root);
  Reader r{file, root};
  Config c;
  c.source = file;
  for (const char* sec : {"system", "shape", "run"})
    if (!root.get_as<toml::table>(sec))
      throw ConfigError(fmt::format("{}: missing section [{}]", file, sec));
  auto require = [&](const char* sec, const char* key) {
    if (!r.get(sec, key))
      throw ConfigError(fmt::format("{}: missing key '{}.{}'", file, sec, key));
  };
  require("system", "particles");
  require("system", "packing_fraction");
  require("shape", "type");
  require("run", "time");

  r.integer("system", "particles", c.particles);
  r.real("system", "packing_fraction", c.packing_fraction);
  r.integer("system", "seed", c.seed);
  r.real("system", "temperature", c.temperature);
  r.real("system", "mass", c.mass);
  std::string type;
  r.string("shape", "type", type);
  r.real("shape", "inertia", c.inertia);
  r.real("run", "equilibrate_time", c.equilibrate_time);
  r.real("run", "time", c.time);
  r.integer("run", "max_collisions", c.max_collisions);
  r.string("neighbors", "method", c.neighbors_method);
  r.real("neighbors", "shell", c.shell);
  r.real("solver", "eps_d", c.eps_d);
  r.real("output", "log_interval", c.log_interval);
  r.real("output", "snapshot_interval", c.snapshot_interval);
  r.real("output", "checkpoint_interval", c.checkpoint_interval);
  r.boolean("output", "trajectory", c.trajectory);
  r.string("init", "method", c.init_method);
  r.real("init", "phi0", c.init_phi0);
  r.real("init", "growth_rate", c.init_growth_rate);
  r.real("observables", "interval", c.obs_interval);
  r.integer("observables", "origin_every", c.obs_origin_every);
  r.real("observables", "max_lag", c.obs_max_lag);
  r.real("observables", "q", c.obs_q);
  r.integer("observables", "q_vectors", c.obs_q_vectors);
  r.real("observables", "gr_interval", c.gr_interval);
  r.integer("observables", "gr_bins", c.gr_bins);

  auto bad = [&](const char* sec, const char* key, const std::string& what) {
    r.fail(r.node(sec, key), std::string(sec) + "." + key, what);
  };
  if (c.particles == 0) bad("system", "particles", "must be at least 1 (got 0)");
  if (c.particles > 100000000) bad("system", "particles", "must be at most 1e8");
  if (!(c.packing_fraction > 0.0)) bad("system", "packing_fraction", "must be positive");
  if (!(c.temperature > 0.0)) bad("system", "temperature", "must be positive");
  if (!(c.mass > 0.0)) bad("system", "mass", "must be positive");

  c.shape = read_shape(r, type);
  const PackingLimit lim = packing_limit(c.shape);
  if (c.packing_fraction >= lim.phi)
    bad("system", "packing_fraction",
        fmt::format("{} is not below {} ({})", c.packing_fraction, lim.phi, lim.note));
  if (r.get("shape", "inertia") && !(c.inertia > 0.0))
    bad("shape", "inertia", "must be positive");
  if (c.inertia == 0.0) c.inertia = 0.4 * c.mass * sqr(half_extents(c.shape).minCoeff());
  if (c.equilibrate_time < 0.0) bad("run", "equilibrate_time", "must not be negative");
  if (!(c.time > 0.0)) bad("run", "time", "must be positive");
  // cells for spheres (their analytic contact times are cheap), neighbour lists otherwise
  if (!r.get("neighbors", "method"))
    c.neighbors_method = std::holds_alternative<Sphere>(c.shape) ? "cells" : "nnl";
  if (c.neighbors_method != "cells" && c.neighbors_method != "nnl")
    bad("neighbors", "method", fmt::format("must be \"cells\" or \"nnl\" (got \"{}\")", c.neighbors_method));
  if (!(c.shell > 0.0)) bad("neighbors", "shell", "must be positive");
  if (!(c.eps_d > 0.0 && c.eps_d < 1.0)) bad("solver", "eps_d", "must be in (0, 1)");
  if (!(c.log_interval > 0.0)) bad("output", "log_interval", "must be positive");
  if (!(c.snapshot_interval > 0.0)) bad("output", "snapshot_interval", "must be positive");
  if (!(c.checkpoint_interval > 0.0)) bad("output", "checkpoint_interval", "must be positive");
  if (c.init_method != "grow" && c.init_method != "lattice")
    bad("init", "method", fmt::format("must be \"grow\" or \"lattice\" (got \"{}\")", c.init_method));
  if (!(c.init_phi0 > 0.0 && c.init_phi0 < 0.5)) bad("init", "phi0", "must be in (0, 0.5)");
  if (!(c.init_growth_rate > 0.0)) bad("init", "growth_rate", "must be positive");
  if (c.obs_interval < 0.0) bad("observables", "interval", "must not be negative (0 switches it off)");
  if (c.obs_origin_every < 1) bad("observables", "origin_every", "must be at least 1");
  if (c.obs_interval > 0.0 && !(c.obs_max_lag >= c.obs_interval))
    bad("observables", "max_lag", "must be at least observables.interval");
  if (!(c.obs_q > 0.0)) bad("observables", "q", "must be positive");
  if (c.obs_q_vectors < 1) bad("observables", "q_vectors", "must be at least 1");
  if (c.gr_interval < 0.0) bad("observables", "gr_interval", "must not be negative (0 switches it off)");
  if (c.gr_bins < 1 || c.gr_bins > 100000) bad("observables", "gr_bins", "must be in 1..100000");
  return c;
}

}  // namespace

Config parse_config(const std::string& text, const std::string& name,
                    const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    throw ConfigError(fmt::format("{}:{}: malformed TOML: {}", name, e.source().begin.line,
                                  e.description()));
  }
  for (const auto& ov : overrides) apply_override(root, ov);
  return validate(name, root);
}

Config load_config(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(fmt::format("{}: cannot open config file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ConfigError(fmt::format("{}: cannot read config file", path));
  return parse_config(ss.str(), path, overrides);
}

std::string to_toml(const Config& c) {
  auto arr = [](const Vec3& v) { return toml::array{v.x(), v.y(), v.z()}; };
  toml::table shape = shape_to_toml(c.shape);
  shape.insert("inertia", c.inertia);
  toml::table root{
      {"system", toml::table{{"particles", int64_t(c.particles)},
                             {"packing_fraction", c.packing_fraction},
                             {"seed", int64_t(c.seed)},
                             {"temperature", c.temperature},
                             {"mass", c.mass}}},
      {"shape", shape},
      {"run", toml::table{{"equilibrate_time", c.equilibrate_time},
                          {"time", c.time},
                          {"max_collisions", int64_t(c.max_collisions)}}},
      {"neighbors", toml::table{{"method", c.neighbors_method}, {"shell", c.shell}}},
      {"solver", toml::table{{"eps_d", c.eps_d}}},
      {"output", toml::table{{"log_interval", c.log_interval},
                             {"snapshot_interval", c.snapshot_interval},
                             {"checkpoint_interval", c.checkpoint_interval},
                             {"trajectory", c.trajectory}}},
      {"observables", toml::table{{"interval", c.obs_interval},
                                  {"origin_every", int64_t(c.obs_origin_every)},
                                  {"max_lag", c.obs_max_lag},
                                  {"q", c.obs_q},
                                  {"q_vectors", int64_t(c.obs_q_vectors)},
                                  {"gr_interval", c.gr_interval},
                                  {"gr_bins", int64_t(c.gr_bins)}}},
  };
  toml::table init;
  init.insert("method", c.init_method);
  init.insert("phi0", c.init_phi0);
  init.insert("growth_rate", c.init_growth_rate);
  root.insert("init", init);
  std::ostringstream os;
  os << "# hardbody resolved configuration (every key, defaults filled in)\n" << root << "\n";
  return os.str();
}

}  // namespace hb
