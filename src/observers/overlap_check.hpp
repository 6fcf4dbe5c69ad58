// The independent overlap check of a run, chosen by shape through the registry: exact centre
// distances for spheres, the Perram–Wertheim contact function for ellipsoids, surface sampling
// for every other shape (observers/overlap_sampling.hpp). None of them uses the distance or
// contact-time solver under test.
#pragma once
#include <functional>
#include <memory>

#include "observers/overlap.hpp"
#include "observers/overlap_sampling.hpp"
#include "shapes/registry.hpp"
#include "system/state.hpp"

namespace hb {

using OverlapCheck = std::function<OverlapReport(const State&, const Box&)>;

namespace overlap_check_detail {
inline OverlapCheck of(const Sphere& s) {
  return [sigma = 2.0 * s.radius](const State& st, const Box& b) { return sphere_overlaps(st.r, b, sigma); };
}
inline OverlapCheck of(const Ellipsoid& e) {
  return [axes = e.half_extents()](const State& st, const Box& b) {
    return ellipsoid_overlaps(st.r, st.q, b, axes);
  };
}
// Any other shape: one surface sampling shared by every check of the run.
template <Shape S>
OverlapCheck of(const S& shape) {
  auto check = std::make_shared<const SurfaceSampling<S>>(shape);
  return [check](const State& st, const Box& b) { return sampled_overlaps(st.r, st.q, b, *check); };
}
}  // namespace overlap_check_detail

// The check for identical bodies of shape s.
inline OverlapCheck independent_overlap_check(const AnyShape& s) {
  return std::visit([](const auto& x) { return overlap_check_detail::of(x); }, s);
}

}  // namespace hb
