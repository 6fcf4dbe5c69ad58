// Final overlap check of a sphere configuration, independent of the event machinery: the
// minimum centre distance over all pairs. Brute force for moderate N; a fresh grid (built
// here from the positions alone, not the simulation's cell lists) for large N.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "math/types.hpp"
#include <functional>
#include "core/box.hpp"
#include "core/field_view.hpp"

namespace hb {

struct OverlapReport {
  std::uint64_t overlaps = 0;   // pairs closer than sigma (1 - tol)
  double min_distance = kInf;   // smallest surface gap |r_ij| - sigma over close pairs
  std::uint64_t pairs_checked = 0;
};

OverlapReport sphere_overlaps_brute(FieldView<Vec3> r, const Box& box, double sigma,
                                    double tol = 1e-10);
OverlapReport sphere_overlaps_grid(FieldView<Vec3> r, const Box& box, double sigma,
                                   double tol = 1e-10);
// Brute force up to 20000 bodies, grid beyond.
OverlapReport sphere_overlaps(FieldView<Vec3> r, const Box& box, double sigma,
                              double tol = 1e-10);

// Spheres of unequal radii (mixtures, polydispersity): overlap when |r_ij| < (R_i + R_j)(1 - tol);
// min_distance is the smallest surface gap |r_ij| - R_i - R_j. Candidates from a fresh grid.
OverlapReport sphere_mixture_overlaps(FieldView<Vec3> r, const std::vector<double>& radii,
                                      const Box& box, double tol = 1e-10);

// Ellipsoids (all with the same semi-axes, orientations body -> lab): the Perram–Wertheim
// contact function F (geometry/perram_wertheim, independent of the distance solver) for every
// pair whose centres are closer than the bounding diameter; overlap when F < 1 - tol.
// min_distance is the smallest centre-line gap |r_AB| (1 - 1/sqrt(F)): zero at contact,
// negative for overlap. Candidate pairs come from a fresh grid (brute force for small boxes).
OverlapReport ellipsoid_overlaps(FieldView<Vec3> r, FieldView<Quat> q,
                                 const Box& box, const Vec3& semi_axes, double tol = 1e-10);

}  // namespace hb
