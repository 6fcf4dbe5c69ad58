// Observables of confined systems (DESIGN.md "Boxes and walls"): the pressure on the hard walls
// from their impulses (WallPressure), the density and orientational order profiles of the body
// centres along the wall normals or radially in a spherical container (DensityProfiles), and the
// contact value of a density profile (contact_density) for the contact theorem. Read-only: the
// run driver feeds wall impulses and synchronised states. Definitions and table formats are in
// docs/observables.md ("Walls").
//
// Coordinates: the engine's, positions in [0, L) (walls at 0 and L_k on a walled axis k; the
// container, of radius R, is centred at L / 2). The tables give positions from the box centre.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/boundaries.hpp"
#include "core/box.hpp"
#include "core/species.hpp"
#include "core/state.hpp"
#include "math/types.hpp"
#include "observers/block_average.hpp"

namespace hb {

// Total area of the hard walls of `walls` in `box`: 2 L_j L_k for each walled axis i (the two
// faces normal to it, j and k the other axes), plus 4 pi R^2 for a container. 0 without walls.
double wall_area(const WallSpec& walls, const Box& box);

// beta P on the walls: the impulses the walls receive per unit area and time, over kT.
// One block per log interval (the blocks of Z): beta P_block = sum J / (A dt kT); the mean is the
// ratio of the sums over the whole measured time, sum J / (A sum(kT dt)) (the block mean for
// equal blocks at one kT), and its error the block-averaged standard error of block_average()
// over the block values: NaN (null in summary.json) with fewer than two blocks, as Z_error.
class WallPressure {
 public:
  // area: the total wall area (wall_area()); must be > 0.
  explicit WallPressure(double area = 1.0);

  // One wall impulse: J > 0 the impulse magnitude along the wall normal (the CollisionRecord's
  // J of a wall collision) at `time`. Throws std::invalid_argument when J is negative or not
  // finite (the accumulators are then unchanged).
  void add(double time, double J);
  // Close the current block of duration dt (> 0; a block of dt <= 0 is ignored, as in
  // VirialPressure) at temperature kT: the same dt and kT the driver gives VirialPressure.
  void close_block(double dt, double kT);
  void reset();

  double area() const { return area_; }
  double last() const { return last_; }  // beta P of the last closed block
  const std::vector<double>& blocks() const { return blocks_; }
  MeanError pressure() const;  // beta P over the measured time, with its block error
  double measured_time() const { return total_time_; }
  std::uint64_t impulses() const { return total_impulses_; }  // wall collisions in closed blocks
  double last_impulse_time() const { return last_time_; }

  // Flat serialisation for checkpoints (exact doubles; counts < 2^53). load() throws
  // std::invalid_argument on a record of the wrong length or of another wall area.
  std::vector<double> save() const;
  void load(const std::vector<double>& record);

 private:
  double area_;
  double sum_ = 0.0, total_sum_ = 0.0;         // sum J in the open block / in closed blocks
  double total_time_ = 0.0, total_kT_time_ = 0.0;
  std::uint64_t impulses_ = 0, total_impulses_ = 0;
  double last_ = 0.0, last_time_ = 0.0;
  std::vector<double> blocks_;
};

// What DensityProfiles needs to know of a species.
struct ProfileSpecies {
  std::string name;       // column density_<name>
  bool sphere = true;     // left out of the order profile
  int long_axis = 0;      // body axis (0 x, 1 y, 2 z) of the largest semi-axis: u = q * e_axis
};
// From the species table: sphere = the shape is a Sphere; long_axis = the body axis of the
// largest half-extent (the first of equal ones, so body x for a prolate spheroid [a, b, b]).
std::vector<ProfileSpecies> profile_species(const SpeciesTable& species);
// Default bin width: 0.02 x the smallest bounding diameter among the species (scale 1), so the
// bins next to a wall resolve its contact layer.
double default_profile_bin(const SpeciesTable& species);

// One histogram of DensityProfiles: along a walled axis (k = 0, 1, 2) over [0, L_k], or radial
// (k = 3) over [0, R] about the box centre.
struct ProfileAxis {
  int k = 0;
  double extent = 0.0;  // L_k or R
  double width = 0.0;   // bin width: extent / bins
  std::size_t bins = 0;
  double area = 0.0;    // slab: the cross-section L_i L_j; radial: 0
  bool radial() const { return k == 3; }
  char name() const { return "xyzr"[k]; }
  double volume(std::size_t bin) const;   // of the slab or the spherical shell
  double position(std::size_t bin) const; // bin centre from the box centre (slab) or shell mid-radius
};

// Number density profiles of the body centres, sampled at snapshot times:
//   slab along walled axis k: rho_a(bin) = counts_a / (width x L_i L_j x samples)
//   container: rho_a(shell) = counts_a / (4/3 pi (r_hi^3 - r_lo^3) x samples)
// per species a and in total, and the orientational order of the non-sphere bodies per bin:
// Q = < 3/2 u u^T - 1/2 I > over the bodies of the bin (all samples), s2 its largest eigenvalue,
// and p2_normal = < P2(u . n) > with n the wall normal (e_k; radial: the unit vector from the
// centre). A centre outside [0, extent] (rounding at a wall) counts in the end bin.
class DensityProfiles {
 public:
  // bin: requested bin width (> 0); each histogram has ceil(extent / bin) bins of width
  // extent / bins (<= bin), so the bins tile [0, L_k] or [0, R] exactly. Throws
  // std::invalid_argument without walls, with bin <= 0, with no species, or when a histogram
  // would have more than 10^7 bins.
  DensityProfiles(const WallSpec& walls, const Box& box, std::vector<ProfileSpecies> species, double bin);

  // Add the bodies of `state` at `time` (positions streamed to `time`; orientations at `time`: a
  // synchronised state, or bodies behind are streamed on a copy). Throws std::invalid_argument,
  // changing nothing, if the box differs from the constructor's or a species id is unknown.
  void sample(double time, const State& state, const Box& box);
  void reset();

  const std::vector<ProfileAxis>& axes() const { return axes_; }
  // The profile along axis name 'x', 'y', 'z' or 'r'; throws std::invalid_argument if absent.
  std::size_t axis_index(char name) const;
  std::size_t species() const { return species_.size(); }
  int samples() const { return samples_; }
  bool has_order() const;  // some species is not a sphere
  // Raw centre counts summed over samples (species a, or all species with a = -1) and densities.
  std::vector<double> counts(std::size_t axis, int species = -1) const;
  std::vector<double> density(std::size_t axis, int species = -1) const;
  // Order profile of the non-sphere bodies: counts, s2, p2_normal per bin (NaN where empty).
  std::vector<double> order_counts(std::size_t axis) const;
  std::vector<double> s2(std::size_t axis) const;
  std::vector<double> p2_normal(std::size_t axis) const;

  // density_profile.tsv: '#' comment lines (samples, per axis bins, width, area or radius),
  // header `axis position density density_<A> ...`, one block of rows per axis.
  std::string to_tsv() const;
  // order_profile.tsv (write only when has_order()): header `axis position count s2 p2_normal`.
  std::string order_tsv() const;

  // Flat serialisation for checkpoints; load() throws std::invalid_argument on a record whose
  // layout (axes, bins, species) differs from this object's.
  std::vector<double> save() const;
  void load(const std::vector<double>& record);

 private:
  static constexpr std::size_t kOrder = 8;  // per bin: count, uu xx xy xz yy yz zz, sum P2
  std::vector<ProfileSpecies> species_;
  Vec3 L_;
  std::vector<ProfileAxis> axes_;
  std::vector<std::vector<double>> counts_;  // per axis: bins x species (row-major by bin)
  std::vector<std::vector<double>> order_;   // per axis: bins x kOrder
  int samples_ = 0;
};

// The contact theorem (hard spheres at a hard wall). In equilibrium the velocities are
// Maxwellian at every position, independent of the configuration: each component v_n has density
// f(v_n) = sqrt(m / (2 pi kT)) exp(-m v_n^2 / (2 kT)). A smooth sphere meets a planar wall when
// its centre reaches the contact distance sigma/2 from it, and the specular reflection
// v_n -> -v_n gives the wall the impulse J = 2 m |v_n| along the normal. The centres that reach
// contact in a time dt per unit wall area are those within |v_n| dt of the contact plane moving
// towards the wall: rho_c |v_n| f(v_n) dv_n dt, with rho_c = rho(sigma/2) the density of centres
// at contact. So the momentum given to the wall per unit area and time is
//   P = int_{v_n < 0} 2 m v_n^2 rho_c f(v_n) dv_n = rho_c m <v_n^2> = rho_c kT,
// i.e. beta P_wall = rho(contact): the wall pressure is the contact value of the density profile
// (for any density; a mixture: the sum over species of their contact densities, each at its own
// sigma_a / 2). The same count at a curved wall: in a spherical container of radius R the
// centres touch at R_c = R - sigma/2, the total force is kT rho(R_c) 4 pi R_c^2, and per unit
// area of the wall (4 pi R^2, the area WallPressure uses) beta P_wall = rho(R_c) (R_c / R)^2.
// For bodies that are not spheres the contact distance depends on the orientation and the wall
// impulse also turns the body: beta P_wall is then the contact density in position and
// orientation, not the centre density at one distance; this helper serves spheres.
//
// Contact value of a density profile by extrapolation. The bins whose inner edge lies at or
// beyond the contact distance from the wall (the first bin entirely on the accessible side)
// are fitted, `bins` of them per wall, by a polynomial of `degree` in the distance from the
// wall, and the fit is evaluated at the contact distance. The profile drops to 0 below contact,
// so the bin holding the contact point (part empty) is never used; the fitted range, bins x
// width, should stay well below the scale on which the profile curves (with the default bin of
// 0.02 sigma, 6 bins span 0.12 sigma). Error: the Poisson noise of the bin counts propagated
// through the (unweighted) fit, which assumes independent snapshots and so is a lower bound when
// successive snapshots are correlated; and the residual error of the fit, which sees any extra
// scatter of the bins but rests on few degrees of freedom. `error` is the larger of the two.
struct ContactFit {
  int bins = 6;    // bins per wall (a slab profile uses both of its walls: 2 x bins points)
  int degree = 2;  // 0 .. 3; needs more points than degree + 1 for a residual error
};
struct ContactValue {
  double density = 0.0;        // extrapolated number density of centres at contact
  double error = 0.0;          // max(poisson_error, residual_error)
  double poisson_error = 0.0;  // the bins' Poisson count noise propagated through the fit
  double residual_error = 0.0; // the formal error of the intercept from the fit residuals
  int points = 0;              // bins fitted
};
// One bin of a profile as the fit sees it: the bin's average of (x - x_c)^j for j = 0..3, with x
// the distance from the wall and x_c the contact distance (the average weighted as the density
// is: uniform across a slab bin, by r^2 across a shell), its density and the variance of it.
struct ContactBin {
  std::array<double, 4> moment{1.0, 0.0, 0.0, 0.0};
  double density = 0.0;
  double variance = 0.0;
};
// Least-squares fit of the bin averages of a polynomial p(x - x_c) to the bins' densities;
// returns p(0). Fitting the bin averages (not values at bin centres) makes the result exact on a
// polynomial profile of at most `degree`, however wide the bins. Throws std::invalid_argument
// with fewer bins than degree + 1 or a degree outside 0..3.
ContactValue fit_contact(const std::vector<ContactBin>& bins, int degree);
// The contact density of profile `axis` ('x', 'y', 'z' or 'r') at distance `contact_distance`
// from the wall(s) (sigma / 2 for spheres of diameter sigma; the container's wall is at R),
// species a or all (-1). Throws std::invalid_argument when the profile is absent, has no samples,
// or has too few bins beyond contact (before the middle of the slab or the container's centre).
ContactValue contact_density(const DensityProfiles& profile, char axis, double contact_distance,
                             int species = -1, const ContactFit& fit = {});

}  // namespace hb
