#include "observers/wall_observables.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <variant>

namespace hb {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMaxBins = 10'000'000;

bool same_length(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }

void append_numbers(std::string& out, const std::vector<double>& xs) {
  char buf[32];
  for (double x : xs) {
    std::snprintf(buf, sizeof buf, "\t%.10g", x);
    out += buf;
  }
  out += '\n';
}

}  // namespace

double wall_area(const WallSpec& walls, const Box& box) {
  double a = 0.0;
  for (int k = 0; k < 3; ++k)
    if (walls.planes[std::size_t(k)]) a += 2.0 * box.L[(k + 1) % 3] * box.L[(k + 2) % 3];
  if (walls.container()) a += 4.0 * kPi * walls.sphere_radius * walls.sphere_radius;
  return a;
}

// ---------------------------------------------------------------------------------------------
// WallPressure

WallPressure::WallPressure(double area) : area_(area) {
  if (!(area > 0.0) || !std::isfinite(area)) throw std::invalid_argument("WallPressure: the wall area must be > 0");
}

void WallPressure::add(double time, double J) {
  if (!(J >= 0.0) || !std::isfinite(J))
    throw std::invalid_argument("WallPressure: a wall impulse must be finite and >= 0, got " + std::to_string(J));
  sum_ += J;
  ++impulses_;
  last_time_ = time;
}

void WallPressure::close_block(double dt, double kT) {
  if (dt <= 0.0) return;
  last_ = sum_ / (area_ * dt * kT);
  blocks_.push_back(last_);
  total_sum_ += sum_;
  total_time_ += dt;
  total_kT_time_ += kT * dt;
  total_impulses_ += impulses_;
  sum_ = 0.0;
  impulses_ = 0;
}

void WallPressure::reset() {
  sum_ = total_sum_ = total_time_ = total_kT_time_ = last_ = last_time_ = 0.0;
  impulses_ = total_impulses_ = 0;
  blocks_.clear();
}

MeanError WallPressure::pressure() const {
  MeanError m = block_average(blocks_);
  if (total_kT_time_ > 0.0) m.mean = total_sum_ / (area_ * total_kT_time_);
  return m;
}

// Record: area, open-block sum, closed sum, time, kT time, open-block impulses, closed impulses,
// last block value, last impulse time, block count, the blocks.
std::vector<double> WallPressure::save() const {
  std::vector<double> d{area_, sum_, total_sum_, total_time_, total_kT_time_, double(impulses_),
                        double(total_impulses_), last_, last_time_, double(blocks_.size())};
  d.insert(d.end(), blocks_.begin(), blocks_.end());
  return d;
}

void WallPressure::load(const std::vector<double>& d) {
  if (d.size() < 10 || d.size() != 10 + std::size_t(d[9]))
    throw std::invalid_argument("wall pressure record has the wrong length");
  if (!same_length(d[0], area_))
    throw std::invalid_argument("wall pressure record is of a wall area " + std::to_string(d[0]) +
                                ", this run's is " + std::to_string(area_));
  sum_ = d[1], total_sum_ = d[2], total_time_ = d[3], total_kT_time_ = d[4];
  impulses_ = std::uint64_t(d[5]), total_impulses_ = std::uint64_t(d[6]);
  last_ = d[7], last_time_ = d[8];
  blocks_.assign(d.begin() + 10, d.end());
}

// ---------------------------------------------------------------------------------------------
// DensityProfiles

std::vector<ProfileSpecies> profile_species(const SpeciesTable& species) {
  std::vector<ProfileSpecies> out;
  for (const Species& sp : species) {
    ProfileSpecies p;
    p.name = sp.name;
    p.sphere = std::holds_alternative<Sphere>(sp.shape);
    half_extents(sp.shape).maxCoeff(&p.long_axis);  // the first of equal maxima
    out.push_back(p);
  }
  return out;
}

double default_profile_bin(const SpeciesTable& species) {
  double d = kInf;
  for (const Species& sp : species) d = std::min(d, 2.0 * bounding_radius(sp.shape));
  return 0.02 * d;
}

double ProfileAxis::volume(std::size_t bin) const {
  if (!radial()) return width * area;
  const double r0 = double(bin) * width, r1 = double(bin + 1) * width;
  return 4.0 / 3.0 * kPi * (r1 * r1 * r1 - r0 * r0 * r0);
}

double ProfileAxis::position(std::size_t bin) const {
  const double mid = (double(bin) + 0.5) * width;
  return radial() ? mid : mid - 0.5 * extent;
}

DensityProfiles::DensityProfiles(const WallSpec& walls, const Box& box, std::vector<ProfileSpecies> species,
                                 double bin)
    : species_(std::move(species)), L_(box.L) {
  if (!walls.any()) throw std::invalid_argument("DensityProfiles: no walls");
  if (!(bin > 0.0) || !std::isfinite(bin)) throw std::invalid_argument("DensityProfiles: the bin width must be > 0");
  if (species_.empty()) throw std::invalid_argument("DensityProfiles: no species");
  for (const auto& s : species_)
    if (s.long_axis < 0 || s.long_axis > 2) throw std::invalid_argument("DensityProfiles: long_axis must be 0, 1 or 2");
  auto add_axis = [&](int k, double extent, double area) {
    const double n = std::ceil(extent / bin * (1.0 - 1e-12));  // L = 10, bin = 0.1: 100 bins, not 101
    if (!(n <= double(kMaxBins)))
      throw std::invalid_argument("DensityProfiles: " + std::to_string(n) + " bins along one axis (at most 1e7)");
    ProfileAxis a;
    a.k = k;
    a.extent = extent;
    a.bins = std::max<std::size_t>(1, std::size_t(n));
    a.width = extent / double(a.bins);
    a.area = area;
    axes_.push_back(a);
  };
  for (int k = 0; k < 3; ++k)
    if (walls.planes[std::size_t(k)]) add_axis(k, box.L[k], box.L[(k + 1) % 3] * box.L[(k + 2) % 3]);
  if (walls.container()) add_axis(3, walls.sphere_radius, 0.0);
  reset();
}

void DensityProfiles::reset() {
  samples_ = 0;
  counts_.clear();
  order_.clear();
  for (const auto& a : axes_) {
    counts_.emplace_back(a.bins * species_.size(), 0.0);
    order_.emplace_back(a.bins * kOrder, 0.0);
  }
}

std::size_t DensityProfiles::axis_index(char name) const {
  for (std::size_t p = 0; p < axes_.size(); ++p)
    if (axes_[p].name() == name) return p;
  throw std::invalid_argument(std::string("density profile: no profile along '") + name + "'");
}

bool DensityProfiles::has_order() const {
  return std::any_of(species_.begin(), species_.end(), [](const ProfileSpecies& s) { return !s.sphere; });
}

void DensityProfiles::sample(double time, const State& state, const Box& box) {
  for (int k = 0; k < 3; ++k)
    if (!same_length(box.L[k], L_[k]))
      throw std::invalid_argument("DensityProfiles: the box changed since the profiles were set up");
  const std::size_t ns = species_.size();
  for (std::size_t i = 0; i < state.size(); ++i)
    if (state.species[i] >= ns)
      throw std::invalid_argument("DensityProfiles: body " + std::to_string(i) + " has an unknown species");
  const Vec3 centre = 0.5 * L_;
  for (std::size_t i = 0; i < state.size(); ++i) {
    const Vec3 r = state.position_at(i, time);
    const ProfileSpecies& sp = species_[state.species[i]];
    Vec3 u = Vec3::Zero();
    if (!sp.sphere) {
      const Quat q = state.t[i] == time ? state.q[i] : state.body_at(i, time).q;
      u = q * Vec3::Unit(sp.long_axis);
    }
    for (std::size_t p = 0; p < axes_.size(); ++p) {
      const ProfileAxis& a = axes_[p];
      Vec3 n = Vec3::UnitZ();
      double x;
      if (a.radial()) {
        const Vec3 d = r - centre;
        x = d.norm();
        if (x > 0.0) n = d / x;
      } else {
        x = r[a.k];
        n = Vec3::Unit(a.k);
      }
      const std::size_t b = std::size_t(std::clamp(std::floor(x / a.width), 0.0, double(a.bins - 1)));
      counts_[p][b * ns + state.species[i]] += 1.0;
      if (sp.sphere) continue;
      double* o = &order_[p][b * kOrder];
      const double c = u.dot(n);
      o[0] += 1.0;
      o[1] += u.x() * u.x(), o[2] += u.x() * u.y(), o[3] += u.x() * u.z();
      o[4] += u.y() * u.y(), o[5] += u.y() * u.z(), o[6] += u.z() * u.z();
      o[7] += 1.5 * c * c - 0.5;
    }
  }
  ++samples_;
}

std::vector<double> DensityProfiles::counts(std::size_t axis, int species) const {
  const ProfileAxis& a = axes_.at(axis);
  const std::size_t ns = species_.size();
  if (species >= int(ns)) throw std::invalid_argument("density profile: no species " + std::to_string(species));
  std::vector<double> c(a.bins, 0.0);
  for (std::size_t b = 0; b < a.bins; ++b)
    for (std::size_t s = 0; s < ns; ++s)
      if (species < 0 || std::size_t(species) == s) c[b] += counts_[axis][b * ns + s];
  return c;
}

std::vector<double> DensityProfiles::density(std::size_t axis, int species) const {
  std::vector<double> rho = counts(axis, species);
  const ProfileAxis& a = axes_[axis];
  for (std::size_t b = 0; b < a.bins; ++b) rho[b] = samples_ > 0 ? rho[b] / (a.volume(b) * samples_) : 0.0;
  return rho;
}

std::vector<double> DensityProfiles::order_counts(std::size_t axis) const {
  std::vector<double> c(axes_.at(axis).bins);
  for (std::size_t b = 0; b < c.size(); ++b) c[b] = order_[axis][b * kOrder];
  return c;
}

std::vector<double> DensityProfiles::s2(std::size_t axis) const {
  std::vector<double> s(axes_.at(axis).bins, kNaN);
  for (std::size_t b = 0; b < s.size(); ++b) {
    const double* o = &order_[axis][b * kOrder];
    if (o[0] == 0.0) continue;
    Mat3 uu;
    uu << o[1], o[2], o[3], o[2], o[4], o[5], o[3], o[5], o[6];
    const Mat3 Q = 1.5 * uu / o[0] - 0.5 * Mat3::Identity();
    s[b] = Eigen::SelfAdjointEigenSolver<Mat3>(Q, Eigen::EigenvaluesOnly).eigenvalues()[2];
  }
  return s;
}

std::vector<double> DensityProfiles::p2_normal(std::size_t axis) const {
  std::vector<double> p(axes_.at(axis).bins, kNaN);
  for (std::size_t b = 0; b < p.size(); ++b) {
    const double* o = &order_[axis][b * kOrder];
    if (o[0] > 0.0) p[b] = o[7] / o[0];
  }
  return p;
}

std::string DensityProfiles::to_tsv() const {
  std::string out = "# hardbody density profiles\n";
  char buf[256];
  std::snprintf(buf, sizeof buf, "# samples=%d species=%zu\n", samples_, species_.size());
  out += buf;
  for (const auto& a : axes_) {
    if (a.radial())
      std::snprintf(buf, sizeof buf, "# bins_r=%zu width_r=%.10g radius=%.10g\n", a.bins, a.width, a.extent);
    else
      std::snprintf(buf, sizeof buf, "# bins_%c=%zu width_%c=%.10g length_%c=%.10g area_%c=%.10g\n", a.name(), a.bins,
                    a.name(), a.width, a.name(), a.extent, a.name(), a.area);
    out += buf;
  }
  out += "axis\tposition\tdensity";
  for (const auto& s : species_) out += "\tdensity_" + s.name;
  out += '\n';
  for (std::size_t p = 0; p < axes_.size(); ++p) {
    const ProfileAxis& a = axes_[p];
    std::vector<std::vector<double>> rho{density(p)};
    for (std::size_t s = 0; s < species_.size(); ++s) rho.push_back(density(p, int(s)));
    for (std::size_t b = 0; b < a.bins; ++b) {
      out += a.name();
      std::vector<double> row{a.position(b)};
      for (const auto& r : rho) row.push_back(r[b]);
      append_numbers(out, row);
    }
  }
  return out;
}

std::string DensityProfiles::order_tsv() const {
  std::string out = "# hardbody order profiles (bodies that are not spheres; u = the long body axis)\n";
  char buf[64];
  std::snprintf(buf, sizeof buf, "# samples=%d\n", samples_);
  out += buf;
  out += "axis\tposition\tcount\ts2\tp2_normal\n";
  for (std::size_t p = 0; p < axes_.size(); ++p) {
    const ProfileAxis& a = axes_[p];
    const auto c = order_counts(p), s = s2(p), pn = p2_normal(p);
    for (std::size_t b = 0; b < a.bins; ++b) {
      out += a.name();
      append_numbers(out, {a.position(b), c[b], s[b], pn[b]});
    }
  }
  return out;
}

// Record: version 1, samples, species, axes, then per axis (k, bins), then per axis its counts
// (bins x species) and its order sums (bins x 8).
std::vector<double> DensityProfiles::save() const {
  std::vector<double> d{1.0, double(samples_), double(species_.size()), double(axes_.size())};
  for (const auto& a : axes_) d.insert(d.end(), {double(a.k), double(a.bins)});
  for (std::size_t p = 0; p < axes_.size(); ++p) {
    d.insert(d.end(), counts_[p].begin(), counts_[p].end());
    d.insert(d.end(), order_[p].begin(), order_[p].end());
  }
  return d;
}

void DensityProfiles::load(const std::vector<double>& d) {
  const std::size_t ns = species_.size(), na = axes_.size();
  bool ok = d.size() >= 4 + 2 * na && d[0] == 1.0 && d[2] == double(ns) && d[3] == double(na);
  std::size_t size = 4 + 2 * na;
  for (std::size_t p = 0; ok && p < na; ++p) {
    ok = d[4 + 2 * p] == double(axes_[p].k) && d[5 + 2 * p] == double(axes_[p].bins);
    size += axes_[p].bins * (ns + kOrder);
  }
  if (!ok || d.size() != size)
    throw std::invalid_argument("density profile record: wrong length, or other axes, bins or species");
  samples_ = int(d[1]);
  auto at = d.begin() + std::ptrdiff_t(4 + 2 * na);
  for (std::size_t p = 0; p < na; ++p) {
    std::copy(at, at + std::ptrdiff_t(counts_[p].size()), counts_[p].begin());
    at += std::ptrdiff_t(counts_[p].size());
    std::copy(at, at + std::ptrdiff_t(order_[p].size()), order_[p].begin());
    at += std::ptrdiff_t(order_[p].size());
  }
}

// ---------------------------------------------------------------------------------------------
// Contact values

ContactValue fit_contact(const std::vector<ContactBin>& bins, int degree) {
  if (degree < 0 || degree > 3) throw std::invalid_argument("fit_contact: degree must be 0 .. 3");
  const int n = int(bins.size()), m = degree + 1;
  if (n < m)
    throw std::invalid_argument("fit_contact: " + std::to_string(n) + " bins for a polynomial of degree " +
                                std::to_string(degree));
  // Columns scaled by s^j (s: the largest |<x - x_c>|) to keep X^T X well conditioned; the
  // intercept (column 0) is unchanged by the scaling.
  double s = 0.0;
  for (const auto& b : bins) s = std::max(s, std::abs(b.moment[1]));
  if (s == 0.0) s = 1.0;
  Eigen::MatrixXd X(n, m);
  Eigen::VectorXd y(n), var(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) X(i, j) = bins[std::size_t(i)].moment[std::size_t(j)] / std::pow(s, j);
    y[i] = bins[std::size_t(i)].density;
    var[i] = bins[std::size_t(i)].variance;
  }
  const Eigen::MatrixXd M = (X.transpose() * X).inverse();  // at most 4 x 4
  const Eigen::VectorXd w = X * M.col(0);                    // intercept = w . y
  const Eigen::VectorXd coef = M * (X.transpose() * y);
  ContactValue c;
  c.points = n;
  c.density = w.dot(y);
  c.poisson_error = std::sqrt(w.cwiseProduct(w).dot(var));
  if (n > m) {
    const double rss = (y - X * coef).squaredNorm();
    c.residual_error = std::sqrt(rss / double(n - m) * M(0, 0));
  }
  c.error = std::max(c.poisson_error, c.residual_error);
  return c;
}

ContactValue contact_density(const DensityProfiles& profile, char axis, double x_c, int species,
                             const ContactFit& fit) {
  const std::size_t p = profile.axis_index(axis);
  const ProfileAxis& a = profile.axes()[p];
  if (profile.samples() == 0) throw std::invalid_argument("contact_density: the profile has no samples");
  if (fit.bins < 1) throw std::invalid_argument("contact_density: fit.bins must be >= 1");
  const auto count = profile.counts(p, species);
  const double eps = 1e-9 * a.width;
  std::vector<ContactBin> bins;
  // A bin spanning distances [d0, d1] from a wall (d1 <= the middle of a slab), if it lies wholly
  // beyond contact.
  auto take = [&](std::size_t b, double d0, double d1) {
    ContactBin cb;
    const double norm = a.volume(b) * profile.samples();
    cb.density = count[b] / norm;
    cb.variance = count[b] / (norm * norm);  // Poisson count
    if (!a.radial()) {
      // uniform across the slab: <(x - x_c)^j> = [t^(j+1)] / ((j + 1)(d1 - d0)), t = x - x_c
      for (int j = 0; j < 4; ++j)
        cb.moment[std::size_t(j)] = (std::pow(d1 - x_c, j + 1) - std::pow(d0 - x_c, j + 1)) / ((j + 1) * (d1 - d0));
    } else {
      // weight r^2 across the shell, x = R - r: 3-point Gauss-Legendre, exact to degree 5
      const double r0 = a.extent - d1, r1 = a.extent - d0, mid = 0.5 * (r0 + r1), half = 0.5 * (r1 - r0);
      const double node[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, weight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
      double wsum = 0.0;
      std::array<double, 4> mom{};
      for (int g = 0; g < 3; ++g) {
        const double r = mid + half * node[g], wr = weight[g] * r * r, t = a.extent - r - x_c;
        wsum += wr;
        for (int j = 0; j < 4; ++j) mom[std::size_t(j)] += wr * std::pow(t, j);
      }
      for (int j = 0; j < 4; ++j) cb.moment[std::size_t(j)] = mom[std::size_t(j)] / wsum;
    }
    bins.push_back(cb);
  };
  // Per wall: the first fit.bins bins whose inner edge is at or beyond the contact distance.
  const double limit = a.radial() ? a.extent : 0.5 * a.extent;
  for (int wall = 0; wall < (a.radial() ? 1 : 2); ++wall) {
    int taken = 0;
    for (std::size_t step = 0; step < a.bins && taken < fit.bins; ++step) {
      // wall 0 of a slab: bins from 0 up; wall 1: from L down; radial: shells from R in.
      const bool from_top = a.radial() || wall == 1;
      const std::size_t b = from_top ? a.bins - 1 - step : step;
      const double lo = double(b) * a.width, hi = double(b + 1) * a.width;
      const double d0 = from_top ? a.extent - hi : lo, d1 = from_top ? a.extent - lo : hi;
      if (d0 < x_c - eps) continue;
      if (d1 > limit + eps) break;
      take(b, std::max(d0, 0.0), d1);
      ++taken;
    }
    if (taken < fit.bins)
      throw std::invalid_argument("contact_density: only " + std::to_string(taken) + " of " +
                                  std::to_string(fit.bins) + " bins between contact and the middle along '" + axis + "'");
  }
  return fit_contact(bins, fit.degree);
}

}  // namespace hb
