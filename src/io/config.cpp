#include "io/config.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "io/resources.hpp"
#include "io/suggest.hpp"
#include "setup/box_setup.hpp"
#include "shapes/codec.hpp"
#include "shapes/inertia.hpp"

#include <fmt/format.h>

namespace hb {

namespace {

enum class Kind { Int, Float, String, Bool, Vec3, Strings };

// THE schema of the scalar sections: every key with its kind and meaning. Unknown keys are
// rejected against it, and docs/config.md is generated from it (config_reference()).
struct KeySpec {
  const char* section;
  const char* key;
  Kind kind;
  const char* meaning;
};
const std::vector<KeySpec>& key_specs() {
  static const std::vector<KeySpec> k = {
      {"system", "particles", Kind::Int, "N, the number of bodies (one-species shorthand, required with [shape]; with [[species]] the counts add up and this key is refused)"},
      {"system", "packing_fraction", Kind::Float, "target packing fraction phi = sum of body volumes / box volume (required; with walls.sphere it may be omitted: phi is then the bodies' volume over the container's, and a value given must agree with it to 1e-6)"},
      {"system", "seed", Kind::Int, "seed of every random choice (lattice velocities, placement, polydispersity)"},
      {"system", "temperature", Kind::Float, "kT: the translational (and rotational) temperature set at the start"},
      {"system", "mass", Kind::Float, "body mass (one-species shorthand; per species with [[species]])"},
      {"box", "aspect", Kind::Vec3, "side ratios Lx : Ly : Lz of the box (three positive numbers); the volume is sum of body volumes / phi, so L = aspect x cbrt(V / (ax ay az)). With walls.sphere only [1, 1, 1]"},
      {"walls", "planes", Kind::Strings, "axes with hard planar walls, a list of distinct names among \"x\", \"y\", \"z\" (e.g. [\"z\"]: walls at -Lz/2 and +Lz/2, the box not periodic along z); [] for none. A walled side shorter than two body lengths (2 x the largest bounding diameter) is refused"},
      {"walls", "sphere", Kind::Float, "radius R of a hard spherical container centred in the box (a cube of side 2 R, periodic along no axis); phi = N v / (4 pi R^3 / 3). Excludes walls.planes (other than []) and a non-cubic box.aspect; R must be at least two body lengths; default: no container"},
      {"run", "equilibrate_time", Kind::Float, "simulated time run and discarded before measuring"},
      {"run", "time", Kind::Float, "simulated time measured (required)"},
      {"run", "max_collisions", Kind::Int, "stop the measured run after this many collisions (0: no limit)"},
      {"thermostat", "type", Kind::String, "\"none\" (NVE) or \"andersen\": each body's velocity and spin redrawn from the Maxwell distribution at system.temperature at the events of a Poisson process of thermostat.rate per body"},
      {"thermostat", "rate", Kind::Float, "resamplings per body per unit time (finite, > 0 with type = \"andersen\"; never negative)"},
      {"thermostat", "during", Kind::String, "\"always\" or \"equilibration\" (only in run.equilibrate_time, which must then be positive)"},
      {"neighbors", "method", Kind::String, "\"cells\" or \"nnl\" (oriented-box / sphere-shell neighbour lists); default cells when every species is a sphere, nnl otherwise; sphere mixtures use cells"},
      {"neighbors", "shell", Kind::Float, "Delta_NNL: the neighbour-list shell (a length)"},
      {"solver", "eps_d", Kind::Float, "the paper's epsilon_d: the distance accuracy of the contact-time search"},
      {"output", "log_interval", Kind::Float, "simulated time per log.tsv row and per pressure block"},
      {"output", "snapshot_interval", Kind::Float, "simulated time between trajectory frames (each checked for overlaps)"},
      {"output", "checkpoint_interval", Kind::Float, "wall seconds between checkpoints (also written on SIGINT/SIGTERM and failures)"},
      {"output", "trajectory", Kind::Bool, "write trajectory.gsd"},
      {"output", "max_output_gb", Kind::Float, "limit on the files of a run (trajectory, logs, tables, checkpoint; estimated from the config before the start, in 1e9 bytes): a run that would write more is refused"},
      {"init", "method", Kind::String, "\"auto\" (default): \"lattice\" for one species of equal spheres, \"grow\" otherwise; \"grow\": Lubachevsky-Stillinger growth from a dilute placement at init.phi0; \"lattice\": (stretched) lattice at the target; mixtures always grow from a random placement"},
      {"init", "phi0", Kind::Float, "packing fraction of the dilute start that is grown"},
      {"init", "file", Kind::String, "init.method = \"file\": a GSD file (a hardbody trajectory or checkpoint, or any HOOMD-schema file) whose frame holds the start: N, species, box and packing fraction must match the config; velocities and spins as in the file"},
      {"init", "frame", Kind::Int, "init.method = \"file\": the frame of init.file (0 = first; default: the last)"},
      {"init", "growth_rate", Kind::Float, "d(scale)/dt of the growth (scale 1 = target size)"},
      {"observables", "interval", Kind::Float, "sampling interval of MSD, C2, F_self (0: off)"},
      {"observables", "origin_every", Kind::Int, "a new time origin every this many samples"},
      {"observables", "max_lag", Kind::Float, "longest lag time of the correlation tables"},
      {"observables", "q", Kind::Float, "target |q| of F_self(q, t)"},
      {"observables", "q_vectors", Kind::Int, "number of q vectors averaged"},
      {"observables", "gr_interval", Kind::Float, "sampling interval of g(r) (0: off)"},
      {"observables", "gr_bins", Kind::Int, "bins of g(r)"},
  };
  return k;
}

const std::map<std::string, std::map<std::string, Kind>>& schema() {
  static const std::map<std::string, std::map<std::string, Kind>> s = [] {
    std::map<std::string, std::map<std::string, Kind>> m;
    for (const KeySpec& k : key_specs()) m[k.section][k.key] = k.kind;
    return m;
  }();
  return s;
}

// Where a value came from: "file:line", or the --set option that gave it ("--set k=v": its
// nodes are parsed with that source name, see apply_override).
constexpr std::string_view kSetSource = "--set ";
std::string where(const std::string& file, const toml::node& n) {
  const auto& src = n.source();
  if (src.path && src.path->rfind(kSetSource, 0) == 0) return *src.path;
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
  Vec3 triple(const toml::node* n, const std::string& key) const {
    const auto* a = n->as_array();
    if (!a || a->size() != 3) fail(n, key, "must be an array of 3 numbers");
    Vec3 out;
    for (int k = 0; k < 3; ++k) out[k] = num(a->get(k), key);
    return out;
  }
  const toml::node* node(const std::string& sec, const std::string& key) const {
    return get(sec, key);
  }
};

// A shape table ([shape], or a species' inline `shape`) as the shape codec's parameters;
// messages name the key (with `prefix`, e.g. "species[1].shape.") and its line.
struct TomlShapeParams final : ParamReader {
  const Reader& r;
  const toml::table& t;
  std::string prefix;
  TomlShapeParams(const Reader& rr, const toml::table& tt, std::string p) : r(rr), t(tt), prefix(std::move(p)) {}
  bool has(std::string_view key) const override { return t.get(key) != nullptr; }
  const toml::node* need(std::string_view key) const {
    const auto* n = t.get(key);
    if (!n) throw ConfigError(fmt::format("{}: missing key '{}{}'", where(r.file, t), prefix, key));
    return n;
  }
  double number(std::string_view key) const override { return r.num(need(key), prefix + std::string(key)); }
  Vec3 triple(std::string_view key) const override { return r.triple(need(key), prefix + std::string(key)); }
  [[noreturn]] void fail(std::string_view key, const std::string& what) const override {
    const auto* n = t.get(key);
    r.fail(n ? n : &t, prefix + std::string(key), what);
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

// A shape table: its type and the parameters of the type's codec entry; `extra` keys of the
// table that are not shape parameters (the shorthand's "inertia").
AnyShape read_shape(const Reader& r, const toml::table& t, const std::string& prefix,
                    std::initializer_list<std::string_view> extra = {}) {
  const TomlShapeParams params(r, t, prefix);
  const auto* tn = t.get("type");
  if (!tn) throw ConfigError(fmt::format("{}: missing key '{}type'", where(r.file, t), prefix));
  const auto type = tn->value_exact<std::string>();
  if (!type) params.fail("type", "must be a string");
  if (!is_shape_name(*type)) params.fail("type", fmt::format("unknown shape type '{}' ({})", *type, shape_names()));
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (key == "type" || std::find(extra.begin(), extra.end(), key) != extra.end()) continue;
    if (!is_shape_key(*type, key))
      params.fail(key, fmt::format("does not apply to shape type '{}' (its keys: {})", *type, shape_keys(*type)));
  }
  return decode_shape(*type, params);
}

// The mixtures' starts: random placement at init.phi0, then growth. Random sphere packings jam
// near 0.64; growth at a finite rate stalls before that.
constexpr double kMixtureStartLimit = 0.6;

// [[species]] -> the species table (DESIGN.md "Species and mixtures"); every problem names
// species[k].key and its line.
SpeciesTable read_species(const Reader& r, const toml::array& arr) {
  SpeciesTable out;
  if (arr.empty()) r.fail(&arr, "species", "must list at least one species");
  if (arr.size() > 65535) r.fail(&arr, "species", "at most 65535 species (a body's species id is 16 bits)");
  for (std::size_t k = 0; k < arr.size(); ++k) {
    const std::string prefix = fmt::format("species[{}].", k);
    const auto* t = arr.get(k)->as_table();
    if (!t) r.fail(arr.get(k), "species", "each [[species]] entry must be a table");
    auto key = [&](const char* name) { return prefix + name; };
    for (const auto& [kk, vv] : *t) {
      const std::string name(kk.str());
      if (name == "sites")
        r.fail(&vv, key("sites"), "square-well sites are not supported yet");
    }
    Species sp;
    const auto* name = t->get("name");
    if (!name) throw ConfigError(fmt::format("{}: missing key '{}'", where(r.file, *t), key("name")));
    if (auto v = name->value_exact<std::string>()) sp.name = *v;
    else r.fail(name, key("name"), "must be a string");
    if (sp.name.empty() || sp.name.size() > 64 ||
        sp.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_+-") != std::string::npos)
      r.fail(name, key("name"), "must be a word of letters, digits, '_', '+' or '-' (at most 64; it is the "
                                "GSD type name and part of file names)");
    for (std::size_t j = 0; j < out.size(); ++j)
      if (out[j].name == sp.name)
        r.fail(name, key("name"), fmt::format("duplicate species name '{}' (also species[{}])", sp.name, j));
    const auto* count = t->get("count");
    if (!count) throw ConfigError(fmt::format("{}: missing key '{}'", where(r.file, *t), key("count")));
    const auto n = count->value_exact<int64_t>();
    if (!n) r.fail(count, key("count"), "must be an integer");
    if (*n < 1) r.fail(count, key("count"), fmt::format("must be at least 1 (got {})", *n));
    sp.count = std::uint64_t(*n);
    const auto* shape = t->get("shape");
    if (!shape) throw ConfigError(fmt::format("{}: missing key '{}'", where(r.file, *t), key("shape")));
    if (!shape->as_table()) r.fail(shape, key("shape"), "must be a table, e.g. { type = \"sphere\", radius = 0.5 }");
    sp.shape = read_shape(r, *shape->as_table(), key("shape."));
    if (const auto* m = t->get("mass")) {
      sp.mass = r.num(m, key("mass"));
      if (!(sp.mass > 0.0)) r.fail(m, key("mass"), fmt::format("must be positive (got {})", sp.mass));
    }
    if (const auto* in = t->get("inertia")) {
      sp.inertia = in->as_array() ? r.triple(in, key("inertia")) : Vec3::Constant(r.num(in, key("inertia")));
      if (!(sp.inertia.minCoeff() > 0.0))
        r.fail(in, key("inertia"), "principal moments must be positive (a positive-definite tensor)");
      const Vec3& I = sp.inertia;
      if (I.x() + I.y() < I.z() * (1 - 1e-12) || I.y() + I.z() < I.x() * (1 - 1e-12) ||
          I.x() + I.z() < I.y() * (1 - 1e-12))
        r.fail(in, key("inertia"), "principal moments of a rigid body satisfy I_a + I_b >= I_c");
    } else {
      sp.inertia = uniform_inertia(sp.shape, sp.mass);
    }
    if (const auto* pn = t->get("polydispersity")) {
      const auto* pt = pn->as_table();
      if (!pt) r.fail(pn, key("polydispersity"), "must be a table { distribution = \"gaussian\", width = 0.1 }");
      const auto* d = pt->get("distribution");
      const std::string dist = d && d->value_exact<std::string>() ? *d->value_exact<std::string>() : "";
      if (dist == "gaussian") sp.poly.distribution = Polydispersity::Distribution::gaussian;
      else if (dist == "uniform") sp.poly.distribution = Polydispersity::Distribution::uniform;
      else r.fail(d ? d : pn, key("polydispersity.distribution"), "must be \"gaussian\" or \"uniform\"");
      const auto* w = pt->get("width");
      if (!w) throw ConfigError(fmt::format("{}: missing key '{}'", where(r.file, *pt), key("polydispersity.width")));
      sp.poly.width = r.num(w, key("polydispersity.width"));
      if (!(sp.poly.width > 0.0 && sp.poly.width < 0.3))
        r.fail(w, key("polydispersity.width"), fmt::format("must be in (0, 0.3) (got {})", sp.poly.width));
    }
    out.push_back(std::move(sp));
  }
  return out;
}

// ---- unknown keys: every one of a config in one message, each with its place and the nearest
// known key ("did you mean"), also across sections ("system.time" -> "run.time").

const std::vector<std::string> kSpeciesKeys{"name", "count", "shape", "mass", "inertia", "polydispersity"};
const std::vector<std::string> kPolydispersityKeys{"distribution", "width"};

std::vector<std::string> section_keys(const std::string& sec) {
  std::vector<std::string> out;
  if (sec == "shape") {
    out = {"type", "inertia"};
    for (const auto& k : all_shape_keys()) out.push_back(k);
  } else if (auto it = schema().find(sec); it != schema().end()) {
    for (const auto& kv : it->second) out.push_back(kv.first);
  }
  return out;
}

std::vector<std::string> section_names() {
  std::vector<std::string> out{"shape", "species"};
  for (const auto& kv : schema()) out.push_back(kv.first);
  return out;
}

// The known key nearest to `key` of section `sec` ("sec.k"), else the same or a near key of
// another section ("other.k"); "" when nothing is near.
std::string suggest_key(const std::string& sec, const std::string& key) {
  if (auto k = nearest_key(key, section_keys(sec)); !k.empty()) return sec + "." + k;
  std::vector<std::string> full, bare;
  for (const auto& other : section_names())
    if (other != sec && other != "species")
      for (const auto& k : section_keys(other)) {
        full.push_back(other + "." + k);
        bare.push_back(k);
      }
  for (std::size_t i = 0; i < bare.size(); ++i)
    if (bare[i] == key) return full[i];
  const std::string k = nearest_key(key, bare);
  for (std::size_t i = 0; i < bare.size(); ++i)
    if (bare[i] == k && !k.empty()) return full[i];
  return "";
}

std::string mean(const std::string& pick) { return pick.empty() ? "" : fmt::format(" (did you mean '{}'?)", pick); }

struct Unknown {
  const toml::node* node;
  std::string message;
};

// Keys of a table that `known` does not list, as "place: unknown key 'prefix.key' (did you mean ...)".
void unknown_in(const std::string& file, const toml::table& t, const std::vector<std::string>& known,
                const std::string& prefix, std::vector<Unknown>& out, const std::vector<std::string>& skip = {}) {
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (std::find(known.begin(), known.end(), key) != known.end() ||
        std::find(skip.begin(), skip.end(), key) != skip.end())
      continue;
    const std::string pick = nearest_key(key, known);
    out.push_back({&v, fmt::format("{}: unknown key '{}{}'{}", where(file, v), prefix, key,
                                   mean(pick.empty() ? "" : prefix + pick))});
  }
}

// Every unknown section and key of the config (sections, [shape], each [[species]] entry, its
// shape and polydispersity), reported together; wrong section types are reported at once.
void check_unknown_keys(const std::string& file, const toml::table& root) {
  const auto& s = schema();
  std::vector<Unknown> bad;
  for (const auto& [k, v] : root) {
    const std::string sec(k.str());
    if (sec == "species") {
      const auto* arr = v.as_array();
      if (!arr) throw ConfigError(fmt::format("{}: 'species' must be an array of tables [[species]]", where(file, v)));
      for (std::size_t i = 0; i < arr->size(); ++i) {
        const auto* t = arr->get(i)->as_table();
        if (!t) continue;  // reported by read_species
        const std::string prefix = fmt::format("species[{}].", i);
        unknown_in(file, *t, kSpeciesKeys, prefix, bad, {"sites"});
        if (const auto* sh = t->get_as<toml::table>("shape")) {
          std::vector<std::string> known{"type"};
          for (const auto& key : all_shape_keys()) known.push_back(key);
          unknown_in(file, *sh, known, prefix + "shape.", bad);
        }
        if (const auto* pd = t->get_as<toml::table>("polydispersity"))
          unknown_in(file, *pd, kPolydispersityKeys, prefix + "polydispersity.", bad);
      }
      continue;
    }
    if (s.find(sec) == s.end() && sec != "shape") {
      if (v.as_table()) {
        const std::string pick = nearest_key(sec, section_names());
        bad.push_back({&v, fmt::format("{}: unknown section or key '{}'{}", where(file, v), sec,
                                       pick.empty() ? "" : fmt::format(" (did you mean [{}]?)", pick))});
      } else {
        // a key above the first section header
        bad.push_back({&v, fmt::format("{}: unknown section or key '{}'{}", where(file, v), sec,
                                       mean(suggest_key("", sec)))});
      }
      continue;
    }
    const auto* t = v.as_table();
    if (!t) throw ConfigError(fmt::format("{}: '{}' must be a table [{}]", where(file, v), sec, sec));
    const std::vector<std::string> known = section_keys(sec);
    for (const auto& [kk, vv] : *t) {
      const std::string key(kk.str());
      if (std::find(known.begin(), known.end(), key) == known.end())
        bad.push_back({&vv, fmt::format("{}: unknown key '{}.{}'{}", where(file, vv), sec, key,
                                        mean(suggest_key(sec, key)))});
    }
  }
  if (bad.empty()) return;
  // in the order of the file (the tables iterate by name); --set values last
  auto line = [](const Unknown& u) {
    const auto& src = u.node->source();
    const bool set = src.path && src.path->rfind(kSetSource, 0) == 0;
    return src.begin.line > 0 && !set ? std::size_t(src.begin.line) : std::size_t(-1);
  };
  std::stable_sort(bad.begin(), bad.end(), [&](const Unknown& a, const Unknown& b) { return line(a) < line(b); });
  std::string msg;
  for (const auto& b : bad) msg += (msg.empty() ? "" : "; ") + b.message;
  throw ConfigError(msg);
}

// Applies one --set override "section.key=value" to the parsed table. The value keeps the
// source name "--set section.key=value", so that every message about it names the option, never
// a line of the file.
void apply_override(toml::table& root, const std::string& ov) {
  const std::string source = std::string(kSetSource) + ov;
  const auto eq = ov.find('=');
  const auto dot = ov.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq)
    throw ConfigError(fmt::format("--set '{}': expected section.key=value", ov));
  auto trim = [](std::string x) {
    const auto b = x.find_first_not_of(" \t"), e = x.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : x.substr(b, e - b + 1);
  };
  const std::string sec = trim(ov.substr(0, dot)), key = trim(ov.substr(dot + 1, eq - dot - 1));
  const std::string value = trim(ov.substr(eq + 1));
  if (sec.empty() || key.empty()) throw ConfigError(fmt::format("--set '{}': expected section.key=value", ov));
  toml::table parsed;
  try {
    parsed = toml::parse(std::string_view("v = " + value), source);
  } catch (const toml::parse_error&) {
    // bare words are strings: --set neighbors.method=cells
    try {
      parsed = toml::parse(std::string_view("v = \"" + value + "\""), source);
    } catch (const toml::parse_error& e) {
      throw ConfigError(fmt::format("{}: cannot parse the value: {}", source, e.description()));
    }
  }
  if (root.contains(sec) && !root.get_as<toml::table>(sec))
    throw ConfigError(fmt::format("--set '{}': '{}' is not a table of keys ([[species]] entries cannot be "
                                  "set with --set; edit the config file)", ov, sec));
  auto* t = root.get_as<toml::table>(sec);
  if (!t) {
    root.insert(sec, toml::table{});
    t = root.get_as<toml::table>(sec);
  }
  // moved, not copied: a copied toml node forgets its source
  parsed.get("v")->visit([&](auto&& v) { t->insert_or_assign(key, std::move(v)); });
}

// [box] and [walls] as given (each key typed and in range; the geometry is checked by validate).
void read_boundaries(const Reader& r, BoundarySpec& b) {
  r.vec3("box", "aspect", b.aspect);
  if (!(b.aspect.minCoeff() > 0.0))
    r.fail(r.node("box", "aspect"), "box.aspect",
           fmt::format("must be three positive side ratios (got [{}, {}, {}])", b.aspect.x(), b.aspect.y(), b.aspect.z()));
  if (const auto* n = r.node("walls", "planes")) {
    const auto* a = n->as_array();
    if (!a) r.fail(n, "walls.planes", "must be a list of axis names, e.g. [\"z\"] ([] for none)");
    for (const auto& e : *a) {
      const auto axis = e.value_exact<std::string>();
      if (!axis || (*axis != "x" && *axis != "y" && *axis != "z"))
        r.fail(&e, "walls.planes",
               axis ? fmt::format("\"{}\" is not an axis: list names among \"x\", \"y\", \"z\"", *axis)
                    : std::string("must list axis names (strings) among \"x\", \"y\", \"z\", e.g. [\"z\"]"));
      const int k = (*axis)[0] - 'x';
      if (b.walls.planes[k]) r.fail(&e, "walls.planes", fmt::format("names the axis \"{}\" twice", *axis));
      b.walls.planes[k] = true;
    }
  }
  if (const auto* n = r.node("walls", "sphere")) {
    const double radius = r.num(n, "walls.sphere");
    if (!(radius > 0.0)) r.fail(n, "walls.sphere", fmt::format("must be a positive radius (got {})", radius));
    if (b.walls.any_plane())
      r.fail(n, "walls.sphere", "walls.planes and walls.sphere exclude each other (planar walls or a spherical container)");
    if (b.aspect != Vec3::Ones())
      r.fail(r.node("box", "aspect"), "box.aspect",
             fmt::format("must be [1, 1, 1] (or absent) with walls.sphere: the container's box is the cube of side "
                         "2 R (got [{}, {}, {}])", b.aspect.x(), b.aspect.y(), b.aspect.z()));
    b.walls.sphere_radius = radius;
  }
}

// A spherical container sets phi = N v / (4 pi R^3 / 3): system.packing_fraction, if given, must
// agree with it to 1e-6 (relative); c.packing_fraction becomes the container's phi either way.
void check_container(const Reader& r, Config& c, bool phi_given) {
  const WallSpec& w = c.boundaries.walls;
  if (!w.container()) return;
  const double phi = packing_fraction(c);
  const auto* sphere = r.node("walls", "sphere");
  if (!std::isnormal(phi))
    r.fail(sphere, "walls.sphere", fmt::format("radius {} is too large: the bodies would fill {} of the container",
                                               w.sphere_radius, phi));
  if (phi_given && !(std::abs(phi - c.packing_fraction) <= 1e-6 * c.packing_fraction)) {
    const double need = container_radius_for(c, c.packing_fraction);
    if (phi > c.packing_fraction)
      r.fail(sphere, "walls.sphere",
             fmt::format("the container is too small for {} bodies at phi = {}: it needs radius {:.10g} (radius {} "
                         "gives phi = {:.6g})", c.particles, c.packing_fraction, need, w.sphere_radius, phi));
    r.fail(sphere, "walls.sphere",
           fmt::format("the container is larger than {} bodies at phi = {} need (radius {:.10g}; radius {} gives "
                       "phi = {:.6g}); omit system.packing_fraction or set walls.sphere = {:.10g}",
                       c.particles, c.packing_fraction, need, w.sphere_radius, phi, need));
  }
  c.packing_fraction = phi;
}

Config validate(const std::string& file, const toml::table& root) {
  check_unknown_keys(file, root);
  Reader r{file, root};
  Config c;
  c.source = file;
  const auto* species = root.get_as<toml::array>("species");
  c.species_given = species != nullptr;
  for (const char* sec : {"system", "run"})
    if (!root.get_as<toml::table>(sec))
      throw ConfigError(fmt::format("{}: missing section [{}]", file, sec));
  if (species) {
    // the [shape] / system.particles / system.mass shorthand is for one species only
    if (const auto* sh = root.get("shape"))
      throw ConfigError(fmt::format("{}: [shape] and [[species]] exclude each other (give each species its shape)", where(file, *sh)));
    for (const char* key : {"particles", "mass"})
      if (const auto* n = r.get("system", key))
        r.fail(n, fmt::format("system.{}", key), "is set per species with [[species]] (count, mass)");
  } else if (!root.get_as<toml::table>("shape")) {
    throw ConfigError(fmt::format("{}: missing section [shape] (or [[species]])", file));
  }
  auto require = [&](const char* sec, const char* key) {
    if (!r.get(sec, key))
      throw ConfigError(fmt::format("{}: missing key '{}.{}'", file, sec, key));
  };
  if (!species) require("system", "particles");
  // with a spherical container phi follows from its radius (a value given must agree)
  const bool phi_given = r.get("system", "packing_fraction") != nullptr;
  if (!r.get("walls", "sphere")) require("system", "packing_fraction");
  if (!species) require("shape", "type");
  require("run", "time");

  r.integer("system", "particles", c.particles);
  r.real("system", "packing_fraction", c.packing_fraction);
  r.integer("system", "seed", c.seed);
  r.real("system", "temperature", c.temperature);
  double mass = 1.0, inertia = 0.0;
  r.real("system", "mass", mass);
  r.real("shape", "inertia", inertia);
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
  r.real("output", "max_output_gb", c.max_output_gb);
  r.string("init", "method", c.init_method);
  r.real("init", "phi0", c.init_phi0);
  r.string("init", "file", c.init_file);
  r.integer("init", "frame", c.init_frame);
  r.real("init", "growth_rate", c.init_growth_rate);
  r.real("observables", "interval", c.obs_interval);
  r.integer("observables", "origin_every", c.obs_origin_every);
  r.real("observables", "max_lag", c.obs_max_lag);
  r.real("observables", "q", c.obs_q);
  r.integer("observables", "q_vectors", c.obs_q_vectors);
  r.real("observables", "gr_interval", c.gr_interval);
  r.integer("observables", "gr_bins", c.gr_bins);
  read_boundaries(r, c.boundaries);
  std::string thermostat_type = "none", thermostat_during = "always";
  r.string("thermostat", "type", thermostat_type);
  r.real("thermostat", "rate", c.thermostat.rate);
  r.string("thermostat", "during", thermostat_during);

  auto bad = [&](const char* sec, const char* key, const std::string& what) {
    r.fail(r.node(sec, key), std::string(sec) + "." + key, what);
  };
  if (!species && c.particles == 0) bad("system", "particles", "must be at least 1 (got 0)");
  if (c.particles > 100000000) bad("system", "particles", "must be at most 1e8");
  if (phi_given && !(c.packing_fraction > 0.0)) bad("system", "packing_fraction", "must be positive");
  if (!(c.temperature > 0.0)) bad("system", "temperature", "must be positive");

  if (species) {
    c.species = read_species(r, *species);
    c.particles = total_count(c.species);
    if (c.particles > 100000000) r.fail(species, "species", "the counts must add up to at most 1e8");
  } else {
    if (!(mass > 0.0)) bad("system", "mass", "must be positive");
    Species sp;
    sp.shape = read_shape(r, *root.get_as<toml::table>("shape"), "shape.", {"inertia"});
    sp.name = std::string(shape_name(sp.shape));
    sp.count = c.particles;
    sp.mass = mass;
    if (r.get("shape", "inertia") && !(inertia > 0.0)) bad("shape", "inertia", "must be positive");
    // the paper's convention for the shorthand: a spherical top, I = 2/5 m r_min^2 (ERRATA 8)
    if (inertia == 0.0) inertia = 0.4 * mass * sqr(half_extents(sp.shape).minCoeff());
    sp.inertia = Vec3::Constant(inertia);
    c.species = {sp};
  }
  check_container(r, c, phi_given);
  {
    // with a container whose radius alone sets phi, a phi out of range is the radius' fault
    auto bad_phi = [&](const std::string& what) {
      if (c.boundaries.walls.container() && !phi_given)
        bad("walls", "sphere", fmt::format("the bodies fill phi = N v / (4 pi R^3 / 3) = {} of the container, and {}; "
                                           "a larger radius is needed", c.packing_fraction, what));
      bad("system", "packing_fraction", what);
    };
    const bool one_kind = !c.mixture();
    const PackingLimit lim = packing_limit(c.species[0].shape);
    if (one_kind && c.packing_fraction >= lim.phi)
      bad_phi(fmt::format("{} is not below {} ({})", c.packing_fraction, lim.phi, lim.note));
    if (!one_kind && c.packing_fraction > kMixtureStartLimit)
      bad_phi(fmt::format("{} is too dense for the start of a mixture (random placement, then growth: at most {})",
                          c.packing_fraction, kMixtureStartLimit));
  }
  if (c.equilibrate_time < 0.0) bad("run", "equilibrate_time", "must not be negative");
  if (!(c.time > 0.0)) bad("run", "time", "must be positive");
  {
    // Time stamps are doubles: beyond ~1e12 thermal times tau = r / sqrt(kT / m) of the smallest,
    // lightest body they cannot resolve its collisions (and such a run would never end).
    double r_min = kInf, m_min = kInf;
    for (const Species& sp : c.species) {
      r_min = std::min(r_min, half_extents(sp.shape).minCoeff());
      m_min = std::min(m_min, sp.mass);
    }
    const double tau = r_min / std::sqrt(c.temperature / m_min);
    const double t_end = c.equilibrate_time + c.time;
    if (!(t_end / tau <= 1e12))
      bad("run", c.equilibrate_time > c.time ? "equilibrate_time" : "time",
          fmt::format("run.equilibrate_time + run.time = {:.3g} is {:.3g} thermal times of the smallest body "
                      "(r / sqrt(kT / m) = {:.3g}); at most 1e12 (time stamps are doubles)", t_end, t_end / tau, tau));
  }
  // cells for spheres (their analytic contact times are cheap), neighbour lists as soon as one
  // species is not a sphere (whichever species comes first)
  if (!r.get("neighbors", "method")) {
    c.neighbors_method = "cells";
    for (const Species& sp : c.species)
      if (!std::holds_alternative<Sphere>(sp.shape)) c.neighbors_method = "nnl";
  }
  if (c.neighbors_method != "cells" && c.neighbors_method != "nnl")
    bad("neighbors", "method", fmt::format("must be \"cells\" or \"nnl\" (got \"{}\")", c.neighbors_method));
  if (!(c.shell > 0.0)) bad("neighbors", "shell", "must be positive");
  if (!(c.eps_d > 0.0 && c.eps_d < 1.0)) bad("solver", "eps_d", "must be in (0, 1)");
  if (!(c.log_interval > 0.0)) bad("output", "log_interval", "must be positive");
  if (!(c.snapshot_interval > 0.0)) bad("output", "snapshot_interval", "must be positive");
  if (!(c.checkpoint_interval > 0.0)) bad("output", "checkpoint_interval", "must be positive");
  if (!(c.max_output_gb > 0.0)) bad("output", "max_output_gb", "must be positive");
  if (c.init_method != "auto" && c.init_method != "grow" && c.init_method != "lattice" && c.init_method != "file")
    bad("init", "method", fmt::format("must be \"auto\", \"grow\", \"lattice\" or \"file\" (got \"{}\")", c.init_method));
  if (c.init_method == "file" && c.init_file.empty())
    bad("init", "file", "init.method = \"file\" needs init.file (a GSD file)");
  if (c.init_method != "file" && !c.init_file.empty())
    bad("init", "file", fmt::format("is read only with init.method = \"file\" (init.method is \"{}\")", c.init_method));
  // "auto": one species of equal spheres starts on the FCC lattice at the target; everything else
  // grows (config.resolved.toml records the method used)
  if (c.init_method == "auto")
    c.init_method = !c.mixture() && std::holds_alternative<Sphere>(c.one().shape) ? "lattice" : "grow";
  if (!(c.init_phi0 > 0.0 && c.init_phi0 < 0.5)) bad("init", "phi0", "must be in (0, 0.5)");
  if (!(c.init_growth_rate > 0.0)) bad("init", "growth_rate", "must be positive");
  if (c.obs_interval < 0.0) bad("observables", "interval", "must not be negative (0 switches it off)");
  if (c.obs_origin_every < 1 || c.obs_origin_every > 1000000000)
    bad("observables", "origin_every", "must be in 1..1e9");
  if (c.obs_interval > 0.0 && !(c.obs_max_lag >= c.obs_interval))
    bad("observables", "max_lag", "must be at least observables.interval");
  // the lag grid has max_lag / interval entries (a table row each)
  if (c.obs_interval > 0.0 && c.obs_max_lag / c.obs_interval > 1e8)
    bad("observables", "max_lag", fmt::format("is {:.3g} observables.interval; at most 1e8 lags (a larger "
                                              "observables.interval, or a shorter max_lag)",
                                              c.obs_max_lag / c.obs_interval));
  if (!(c.obs_q > 0.0)) bad("observables", "q", "must be positive");
  if (c.obs_q_vectors < 1 || c.obs_q_vectors > 100000) bad("observables", "q_vectors", "must be in 1..100000");
  if (c.gr_interval < 0.0) bad("observables", "gr_interval", "must not be negative (0 switches it off)");
  if (c.gr_bins < 1 || c.gr_bins > 100000) bad("observables", "gr_bins", "must be in 1..100000");
  // [thermostat]
  if (thermostat_type == "none") c.thermostat.type = ThermostatSpec::Type::none;
  else if (thermostat_type == "andersen") c.thermostat.type = ThermostatSpec::Type::andersen;
  else bad("thermostat", "type", fmt::format("must be \"none\" or \"andersen\" (got \"{}\")", thermostat_type));
  if (c.thermostat.rate < 0.0)
    bad("thermostat", "rate", fmt::format("must not be negative (got {}; resamplings per body per unit time)",
                                          c.thermostat.rate));
  if (c.thermostat.active() && !(c.thermostat.rate > 0.0))
    bad("thermostat", "rate", "thermostat.type = \"andersen\" needs a positive rate (resamplings per body per unit time)");
  if (thermostat_during == "always") c.thermostat.during = ThermostatSpec::During::always;
  else if (thermostat_during == "equilibration") c.thermostat.during = ThermostatSpec::During::equilibration;
  else bad("thermostat", "during", fmt::format("must be \"always\" or \"equilibration\" (got \"{}\")", thermostat_during));
  if (c.thermostat.active() && c.thermostat.during == ThermostatSpec::During::equilibration && c.equilibrate_time == 0.0)
    bad("thermostat", "during", "is \"equilibration\" but run.equilibrate_time = 0: the thermostat would never act");
  // the box and its walls against the bodies (setup/box_setup.hpp)
  if (const auto p = boundary_problem(c)) {
    const auto dot = p->key.find('.');
    r.fail(r.node(p->key.substr(0, dot), p->key.substr(dot + 1)), p->key, p->what);
  }
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
  // (an ifstream opens a directory, and reading it gives an empty text)
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ConfigError(fmt::format("{}: is a directory, not a config file", path));
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw ConfigError(fmt::format("{}: cannot open config file ({})", path,
                                  errno ? std::strerror(errno) : "unknown reason"));
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ConfigError(fmt::format("{}: cannot read config file", path));
  Config c = parse_config(ss.str(), path, overrides);
  check_resources(c, available_memory_bytes());
  return c;
}

namespace {

// ---- the resolved config as TOML text. toml++ prints a double with 17 significant digits
// (0.10000000000000001); these print the shortest digits that read back the same double.

std::string toml_number(double x) {
  std::string t = fmt::format("{}", x);  // shortest round trip; "1e+20", "inf", "nan"
  if (t.find_first_of(".en") == std::string::npos) t += ".0";  // a float, not an integer
  return t;
}

std::string toml_string(std::string_view x) {
  const bool literal = std::none_of(x.begin(), x.end(), [](char ch) {
    return ch == '\'' || static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f;
  });
  if (literal) return "'" + std::string(x) + "'";
  std::string out = "\"";
  for (char ch : x) {
    if (ch == '"' || ch == '\\') out += '\\', out += ch;
    else if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) out += fmt::format("\\u{:04X}", int(ch));
    else out += ch;
  }
  return out + "\"";
}

std::string toml_key(std::string_view k) {
  const bool bare = !k.empty() && std::all_of(k.begin(), k.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
  });
  return bare ? std::string(k) : toml_string(k);
}

// A value: scalars, arrays "[ a, b ]" and tables inline "{ k = v, ... }".
std::string toml_value(const toml::node& n) {
  if (auto d = n.value_exact<double>()) return toml_number(*d);
  if (auto i = n.value_exact<int64_t>()) return fmt::format("{}", *i);
  if (auto b = n.value_exact<bool>()) return *b ? "true" : "false";
  if (auto str = n.value_exact<std::string>()) return toml_string(*str);
  if (const auto* a = n.as_array()) {
    std::string out = "[";
    for (std::size_t k = 0; k < a->size(); ++k) out += (k ? ", " : " ") + toml_value(*a->get(k));
    return out + (a->empty() ? "]" : " ]");
  }
  if (const auto* t = n.as_table()) {
    std::string out = "{";
    for (const auto& [k, v] : *t) out += (out.size() > 1 ? ", " : " ") + toml_key(k.str()) + " = " + toml_value(v);
    return out + (t->empty() ? "}" : " }");
  }
  throw std::logic_error("to_toml: a value of a kind the config does not use");
}

// Sections in reading order ([system] and the bodies first), arrays of tables as [[name]].
std::string toml_text(const toml::table& root) {
  std::vector<std::string> order{"system", "shape", "species", "box", "walls", "run", "thermostat",
                                 "neighbors", "init", "solver", "output", "observables"};
  for (const auto& [k, v] : root)
    if (std::find(order.begin(), order.end(), k.str()) == order.end()) order.emplace_back(k.str());
  std::string out;
  auto body = [&](const toml::table& t) {
    for (const auto& [k, v] : t) out += toml_key(k.str()) + " = " + toml_value(v) + "\n";
  };
  for (const auto& sec : order) {
    const auto* n = root.get(sec);
    if (!n) continue;
    if (const auto* t = n->as_table()) {
      out += "\n[" + toml_key(sec) + "]\n";
      body(*t);
    } else if (const auto* a = n->as_array()) {
      for (const auto& e : *a) {
        out += "\n[[" + toml_key(sec) + "]]\n";
        body(*e.as_table());
      }
    }
  }
  return out;
}

}  // namespace

std::string to_toml(const Config& c) {
  toml::table root{
      {"system", toml::table{{"packing_fraction", c.packing_fraction},
                             {"seed", int64_t(c.seed)},
                             {"temperature", c.temperature}}},
      {"run", toml::table{{"equilibrate_time", c.equilibrate_time},
                          {"time", c.time},
                          {"max_collisions", int64_t(c.max_collisions)}}},
      {"neighbors", toml::table{{"method", c.neighbors_method}, {"shell", c.shell}}},
      {"solver", toml::table{{"eps_d", c.eps_d}}},
      {"output", toml::table{{"log_interval", c.log_interval},
                             {"snapshot_interval", c.snapshot_interval},
                             {"checkpoint_interval", c.checkpoint_interval},
                             {"trajectory", c.trajectory},
                             {"max_output_gb", c.max_output_gb}}},
      {"observables", toml::table{{"interval", c.obs_interval},
                                  {"origin_every", int64_t(c.obs_origin_every)},
                                  {"max_lag", c.obs_max_lag},
                                  {"q", c.obs_q},
                                  {"q_vectors", int64_t(c.obs_q_vectors)},
                                  {"gr_interval", c.gr_interval},
                                  {"gr_bins", int64_t(c.gr_bins)}}},
  };
  if (c.species_given) {
    toml::array all;
    for (const Species& sp : c.species) {
      toml::table t{{"name", sp.name}, {"count", int64_t(sp.count)}, {"shape", shape_to_toml(sp.shape)},
                    {"mass", sp.mass}, {"inertia", toml::array{sp.inertia.x(), sp.inertia.y(), sp.inertia.z()}}};
      if (sp.poly.active())
        t.insert("polydispersity",
                 toml::table{{"distribution", sp.poly.distribution == Polydispersity::Distribution::gaussian
                                                  ? "gaussian" : "uniform"},
                             {"width", sp.poly.width}});
      all.push_back(std::move(t));
    }
    root.insert("species", std::move(all));
  } else {
    const Species& sp = c.one();
    root["system"].as_table()->insert("particles", int64_t(c.particles));
    root["system"].as_table()->insert("mass", sp.mass);
    toml::table shape = shape_to_toml(sp.shape);
    shape.insert("inertia", sp.inertia.x());
    root.insert("shape", std::move(shape));
  }
  toml::table init;
  init.insert("method", c.init_method);
  init.insert("phi0", c.init_phi0);
  init.insert("growth_rate", c.init_growth_rate);
  if (c.init_method == "file") {
    init.insert("file", c.init_file);
    if (c.init_frame != kLastFrame) init.insert("frame", static_cast<std::int64_t>(c.init_frame));
  }
  root.insert("init", init);
  const Vec3& a = c.boundaries.aspect;
  root.insert("box", toml::table{{"aspect", toml::array{a.x(), a.y(), a.z()}}});
  toml::table walls;  // planar walls (a list, maybe empty) or the container: they exclude each other
  if (c.boundaries.walls.container()) {
    walls.insert("sphere", c.boundaries.walls.sphere_radius);
  } else {
    toml::array planes;
    for (int k = 0; k < 3; ++k)
      if (c.boundaries.walls.planes[k]) planes.push_back(std::string(1, char('x' + k)));
    walls.insert("planes", std::move(planes));
  }
  root.insert("walls", std::move(walls));
  const ThermostatSpec& th = c.thermostat;
  root.insert("thermostat",
              toml::table{{"type", th.type == ThermostatSpec::Type::andersen ? "andersen" : "none"},
                          {"rate", th.rate},
                          {"during", th.during == ThermostatSpec::During::equilibration ? "equilibration" : "always"}});
  return "# hardbody resolved configuration (every key, defaults filled in)\n" + toml_text(root);
}

namespace {
const char* kind_doc(Kind k) {
  switch (k) {
    case Kind::Int: return "integer";
    case Kind::Float: return "number";
    case Kind::String: return "string";
    case Kind::Bool: return "bool";
    case Kind::Vec3: return "3 numbers";
    case Kind::Strings: return "list of strings";
  }
  return "?";
}
}  // namespace

// A markdown table cell: '|' would end the cell.
static std::string cell(std::string_view text) {
  std::string out;
  for (char ch : text) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return out;
}

std::string config_reference() {
  // defaults: a minimal config, resolved
  const Config defaults = parse_config(
      "[system]\nparticles = 256\npacking_fraction = 0.3\n[shape]\ntype = \"sphere\"\nradius = 0.5\n"
      "[run]\ntime = 1.0\n", "defaults");
  const toml::table resolved = toml::parse(to_toml(defaults));
  auto default_of = [&](const std::string& sec, const std::string& key) -> std::string {
    if ((sec == "system" && key == "particles") || (sec == "run" && key == "time"))
      return "required";
    if (sec == "system" && key == "packing_fraction") return "required (or walls.sphere)";
    if (sec == "neighbors" && key == "method") return "by shape";
    if (sec == "walls" && key == "sphere") return "none";
    const auto* t = resolved.get_as<toml::table>(sec);
    const auto* n = t ? t->get(key) : nullptr;
    if (!n) return "";
    if (auto d = n->value_exact<double>()) return fmt::format("{:g}", *d);
    if (auto i = n->value_exact<int64_t>()) return fmt::format("{}", *i);
    if (auto b = n->value_exact<bool>()) return *b ? "true" : "false";
    if (auto str = n->value_exact<std::string>()) return "\"" + *str + "\"";
    if (const auto* a = n->as_array()) {
      std::string out = "[";
      for (std::size_t k = 0; k < a->size(); ++k) {
        const auto* e = a->get(k);
        out += (k ? ", " : "") + (e->value_exact<double>() ? fmt::format("{:g}", *e->value_exact<double>())
                                                           : toml_value(*e));
      }
      return out + "]";
    }
    return "";
  };
  std::string out =
      "# Configuration keys\n\n"
      "Generated from the schema in `src/io/config.cpp` and the shape registry\n"
      "(`hardbody config-reference > docs/config.md`; a test fails when this file is out of date).\n"
      "Every key is checked: an unknown key, a wrong type or a value out of range stops the program with\n"
      "exit status 2 and one message naming the file, the key and the line. `--set section.key=value`\n"
      "overrides any key of a [section] (not of a [[species]] entry); the value is a TOML literal, a bare word a string\n"
      "(`--set neighbors.method=nnl`, `--set box.aspect=[1,1,2]`, `--set 'walls.planes=[\"z\"]'`).\n";
  std::string sec;
  for (const KeySpec& k : key_specs()) {
    if (k.section != sec) {
      sec = k.section;
      out += fmt::format("\n## [{}]\n\n| key | type | default | meaning |\n|---|---|---|---|\n", sec);
    }
    out += fmt::format("| `{}` | {} | {} | {} |\n", k.key, kind_doc(k.kind), default_of(k.section, k.key), cell(k.meaning));
  }
  out += "\n## [shape] (one species; or the `shape` of each [[species]])\n\n"
         "| key | meaning |\n|---|---|\n"
         "| `type` | the shape: " + shape_names() + " (required) |\n"
         "| `inertia` | [shape] only: scalar moment of inertia of the spherical top; default 2/5 m r_min^2 (the paper's convention) |\n";
  for_each_shape_type([&](auto s) {
    using S = decltype(s);
    out += fmt::format("| type = \"{}\" | {} |\n", S::kName, cell(ShapeCodec<S>::kDoc));
    return false;
  });
  out += "\n## [[species]] (a mixture; replaces [shape], system.particles and system.mass)\n\n"
         "| key | type | default | meaning |\n|---|---|---|---|\n"
         "| `name` | string | required | GSD type name and part of file names: unique, letters, digits, _ + - (at most 64) |\n"
         "| `count` | integer | required | bodies of this species (>= 1) |\n"
         "| `shape` | table | required | `{ type = ..., ... }` as [shape] above |\n"
         "| `mass` | number | 1 | body mass at scale 1 |\n"
         "| `inertia` | number or 3 numbers | uniform solid | principal moments along body x, y, z (positive, I_a + I_b >= I_c); one number: a spherical top |\n"
         "| `polydispersity` | table | none | `{ distribution = \"gaussian\" or \"uniform\", width = w }`: body sizes scaled by s with mean 1 and relative standard deviation w in (0, 0.3) (gaussian truncated at 3 w); mass scales as s^3, inertia as s^5 |\n"
         "\nMixtures (and polydisperse bodies) start from a random placement at `init.phi0` (lower if the\n"
         "bodies' bounding spheres would fill more than a quarter of the box) grown to\n"
         "`system.packing_fraction` (at most 0.6). Non-spherical mixtures take either neighbour method\n"
         "(per-body boxes with NNL); sphere mixtures use cell lists. Any shapes may be mixed; a body\n"
         "whose principal moments differ rotates as the exact free symmetric or asymmetric top.\n";
  out += "\n## Boxes, walls and the thermostat\n\n"
         "The box has the volume V = (sum of body volumes) / phi (with polydispersity, of the sizes drawn from\n"
         "`system.seed`) and the sides L = aspect x cbrt(V / (ax ay az)); it is periodic along every axis\n"
         "without walls. `walls.planes` puts hard walls at the two faces normal to each axis listed (at\n"
         "-L/2 and +L/2 from the box centre). `walls.sphere = R` puts the bodies in a hard spherical container\n"
         "of radius R instead: the box is the cube of side 2 R around it, periodic along no axis, and phi is\n"
         "the bodies' volume over 4 pi R^3 / 3, so `system.packing_fraction` may be omitted\n"
         "(`config.resolved.toml` records the container's phi). A body length is the largest bounding\n"
         "diameter over the species (at the largest polydisperse scale). Each of these stops the program\n"
         "(exit status 2) with one message naming the key:\n\n"
         "| key | refused |\n|---|---|\n"
         "| `box.aspect` | a side ratio that is not a positive finite number; an aspect other than [1, 1, 1] with `walls.sphere`; a periodic side shorter than two body lengths (a non-cubic box) |\n"
         "| `walls.planes` | not a list of distinct names among \"x\", \"y\", \"z\"; a walled side shorter than two body lengths (both lengths are given) |\n"
         "| `walls.sphere` | a radius that is not positive and finite; beside a non-empty `walls.planes` (\"walls.planes and walls.sphere exclude each other\"); a radius below two body lengths; a `system.packing_fraction` that differs from the container's by more than 1e-6 (relative): \"the container is too small for N bodies at phi: it needs radius R\", or \"the container is larger than N bodies at phi need (radius R); omit system.packing_fraction or set walls.sphere = R\"; without `system.packing_fraction`, a container too small for the densest start; a growth that jams below the container's phi (\"a container of radius R holds the N bodies at phi = ..., which cannot be reached: the growth jammed at packing fraction ...\") |\n"
         "| `thermostat.type` | anything but \"none\" and \"andersen\" |\n"
         "| `thermostat.rate` | a negative or non-finite rate (whatever the type); with \"andersen\", a rate that is not positive |\n"
         "| `thermostat.during` | anything but \"always\" and \"equilibration\"; \"equilibration\" with \"andersen\" and `run.equilibrate_time = 0` |\n";
  return out;
}

}  // namespace hb
