// The event sources of single bodies, as the event loop sees them: a body against a fixed object
// (locals/: hard planar walls, a hard spherical container) and system events that act on one body at a time (thermostat/: the
// Andersen thermostat). Each
// predicts the body's next event of its kind from the body's own trajectory only, so an event
// stays valid until the body's own counter changes: the loop keeps it in the body's calendar slot
// beside its best collision and its neighbour event, and runs it when it comes up.
//
// The shape, mass and growth of body i come from the pair model (Model::visit_body), so every
// shape and species of every model meets the walls through the same code.
#pragma once
#include <cstdint>
#include <type_traits>
#include <utility>

#include "collision/record.hpp"
#include "core/box.hpp"
#include "core/state.hpp"
#include "events/event.hpp"
#include "locals/planar_walls.hpp"
#include "locals/spherical_container.hpp"
#include "thermostat/andersen.hpp"

namespace hb {

class BodyEvents {
 public:
  BodyEvents() = default;
  explicit BodyEvents(PlanarWalls walls, AndersenThermostat thermostat = {},
                      SphericalContainer container = {})
      : walls_(walls), container_(container), thermostat_(std::move(thermostat)) {}

  bool active() const { return walls_.active() || container_.active() || thermostat_.active(); }
  const PlanarWalls& walls() const { return walls_; }
  const SphericalContainer& container() const { return container_; }
  const AndersenThermostat& thermostat() const { return thermostat_; }
  AndersenThermostat& thermostat() { return thermostat_; }

  // Before the first prediction of a fresh run (n bodies at time now); a restored thermostat
  // keeps its state.
  void prepare(std::size_t n, double now) {
    if (thermostat_.rate() > 0.0 && !thermostat_.started(n)) thermostat_.start(n, now);
  }

  // Body i's earliest event of these sources in [now, t_end] (body i stored at `now`); type
  // None when there is none.
  template <class Model>
  Event predict(const Model& m, const State& s, const Box& box, std::uint32_t i, double now,
                double t_end) const {
    Event e;
    e.owner = i;
    if (walls_.active() || container_.active()) {
      m.visit_body(s, i, now, [&](const auto& shape, const MassProperties&, const BodyGrowth& g, double law_end) {
        const WallContact c = walls_.active()
                                  ? walls_.contact(shape, s.body(i), g, box, now, std::min(t_end, law_end))
                                  : container_.contact(shape, s.body(i), g, box, now, std::min(t_end, law_end));
        if (c.time < e.time) {
          e.time = c.time;
          e.type = EventType::Wall;
          e.partner = static_cast<std::uint32_t>(c.face);  // 0..5 box faces, 6 the container
        }
      });
    }
    if (thermostat_.active() && thermostat_.next(i) < e.time) {
      e.time = thermostat_.next(i);
      e.type = EventType::Thermostat;
      e.partner = 0;
    }
    return e;
  }

  // Run event e of body e.owner (stored at `now`): its velocities change.
  template <class Model>
  CollisionRecord run(const Model& m, State& s, const Box& box, const Event& e, double now) {
    CollisionRecord rec;
    const std::uint32_t i = e.owner;
    if (e.type == EventType::Thermostat) {
      m.visit_body(s, i, now, [&](const auto& shape, const MassProperties& mass, const BodyGrowth&, double) {
        constexpr bool sphere = std::is_same_v<std::decay_t<decltype(shape)>, Sphere>;
        rec.dE = thermostat_.fire(s, i, now, mass.mass, Vec3(mass.inertia_body.diagonal()), !sphere);
      });
      rec.a = i;
      rec.time = now;
      return rec;
    }
    m.visit_body(s, i, now, [&](const auto& shape, const MassProperties& mass, const BodyGrowth& g, double) {
      BodyState b = s.body(i);
      rec = e.partner == SphericalContainer::kWall ? container_.collide(shape, b, mass, g, box)
                                                   : walls_.collide(shape, b, mass, g, static_cast<int>(e.partner));
      s.v[i] = b.v;
      s.w[i] = b.w;
    });
    rec.a = i;
    rec.time = now;
    return rec;
  }

 private:
  PlanarWalls walls_;  // planar walls and the container exclude each other (the config's check)
  SphericalContainer container_;
  AndersenThermostat thermostat_;
};

}  // namespace hb
