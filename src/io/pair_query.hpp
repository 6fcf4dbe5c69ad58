// `hardbody distance` and `hardbody contact-time`: JSON lines in, JSON lines out (DESIGN.md
// contract). One pair per input line; a malformed line stops with InputError naming the line
// (and the key: unknown keys, all of them, with a "did you mean" for near misses; numbers that
// overflow a double; inputs the solvers cannot resolve).
//
// Both commands know the same keys: top level a, b, t_max; body shape, position, orientation,
// velocity, angular_velocity, inertia (`distance` ignores the motion keys and t_max, so a
// contact-time line, e.g. a run's reproducer, can be given to it). Orientations are any
// non-zero quaternion, normalised after dividing by the largest |component|.
//
// Each pair is solved in units of its size (the power of two at or below the larger bounding
// radius; positions relative to A), so scaled copies give exactly scaled answers at any size a
// double holds. `distance` of overlapping pairs reports the penetration depth (the shortest
// separating translation, geometry/penetration.hpp) and the deepest pair of points; a warning
// goes to stderr when the depth could not be certified to 1e-6 of the smaller body.
#pragma once
#include <istream>
#include <ostream>
#include <string>

namespace hb {

// Returns the number of pairs processed. `source` names the input in error messages.
std::size_t distance_queries(std::istream& in, std::ostream& out, const std::string& source);
// eps_d is a length (the search's distance accuracy); each pair refuses one that is not in
// [1e-13, 0.1] times its smaller inscribed radius, and motions whose rounding exceeds it.
std::size_t contact_time_queries(std::istream& in, std::ostream& out, const std::string& source,
                                 double eps_d = 1e-5);

}  // namespace hb
