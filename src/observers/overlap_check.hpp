// The independent overlap check of a run, chosen by shape through the registry: exact centre
// distances for spheres, the Perram–Wertheim contact function for ellipsoids, surface sampling
// for every other shape (observers/overlap_sampling.hpp). None of them uses the distance or
// contact-time solver under test.
#pragma once
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "geometry/perram_wertheim.hpp"

#include "observers/overlap.hpp"
#include "observers/overlap_sampling.hpp"
#include "shapes/registry.hpp"
#include "core/state.hpp"

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

// ---- Mixtures and polydispersity --------------------------------------------------------------
// mixture_overlap_check(species_shapes): the check of a run whose bodies differ. Body i has the
// shape species_shapes[st.species[i]] scaled about its centre by st.scale[i] (an empty species
// vector means species 0 for all, an empty scale vector scale 1; an empty q means identity).
// Candidate pairs: every pair whose minimum-image centre distance is below 2 R_max, R_max the
// largest scaled bounding radius of the bodies, or below 4 R_max when every species is a sphere
// (as sphere_overlaps_grid: the closest pair of any configuration that is not extremely dilute
// is then among them, so min_distance is the smallest gap also when nothing overlaps); they
// come from for_close_pairs (a fresh grid, brute force for small boxes). Each candidate is
// decided by its pair type:
//  - sphere-sphere (any radii): exact, overlap when |r_ij| < (R_i + R_j)(1 - tol); its gap is
//    |r_ij| - R_i - R_j (as sphere_overlaps and sphere_mixture_overlaps);
//  - sphere or ellipsoid with sphere or ellipsoid (a sphere is the ellipsoid of equal
//    semi-axes; semi-axes scaled): Perram–Wertheim, overlap when F < 1 - tol; its gap is the
//    centre-line gap |r_ij| (1 - 1/sqrt F) (as ellipsoid_overlaps);
//  - any pair with another shape (superquadrics): surface sampling both ways (sampled_pair,
//    one SurfaceSampling per species shared by every scale), only when the centres are closer
//    than R_i + R_j; its gap is the sampled gap estimate (as sampled_overlaps).
// The report: overlaps = overlapping pairs, min_distance = the smallest gap over the decided
// pairs, pairs_checked = the decided pairs. For identical bodies (one species, scale 1) the
// numbers are those of the identical-body checks bit for bit: ellipsoid_overlaps,
// superquadric_overlaps / sampled_overlaps and sphere_overlaps_grid (sphere_overlaps, the brute
// force below 20000 bodies, gives the same overlaps and min_distance; only its pairs_checked,
// all N (N - 1) / 2 pairs, differs). tol = 1e-10, the default of every identical-body check.
namespace overlap_check_detail {

template <class V>
struct SamplingsOf;
template <class... S>
struct SamplingsOf<std::variant<S...>> {
  using type = std::variant<SurfaceSampling<S>...>;
};
using AnySampling = typename SamplingsOf<AnyShape>::type;

enum class PairKind : unsigned char { sphere, ellipsoid, sampled };

struct MixturePlan {
  std::vector<PairKind> kind;      // per species
  std::vector<double> bound;       // bounding radius at scale 1
  std::vector<Vec3> semi_axes;     // spheres and ellipsoids: semi-axes at scale 1
  std::vector<AnySampling> sampling;  // per species, only if some species is sampled
  bool all_spheres = true;
  double tol = 1e-10;

  explicit MixturePlan(const std::vector<AnyShape>& shapes) {
    if (shapes.empty()) throw std::invalid_argument("mixture_overlap_check: no species");
    if (shapes.size() > 65536) throw std::invalid_argument("mixture_overlap_check: more than 65536 species");
    bool any_sampled = false;
    for (const AnyShape& s : shapes) {
      kind.push_back(std::holds_alternative<Sphere>(s)      ? PairKind::sphere
                     : std::holds_alternative<Ellipsoid>(s) ? PairKind::ellipsoid
                                                            : PairKind::sampled);
      any_sampled = any_sampled || kind.back() == PairKind::sampled;
      all_spheres = all_spheres && kind.back() == PairKind::sphere;
      bound.push_back(bounding_radius(s));
      semi_axes.push_back(half_extents(s));
    }
    if (any_sampled)
      for (const AnyShape& s : shapes)
        std::visit([&](const auto& x) {
          using S = std::decay_t<decltype(x)>;
          sampling.emplace_back(std::in_place_type<SurfaceSampling<S>>, x,
                                SurfaceSampling<S>::kDefaultSamples, tol);
        }, s);
  }

  OverlapReport operator()(const State& st, const Box& box) const {
    const std::size_t n = st.r.size();
    if (!st.species.empty() && st.species.size() != n)
      throw std::invalid_argument("mixture_overlap_check: species and positions differ in size");
    if (!st.scale.empty() && st.scale.size() != n)
      throw std::invalid_argument("mixture_overlap_check: scale and positions differ in size");
    if (!st.q.empty() && st.q.size() != n)
      throw std::invalid_argument("mixture_overlap_check: orientations and positions differ in size");
    auto species = [&](std::size_t i) -> std::size_t { return st.species.empty() ? 0 : st.species[i]; };
    auto scale = [&](std::size_t i) { return st.scale.empty() ? 1.0 : st.scale[i]; };
    auto orient = [&](std::size_t i) { return st.q.empty() ? Quat::Identity() : st.q[i]; };
    double rmax = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t a = species(i);
      if (a >= kind.size())
        throw std::out_of_range("mixture_overlap_check: body " + std::to_string(i) + " has species " +
                                std::to_string(a) + " of " + std::to_string(kind.size()));
      const double s = scale(i);
      if (!(s > 0.0) || !std::isfinite(s))
        throw std::invalid_argument("mixture_overlap_check: body " + std::to_string(i) +
                                    " has a non-positive or non-finite scale");
      rmax = std::max(rmax, bound[a] * s);
    }
    OverlapReport rep;
    if (n < 2) return rep;
    for_close_pairs(st.r, box, (all_spheres ? 4.0 : 2.0) * rmax, [&](std::uint32_t i, std::uint32_t j, const Vec3& d) {
      const std::size_t a = species(i), b = species(j);
      const double sa = scale(i), sb = scale(j);
      double gap;
      bool overlap;
      if (kind[a] == PairKind::sphere && kind[b] == PairKind::sphere) {
        const double sigma = semi_axes[a].x() * sa + semi_axes[b].x() * sb;
        const double dist = d.norm();
        gap = dist - sigma;
        overlap = dist < sigma * (1.0 - tol);
      } else if (kind[a] != PairKind::sampled && kind[b] != PairKind::sampled) {
        const EllipsoidPose A{Vec3(semi_axes[a] * sa), st.r[i], orient(i)};
        const EllipsoidPose B{Vec3(semi_axes[b] * sb), Vec3(st.r[i] + d), orient(j)};
        const PerramWertheim pw = perram_wertheim(A, B, d, tol);
        // coincident centres (F = 0): no centre line; the deepest touching distance along any
        // direction is at least the sum of the inscribed radii
        gap = pw.F > 0.0 ? d.norm() * (1.0 - 1.0 / std::sqrt(pw.F))
                         : -(A.semi_axes.minCoeff() + B.semi_axes.minCoeff());
        overlap = pw.overlap;
      } else {
        if (!(d.norm() < bound[a] * sa + bound[b] * sb)) return;
        const SampledPair p = std::visit(
            [&](const auto& A, const auto& B) { return sampled_pair(A, sa, orient(i), B, sb, orient(j), d, tol); },
            sampling[a], sampling[b]);
        gap = p.gap;
        overlap = p.overlap;
      }
      ++rep.pairs_checked;
      rep.min_distance = std::min(rep.min_distance, gap);
      if (overlap) ++rep.overlaps;
    });
    return rep;
  }
};

}  // namespace overlap_check_detail

// The check of a mixture (and of polydispersity): species_shapes[k] is the shape of species k at
// scale 1 (see above). Throws std::invalid_argument for an empty table; the returned check
// throws for a species id out of range or a non-positive scale.
inline OverlapCheck mixture_overlap_check(std::vector<AnyShape> species_shapes) {
  auto plan = std::make_shared<const overlap_check_detail::MixturePlan>(species_shapes);
  return [plan](const State& st, const Box& b) { return (*plan)(st, b); };
}

}  // namespace hb
