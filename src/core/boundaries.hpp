// What bounds the bodies of a run (DESIGN.md "Boxes and walls"), as read from the config: the
// box's side ratios, hard planar walls on some axes, or a hard spherical container. The engine
// side is core/box.hpp (periodic flags) and locals/ (the wall event sources).
#pragma once
#include <array>
#include <string>

#include "math/types.hpp"

namespace hb {

struct WallSpec {
  // planes[k]: hard planar walls at the two faces of the box normal to axis k (x, y, z); the box
  // is then not periodic along k. Walls sit at 0 and L_k in the engine's coordinates, i.e. at
  // -L_k/2 and +L_k/2 from the box centre (the coordinates of the outputs).
  std::array<bool, 3> planes{false, false, false};
  // > 0: a hard spherical container of this radius, centred at the box centre; the box is then a
  // cube of side 2 R, periodic along no axis, and phi = N v / (4 pi R^3 / 3).
  double sphere_radius = 0.0;

  bool any_plane() const { return planes[0] || planes[1] || planes[2]; }
  bool container() const { return sphere_radius > 0.0; }
  bool any() const { return any_plane() || container(); }
};

struct BoundarySpec {
  Vec3 aspect = Vec3::Ones();  // [box] aspect: side ratios Lx : Ly : Lz (default cubic)
  WallSpec walls;
};

// Andersen thermostat (DESIGN.md "Thermostat"): each body's translational and angular velocity is
// redrawn from the Maxwell distribution at the run temperature at the events of a Poisson process
// of `rate` per body per unit time.
struct ThermostatSpec {
  enum class Type { none, andersen };
  enum class During { always, equilibration };
  Type type = Type::none;
  double rate = 0.0;
  During during = During::always;
  bool active() const { return type != Type::none; }
};

}  // namespace hb
