// The Python module `hardbody`: conversions between Python objects and library calls only.
// Simulations are built from the same configuration the CLI reads (a dict with the TOML's
// sections, TOML text or a TOML file); pair queries take and return the JSON-lines records of
// `hardbody distance` / `hardbody contact-time` as dicts. Docs: docs/python.md.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "io/checkpoint.hpp"
#include "observers/correlations.hpp"
#include "io/config.hpp"
#include "io/pair_query.hpp"
#include "io/run.hpp"
#include "setup/mixture_setup.hpp"
#include "sim_holder.hpp"

namespace py = pybind11;

namespace hb::py_module {

using hb::python::SimHandle;
using hb::python::Stop;

// ---------------------------------------------------------------- dict -> TOML text

std::string toml_key(const std::string& k) { return nlohmann::json(k).dump(); }

std::string toml_value(py::handle v, const std::string& key) {
  if (py::hasattr(v, "tolist") && !py::isinstance<py::str>(v))  // numpy scalars and arrays
    return toml_value(v.attr("tolist")(), key);
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v)) return py::str(v).cast<std::string>();
  if (py::isinstance<py::float_>(v)) return py::repr(v).cast<std::string>();  // round trip
  if (py::isinstance<py::str>(v)) return nlohmann::json(v.cast<std::string>()).dump();
  if (py::isinstance<py::dict>(v)) {
    std::string s = "{";
    for (auto [k, x] : v.cast<py::dict>()) {
      const std::string name = py::str(k).cast<std::string>();
      s += (s.size() > 1 ? ", " : "") + toml_key(name) + " = " + toml_value(x, key + "." + name);
    }
    return s + "}";
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::string s = "[";
    for (auto x : v) s += (s.size() > 1 ? ", " : "") + toml_value(x, key);
    return s + "]";
  }
  throw py::value_error("config key '" + key + "': cannot use a value of type " +
                        py::str(py::type::of(v).attr("__name__")).cast<std::string>());
}

// {"system": {...}, "shape": {...}, ...} -> TOML text with one table per section. The [run]
// table (run.time is required by the CLI) is filled in when missing: the module runs only on
// request (Simulation.run).
std::string dict_to_toml(const py::dict& d) {
  std::string top, tables;
  for (auto [k, v] : d) {
    const std::string sec = py::str(k).cast<std::string>();
    if (!py::isinstance<py::dict>(v)) {
      top += toml_key(sec) + " = " + toml_value(v, sec) + "\n";
      continue;
    }
    const py::dict t = v.cast<py::dict>();
    tables += "[" + toml_key(sec) + "]\n";
    for (auto [kk, vv] : t) {
      const std::string key = py::str(kk).cast<std::string>();
      tables += toml_key(key) + " = " + toml_value(vv, sec + "." + key) + "\n";
    }
    if (sec == "run" && !t.contains("time")) tables += "time = 1.0\n";
  }
  if (!d.contains("run")) tables += "[run]\ntime = 1.0\n";
  return top + tables;
}

// ---------------------------------------------------------------- numpy helpers

template <class F>
py::array_t<double> table(std::size_t rows, std::size_t cols, F&& fill) {
  py::array_t<double> a({rows, cols});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows; ++i) fill(i, &m(i, 0));
  return a;
}
py::array_t<double> vec3_table(FieldView<Vec3> v) {
  return table(v.size(), 3, [&](std::size_t i, double* o) {
    for (int k = 0; k < 3; ++k) o[k] = v[i][k];
  });
}
py::array_t<double> vec3_array(const Vec3& v) {
  py::array_t<double> a(3);
  for (int k = 0; k < 3; ++k) a.mutable_at(k) = v[k];
  return a;
}

void check_signals() {
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

// ---------------------------------------------------------------- Simulation

class Simulation {
 public:
  explicit Simulation(Config c)
      : cfg_(std::move(c)), sim_(hb::python::make_simulation(cfg_)), block_start_(sim_->now()) {}
  Simulation(Config c, const hb::Box& box, const hb::State& start)
      : cfg_(std::move(c)), sim_(hb::python::make_simulation(cfg_, box, start)),
        block_start_(sim_->now()) {}

  // Advances by `time`, to the absolute time `until`, and/or by `collisions` real collisions,
  // whichever comes first; stops exactly at the time limit. Pressure blocks are
  // output.log_interval long (aligned with reset_observables()).
  void run(std::optional<double> time, std::optional<std::uint64_t> collisions,
           std::optional<double> until) {
    if (!time && !collisions && !until)
      throw py::value_error("run(): give time=, until= and/or collisions=");
    double t_end = std::numeric_limits<double>::infinity();
    if (time) {
      if (!(*time >= 0.0 && std::isfinite(*time)))
        throw py::value_error("run(): time must be finite and not negative");
      t_end = sim_->now() + *time;
    }
    if (until) {
      if (!(*until >= sim_->now() && std::isfinite(*until)))
        throw py::value_error("run(): until must be finite and not before the current time");
      t_end = std::min(t_end, *until);
    }
    const std::uint64_t c_end =
        collisions ? sim_->collisions() + *collisions : std::numeric_limits<std::uint64_t>::max();
    const double block = cfg_.log_interval;
    for (;;) {
      const double block_end = block_start_ + block;
      const Stop stop = sim_->advance(std::min(t_end, block_end), c_end, pressure_, check_signals);
      if (sim_->now() >= block_end) {
        pressure_.close_block(sim_->now() - block_start_, sim_->temperature(), n());
        block_start_ = sim_->now();
      }
      if (stop == Stop::collisions || sim_->now() >= t_end) break;
      check_signals();
    }
  }

  // (Z, error) since the last reset: Z = beta P / rho from the collision virial, including the
  // open block; the error is the block-averaged standard error of the closed blocks (NaN with
  // fewer than two).
  py::tuple pressure() const {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    VirialPressure all = pressure_;
    const double dt = sim_->now() - block_start_;
    if (dt > 0.0) all.close_block(dt, sim_->temperature(), n());
    const MeanError closed = pressure_.Z();
    const MeanError z = all.Z();
    return py::make_tuple(z.blocks > 0 ? z.mean : nan, closed.blocks >= 2 ? closed.error : nan);
  }
  void reset_observables() {
    pressure_.reset();
    block_start_ = sim_->now();
  }

  std::size_t n() const { return cfg_.particles; }
  double time() const { return sim_->now(); }
  std::uint64_t collisions() const { return sim_->collisions(); }
  py::array_t<double> box() const { return vec3_array(sim_->box().L); }
  double packing_fraction() const { return body_volume(cfg_.species, sim_->synchronized()) / sim_->box().volume(); }
  double kinetic_energy() const { return sim_->kinetic_energy(); }
  double temperature() const { return sim_->temperature(); }
  std::uint64_t overlaps() const { return sim_->overlaps().overlaps; }
  double min_distance() const { return sim_->overlaps().min_distance; }
  std::string config() const { return to_toml(cfg_); }
  py::dict events() const {
    py::dict d;
    const auto c = sim_->event_counts();
    for (int k = 1; k < kEventTypes; ++k) d[event_name(EventType(k))] = c[k];
    d["stale"] = sim_->stale_events();
    return d;
  }

  py::array_t<double> positions() const { return vec3_table(sim_->synchronized().r); }
  py::array_t<double> unwrapped_positions() const {
    const State s = sim_->synchronized();
    const Vec3 L = sim_->box().L;
    return table(s.size(), 3, [&](std::size_t i, double* o) {
      for (int k = 0; k < 3; ++k) o[k] = s.r[i][k] + double(s.image[i][k]) * L[k];
    });
  }
  py::array_t<double> velocities() const { return vec3_table(sim_->synchronized().v); }
  py::array_t<double> angular_velocities() const { return vec3_table(sim_->synchronized().w); }
  py::array_t<double> orientations() const {
    const State s = sim_->synchronized();
    return table(s.size(), 4, [&](std::size_t i, double* o) {
      o[0] = s.q[i].w(), o[1] = s.q[i].x(), o[2] = s.q[i].y(), o[3] = s.q[i].z();
    });
  }

  std::string repr() const {
    return "<hardbody.Simulation " + (cfg_.species.size() == 1 ? std::string(shape_name(cfg_.one().shape)) : std::string("mixture")) + " N=" + std::to_string(n()) +
           " t=" + py::repr(py::float_(time())).cast<std::string>() +
           " collisions=" + std::to_string(collisions()) + ">";
  }

 public:
  // synchronized state and box, for observers sampled from Python
  hb::State state_now() const { return sim_->synchronized(); }
  const hb::Box& box_now() const { return sim_->box(); }
  double time_now() const { return sim_->now(); }

 private:
  Config cfg_;
  std::unique_ptr<SimHandle> sim_;
  VirialPressure pressure_;
  double block_start_ = 0.0;
};

std::vector<std::string> as_overrides(const std::optional<std::vector<std::string>>& o) {
  return o ? *o : std::vector<std::string>{};
}

Config config_from(const py::object& config, const std::vector<std::string>& overrides) {
  if (py::isinstance<py::dict>(config))
    return parse_config(dict_to_toml(config.cast<py::dict>()), "config dict", overrides);
  if (py::isinstance<py::str>(config) || py::hasattr(config, "__fspath__")) {
    const std::string path = py::module_::import("os").attr("fspath")(config).cast<std::string>();
    return load_config(path, overrides);
  }
  throw py::type_error("Simulation(config): config must be a dict or a path to a TOML file");
}

// ---------------------------------------------------------------- pair queries

// One query through the CLI's JSON-lines code: dict -> JSON line -> result line -> dict,
// with the points as numpy arrays.
template <class Query>
py::object pair_query(const py::dict& q, const char* source, Query query) {
  const py::module_ json = py::module_::import("json");
  const py::cpp_function to_list([](py::object o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("cannot convert a value of type " +
                         py::str(py::type::of(o).attr("__name__")).cast<std::string>() + " to JSON");
  });
  const auto line = py::cast<std::string>(
      json.attr("dumps")(q, py::arg("allow_nan") = false, py::arg("default") = to_list));
  std::istringstream in(line);
  std::ostringstream out;
  query(in, out, source);
  py::dict r = json.attr("loads")(out.str());
  for (const char* k : {"point_a", "point_b", "point", "normal"})
    if (r.contains(k) && !r[k].is_none()) {
      const auto v = py::cast<std::vector<double>>(r[k]);
      r[k] = py::array_t<double>(py::ssize_t(v.size()), v.data());
    }
  return r;
}

py::object distance(const py::object& a, const py::object& b) {
  py::dict q;
  q["a"] = a;
  q["b"] = b;
  return pair_query(q, "hardbody.distance", [](std::istream& in, std::ostream& out, const char* s) {
    distance_queries(in, out, s);
  });
}

py::object contact_time(const py::object& a, const py::object& b, double t_max, double eps_d) {
  if (!(eps_d > 0.0 && eps_d < 1.0)) throw py::value_error("contact_time(): eps_d must be in (0, 1)");
  py::dict q;
  q["a"] = a;
  q["b"] = b;
  q["t_max"] = t_max;
  return pair_query(q, "hardbody.contact_time",
                    [eps_d](std::istream& in, std::ostream& out, const char* s) {
                      contact_time_queries(in, out, s, eps_d);
                    });
}

}  // namespace hb::py_module

PYBIND11_MODULE(hardbody, m) {
  using namespace hb::py_module;
  using Sim = hb::py_module::Simulation;
  m.doc() = "Event-driven molecular dynamics of hard rigid bodies (see docs/python.md).";

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const hb::ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const hb::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  py::class_<Sim>(m, "Simulation",
                  "A simulation built as `hardbody run` builds it (lattice start at t = 0).\n\n"
                  "config: a dict {'system': {...}, 'shape': {...}, ...} with the TOML's sections "
                  "and keys, or the path of a TOML file. overrides: 'section.key=value' strings "
                  "(as --set). Invalid configurations raise ValueError naming the key.")
      .def(py::init([](const py::object& config, std::optional<std::vector<std::string>> overrides) {
             return std::make_unique<Sim>(config_from(config, as_overrides(overrides)));
           }),
           py::arg("config"), py::arg("overrides") = py::none())
      .def_static("from_gsd",
                  [](const std::string& path, const py::object& config, long frame,
                     std::optional<std::vector<std::string>> overrides) {
                    hb::Config c = config_from(config, as_overrides(overrides));
                    hb::Box box;
                    const hb::State st = hb::state_from_gsd(path, frame, box);
                    return std::make_unique<Sim>(std::move(c), box, st);
                  },
                  py::arg("path"), py::arg("config"), py::arg("frame") = -1,
                  py::arg("overrides") = py::none(),
                  "Builds a simulation from the bodies of a GSD frame (trajectory.gsd or "
                  "checkpoint.gsd; exact doubles when present) with the physics of `config`; "
                  "time starts at 0. The frame must match system.particles and be overlap-free.")
      .def_static("from_toml",
                  [](const std::string& text, std::optional<std::vector<std::string>> overrides) {
                    return std::make_unique<Sim>(hb::parse_config(text, "config text", as_overrides(overrides)));
                  },
                  py::arg("text"), py::arg("overrides") = py::none(), "Builds a simulation from TOML text.")
      .def("run", &Sim::run, py::arg("time") = py::none(), py::arg("collisions") = py::none(),
           py::arg("until") = py::none(),
           "Advance by `time`, up to the absolute time `until`, and/or by `collisions` collisions, "
           "whichever comes first (time limits are met exactly).")
      .def("pressure", &Sim::pressure,
           "(Z, error): compressibility factor beta P / rho from the collision virial over what "
           "was run since the last reset_observables(), with its block-averaged standard error "
           "(blocks of output.log_interval; NaN with fewer than two closed blocks).")
      .def("reset_observables", &Sim::reset_observables, "Start measuring the pressure afresh.")
      .def("kinetic_energy", &Sim::kinetic_energy, "Total kinetic energy (translation + rotation).")
      .def("overlaps", &Sim::overlaps,
           "Number of overlapping pairs by the independent check (0 for a valid state).")
      .def("min_distance", &Sim::min_distance, "Smallest gap found by the overlap check.")
      .def_property_readonly("time", &Sim::time)
      .def_property_readonly("collisions", &Sim::collisions)
      .def_property_readonly("N", &Sim::n)
      .def_property_readonly("box", &Sim::box, "Box side lengths, numpy (3,).")
      .def_property_readonly("packing_fraction", &Sim::packing_fraction)
      .def_property_readonly("temperature", &Sim::temperature, "Translational 2 K_trans / (3 N).")
      .def_property_readonly("positions", &Sim::positions,
                             "numpy (N, 3) at the current time, wrapped into [0, L).")
      .def_property_readonly("unwrapped_positions", &Sim::unwrapped_positions,
                             "numpy (N, 3) at the current time, periodic images undone.")
      .def_property_readonly("velocities", &Sim::velocities, "numpy (N, 3).")
      .def_property_readonly("orientations", &Sim::orientations,
                             "numpy (N, 4) quaternions w, x, y, z (body to lab).")
      .def_property_readonly("angular_velocities", &Sim::angular_velocities, "numpy (N, 3), lab frame.")
      .def_property_readonly("events", &Sim::events, "Event counts by type, and stale events.")
      .def_property_readonly("config", &Sim::config, "The resolved configuration as TOML text.")
      .def("__repr__", &Sim::repr);

  py::class_<hb::TimeCorrelations>(
      m, "Correlations",
      "MSD, C1, C2, F_self and alpha2 with multiple time origins (observers/correlations.hpp). "
      "Call sample(sim) every `interval` of simulated time (run(time=interval) in between).")
      .def(py::init([](double interval, int origin_every, double max_lag, double q, int q_vectors) {
             hb::CorrelationSpec sp;
             sp.interval = interval;
             sp.origin_every = origin_every;
             sp.max_lag_samples = std::max(1, int(std::lround(max_lag / interval)));
             sp.q = q;
             sp.max_q_vectors = q_vectors;
             return hb::TimeCorrelations(sp);
           }),
           py::arg("interval") = 0.1, py::arg("origin_every") = 10, py::arg("max_lag") = 10.0,
           py::arg("q") = 2.0 * hb::kPi, py::arg("q_vectors") = 6)
      .def("sample", [](hb::TimeCorrelations& c, const Sim& sim) {
             c.sample(sim.time_now(), sim.state_now(), sim.box_now());
           }, py::arg("sim"))
      .def_property_readonly("times", [](const hb::TimeCorrelations& c) { return py::array_t<double>(py::cast(c.times())); })
      .def_property_readonly("msd", [](const hb::TimeCorrelations& c) { return py::array_t<double>(py::cast(c.msd())); })
      .def_property_readonly("c1", [](const hb::TimeCorrelations& c) { return py::array_t<double>(py::cast(c.c1())); })
      .def_property_readonly("c2", [](const hb::TimeCorrelations& c) { return py::array_t<double>(py::cast(c.c2())); })
      .def_property_readonly("fself", [](const hb::TimeCorrelations& c) { return py::array_t<double>(py::cast(c.fself())); })
      .def("diffusion", [](const hb::TimeCorrelations& c) {
             const auto f = c.diffusion();
             return py::dict(py::arg("D") = f.D, py::arg("t_from") = f.t_from, py::arg("t_to") = f.t_to,
                             py::arg("points") = f.points);
           });

  m.def("distance", &distance, py::arg("a"), py::arg("b"),
        "Distance of two posed bodies (dicts as in `hardbody distance`): "
        "{'distance', 'point_a', 'point_b'}; negative when they overlap.");
  m.def("contact_time", &contact_time, py::arg("a"), py::arg("b"), py::arg("t_max"),
        py::arg("eps_d") = 1e-5,
        "First contact in [0, t_max] of two freely moving bodies (dicts as in "
        "`hardbody contact-time`): {'time', 'point', 'normal'}, all None when they do not touch.");
}
