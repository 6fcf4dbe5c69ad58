// The species table: what kinds of bodies a run holds (DESIGN.md "Species and mixtures"). Each
// body carries its species id and its size scale in the State; everything else about it (shape,
// mass, inertia) is looked up here, HOOMD-style: parameters per type, indexed by id.
//
// Size polydispersity: body i of a polydisperse species is its shape scaled by s_i about the
// centre (the scale law that growth uses, shapes/scaled.hpp), drawn once at the start with mean 1
// and relative standard deviation `width`: gaussian truncated at 3 widths, or uniform on
// [1 - sqrt(3) width, 1 + sqrt(3) width]. Its mass scales as s^3 and its inertia as s^5 (uniform
// density).
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "math/types.hpp"
#include "shapes/registry.hpp"

namespace hb {

struct Polydispersity {
  enum class Distribution { none, gaussian, uniform };
  Distribution distribution = Distribution::none;
  double width = 0.0;  // relative standard deviation of the scale
  bool active() const { return distribution != Distribution::none; }
  // largest scale the distribution can draw (gaussian truncated at 3 widths)
  double max_scale() const {
    return distribution == Distribution::gaussian ? 1.0 + 3.0 * width
           : distribution == Distribution::uniform ? 1.0 + 1.7320508075688772 * width : 1.0;
  }
};

struct Species {
  std::string name;         // GSD type name; unique in a run
  std::uint64_t count = 0;  // bodies of this species
  AnyShape shape = Sphere{0.5};
  double mass = 1.0;                  // at scale 1
  Vec3 inertia = Vec3::Constant(0.1); // principal moments along body x, y, z at scale 1
  Polydispersity poly;

  bool spherical_top() const { return inertia.x() == inertia.y() && inertia.y() == inertia.z(); }
  double mass_at(double scale) const { return mass * scale * scale * scale; }
};

using SpeciesTable = std::vector<Species>;

inline std::uint64_t total_count(const SpeciesTable& t) {
  std::uint64_t n = 0;
  for (const Species& s : t) n += s.count;
  return n;
}

// Index of the unordered species pair {a, b} among the ns (ns + 1) / 2 pairs a <= b, listed row
// by row (0-0, 0-1, ..., 0-(ns-1), 1-1, ...): the layout of every per-pair table of a run.
inline std::size_t species_pair_index(std::size_t a, std::size_t b, std::size_t ns) {
  if (a > b) std::swap(a, b);
  return a * ns - a * (a - 1) / 2 + (b - a);
}

}  // namespace hb
