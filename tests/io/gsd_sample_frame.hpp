// A HOOMD frame with every field set and none at its schema default, shared by the C++ GSD tests
// and the sample writer of the Python round trip (tests/python).
#pragma once
#include <cmath>
#include <limits>

#include "io/gsd_hoomd.hpp"

namespace hb::gsd::test {

// Deterministic values that need every bit of a double (not representable as float).
inline double sample_value(int seed, int i) {
  return std::sin(0.7 * seed + 1.3 * i) * 3.3 + 1e-9 * i;
}

inline HoomdFrame sample_frame(std::uint64_t step, std::uint32_t N, int seed) {
  HoomdFrame f;
  f.step = step;
  f.box = {10.5f, 11.0f, 12.25f, 0.0f, 0.125f, 0.0f};
  f.N = N;
  f.types = {"ellipsoid", "sphere", "superquadric"};
  f.type_shapes = {ellipsoid_shape(2.0, 1.0, 0.5), sphere_shape(1.0),
                   convex_polyhedron_shape({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, -1, -1}})};
  LogArray pos{N, 3, {}};
  for (std::uint32_t i = 0; i < N; ++i) {
    f.type_id.push_back(i % 3);
    for (int k = 0; k < 3; ++k) {
      const int j = static_cast<int>(3 * i) + k;
      pos.values.push_back(sample_value(seed, j));
      f.position.push_back(static_cast<float>(pos.values.back()));
      f.velocity.push_back(static_cast<float>(sample_value(seed + 1, j)));
      f.image.push_back(static_cast<std::int32_t>(i) - k);
    }
    const double a = 0.3 * (i + 1) + seed;
    f.orientation.insert(f.orientation.end(),
                         {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a) * 0.6),
                          0.0f, static_cast<float>(std::sin(a) * 0.8)});
    f.angmom.insert(f.angmom.end(), {0.0f, 0.5f * i + seed, -0.25f * i, 1.0f});
  }
  f.log["particles/hardbody/position_double"] = pos;
  f.log["hardbody/time"] = LogArray{1, 1, {sample_value(seed, 100)}};
  f.log["hardbody/special"] = LogArray{1, 4,
                                       {-0.0, std::numeric_limits<double>::denorm_min(),
                                        std::numeric_limits<double>::max(), 0.1 * seed}};
  return f;
}

// Orientations all identity (the schema default).
inline void set_identity_orientations(HoomdFrame& f) {
  f.orientation.assign(std::size_t{4} * f.N, 0.0f);
  for (std::uint32_t i = 0; i < f.N; ++i) f.orientation[4 * i] = 1.0f;
}

}  // namespace hb::gsd::test
