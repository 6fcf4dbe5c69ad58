// The box of a run from its config alone (DESIGN.md "Boxes and walls"): its sides (box.aspect and
// the packing fraction, or the spherical container), which axes are periodic (walls.planes), the
// effective packing fraction, and the geometric checks of the walls. The config reader
// (io/config.cpp) runs the checks; the builder and the drivers take the box and phi from here.
#pragma once
#include <optional>
#include <string>

#include "core/box.hpp"
#include "setup/config.hpp"

namespace hb {

// Sum of the body volumes: count x volume over the species; with polydispersity, sum_i v_i s_i^3
// over the scales the starts draw from system.seed (species_state), so that a box of volume
// total / phi holds the grown bodies at exactly phi.
double total_body_volume(const Config& c);

// The body length: the largest bounding diameter over the species, at the largest scale their
// polydispersity can draw.
double body_length(const Config& c);

// 4 pi R^3 / 3.
double container_volume(double radius);

// The radius of the spherical container that holds the config's bodies at packing fraction phi.
double container_radius_for(const Config& c, double phi);
// The volume phi refers to: the spherical container's, or the box's.
double phi_volume(const Config& c, const Box& box);

// The run's packing fraction: with a spherical container (walls.sphere = R) the bodies' volume
// over the container's, N v / (4 pi R^3 / 3); otherwise system.packing_fraction.
double packing_fraction(const Config& c);

// The box of the run. With walls.sphere = R: a cube of side 2 R around the container, periodic
// along no axis. Otherwise sides L = aspect x cbrt(V / (ax ay az)) with V = total_body_volume / phi
// (so L_x : L_y : L_z = box.aspect and the volume is V), periodic except along walls.planes.
// With the default aspect this is cubic_box_for's cube.
Box box_for(const Config& c);

// A geometric problem of the boundaries: the key to change and what is wrong with it.
struct BoundaryProblem {
  std::string key;   // "walls.planes", "walls.sphere" or "box.aspect"
  std::string what;  // the message after "key '...': "
};

// The first geometric problem of the config's box and walls, if any:
//   walls.sphere  the container's radius is below two body lengths;
//   walls.planes  a walled side of box_for is shorter than two body lengths;
//   box.aspect    (a non-cubic aspect) a periodic side is shorter than two body lengths (the
//                 minimum image; cubic boxes are checked by the builder against the interaction
//                 range).
// Needs a validated config (positive packing fraction, species read).
std::optional<BoundaryProblem> boundary_problem(const Config& c);

// boundary_problem as a ConfigError "<source>: key '<key>': <what>" (exit status 2).
void check_boundaries(const Config& c);

}  // namespace hb
