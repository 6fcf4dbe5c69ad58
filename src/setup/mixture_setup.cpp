#include "setup/mixture_setup.hpp"

#include <cmath>
#include <pcg_random.hpp>
#include <random>
#include <stdexcept>
#include <unordered_map>

namespace hb {

State species_state(const SpeciesTable& species, std::uint64_t seed) {
  State s;
  s.resize(total_count(species));
  pcg64 rng(seed, 0x706f6c7964697370ull);  // stream "polydisp"
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::size_t i = 0;
  for (std::size_t k = 0; k < species.size(); ++k) {
    const Polydispersity& p = species[k].poly;
    for (std::uint64_t c = 0; c < species[k].count; ++c, ++i) {
      s.species[i] = static_cast<std::uint16_t>(k);
      double x = 0.0;
      if (p.distribution == Polydispersity::Distribution::gaussian) {
        do x = gauss(rng); while (std::abs(x) > 3.0);  // truncated at 3 widths
      } else if (p.distribution == Polydispersity::Distribution::uniform) {
        x = std::sqrt(3.0) * uni(rng);  // standard deviation 1
      }
      s.scale[i] = 1.0 + p.width * x;
    }
  }
  return s;
}

double body_volume(const SpeciesTable& species, const State& s) {
  double v = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) v += volume(species[s.species[i]].shape) * std::pow(s.scale[i], 3);
  return v;
}

namespace {
Box cubic_box(double volume) {
  Box b;
  b.L = Vec3::Constant(std::cbrt(volume));
  return b;
}
}  // namespace

std::vector<Vec3> random_sphere_placement(const std::vector<double>& radii, const Box& box,
                                          std::uint64_t seed, double container) {
  pcg64 rng(seed, 0x706c6163656d656eull);  // stream "placemen"
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double rmax = 0.0;
  for (double r : radii) rmax = std::max(rmax, r);
  // cells of side >= 2 rmax: a new sphere can only touch spheres in its own and adjacent cells
  Eigen::Vector3i nc;
  for (int k = 0; k < 3; ++k) nc[k] = std::max(1, int(box.L[k] / (2.0 * rmax)));
  auto cell_of = [&](const Vec3& r) {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k) c[k] = std::min(nc[k] - 1, int(r[k] / box.L[k] * nc[k]));
    return c;
  };
  auto key = [&](const Eigen::Vector3i& c) {
    return (std::int64_t(c.x()) * nc.y() + c.y()) * nc.z() + c.z();
  };
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells;
  std::vector<Vec3> pos;
  pos.reserve(radii.size());
  for (std::size_t i = 0; i < radii.size(); ++i) {
    bool placed = false;
    for (int attempt = 0; attempt < 10000 && !placed; ++attempt) {
      Vec3 r(u(rng) * box.L.x(), u(rng) * box.L.y(), u(rng) * box.L.z());
      if (container > 0.0) {  // inside the container (a candidate outside it is a failed attempt)
        if ((r - box.centre()).norm() > container - radii[i] * 1.001 - 1e-5) continue;
      } else {
        for (int k = 0; k < 3; ++k)  // clear of the walls of an axis that is not periodic
          if (!box.periodic[k]) {
            const double lo = radii[i] * 1.001 + 1e-5;
            r[k] = lo + (r[k] / box.L[k]) * (box.L[k] - 2.0 * lo);
          }
      }
      const Eigen::Vector3i c = cell_of(r);
      bool free = true;
      for (int dx = -1; dx <= 1 && free; ++dx)
        for (int dy = -1; dy <= 1 && free; ++dy)
          for (int dz = -1; dz <= 1 && free; ++dz) {
            Eigen::Vector3i d(c.x() + dx, c.y() + dy, c.z() + dz);
            for (int k = 0; k < 3; ++k) d[k] = (d[k] + nc[k]) % nc[k];
            const auto it = cells.find(key(d));
            if (it == cells.end()) continue;
            for (std::uint32_t j : it->second)
              if (box.minimum_image(pos[j] - r).norm() < radii[i] + radii[j]) {
                free = false;
                break;
              }
          }
      if (free) {
        cells[key(c)].push_back(static_cast<std::uint32_t>(i));
        pos.push_back(r);
        placed = true;
      }
    }
    if (!placed)
      throw std::invalid_argument("random placement: no room for body " + std::to_string(i) +
                                  " (the dilute packing fraction init.phi0 is too high)");
  }
  return pos;
}

void maxwell_boltzmann(State& s, double kT, const std::vector<double>& masses, std::uint64_t seed) {
  pcg64 rng(seed, 0x68617264626f6479ull);  // stream "hardbody"
  std::normal_distribution<double> gauss(0.0, 1.0);
  const std::size_t n = s.size();
  Vec3 p = Vec3::Zero();
  double mtot = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    s.v[i] = std::sqrt(kT / masses[i]) * Vec3(gauss(rng), gauss(rng), gauss(rng));
    p += masses[i] * s.v[i];
    mtot += masses[i];
  }
  const Vec3 vcm = p / mtot;
  double k = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    s.v[i] -= vcm;
    k += 0.5 * masses[i] * s.v[i].squaredNorm();
  }
  if (k > 0.0) {
    const double f = std::sqrt(1.5 * double(n) * kT / k);
    for (auto& v : s.v) v *= f;
  }
}

// The volume that defines phi in a growth: the container's, or the box's.
static double growth_volume(const Box& box, const GrowthOptions& opt) {
  return opt.container > 0.0 ? 4.0 / 3.0 * kPi * opt.container * opt.container * opt.container : box.volume();
}

GrowthResult grow_sphere_mixture(const SpeciesTable& species, double phi, std::uint64_t seed,
                                 const GrowthOptions& opt) {
  if (!(opt.phi0 > 0.0) || opt.phi0 > phi) throw std::invalid_argument("grow_sphere_mixture: need 0 < phi0 <= phi");
  State st = species_state(species, seed);
  const Box box = opt.box ? *opt.box : cubic_box(body_volume(species, st) / phi);
  const double s0 = std::cbrt(opt.phi0 / phi);
  HardSphereMixture model = HardSphereMixture::of(species, GrowthLaw{s0, opt.rate, 0.0, (1.0 - s0) / opt.rate});
  std::vector<double> radii(st.size()), masses(st.size());
  for (std::size_t i = 0; i < st.size(); ++i) {
    radii[i] = model.body_radius(st, i) * s0;
    masses[i] = model.body_mass(st, i);
  }
  st.r = random_sphere_placement(radii, box, seed, opt.container);
  maxwell_boltzmann(st, opt.kT, masses, seed);
  auto thermostat = [&](State& x) {
    const double k = model.kinetic_energy(x);
    const double f = std::sqrt(1.5 * double(x.size()) * opt.kT / k);
    for (auto& v : x.v) v *= f;
    return k - model.kinetic_energy(x);
  };
  GrowthOptions o = opt;
  o.phi_target = phi;
  GrowthResult res = s0 < 1.0 ? run_growth(model, std::move(st), box, o, thermostat) : GrowthResult{};
  if (s0 >= 1.0) res.state = std::move(st), res.box = box, res.s0 = 1.0;
  res.phi = body_volume(species, res.state) / growth_volume(box, opt);
  return res;
}

void maxwell_boltzmann_spin(State& s, double kT, const std::vector<Vec3>& inertia, std::uint64_t seed) {
  pcg64 rng(seed, 0x7370696e73706e31ull);  // the stream of the one-species spins
  std::normal_distribution<double> gauss(0.0, 1.0);
  double k = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3& I = inertia[i];
    const Vec3 W(std::sqrt(kT / I[0]) * gauss(rng), std::sqrt(kT / I[1]) * gauss(rng),
                 std::sqrt(kT / I[2]) * gauss(rng));  // body frame
    s.w[i] = s.q[i] * W;
    k += 0.5 * W.dot(I.cwiseProduct(W));
  }
  if (k > 0.0) {
    const double f = std::sqrt(1.5 * double(s.size()) * kT / k);
    for (auto& w : s.w) w *= f;
  }
}

void random_orientations(State& s, std::uint64_t seed) {
  pcg64 rng(seed, 0x6f7269656e747331ull);  // stream "orients1"
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (auto& q : s.q) {  // a normalised 4-d Gaussian is uniform on the rotations
    Quat x;
    do x = Quat(gauss(rng), gauss(rng), gauss(rng), gauss(rng)); while (!(x.norm() > 1e-3));
    q = x.normalized();
  }
}

double rescale_to_temperature(State& s, const RigidMixture& model, double kT) {
  return thermalize_per_dof(
      s, kT, [&](std::size_t i) { return model.body_mass(s, i).mass; },
      [&](std::size_t i) { return Vec3(model.body_mass(s, i).inertia_body.diagonal()); });
}

GrowthResult grow_rigid_mixture(const SpeciesTable& species, double phi, std::uint64_t seed,
                                const GrowthOptions& opt, double eps_d) {
  if (!(opt.phi0 > 0.0) || opt.phi0 > phi) throw std::invalid_argument("grow_rigid_mixture: need 0 < phi0 <= phi");
  State st = species_state(species, seed);
  const Box box = opt.box ? *opt.box : cubic_box(body_volume(species, st) / phi);
  double v_bounding = 0.0;  // bounding-sphere volume at scale 1
  for (std::size_t i = 0; i < st.size(); ++i)
    v_bounding += 4.18879020478639 * std::pow(bounding_radius(species[st.species[i]].shape) * st.scale[i], 3);
  const double s0 = std::min(std::cbrt(opt.phi0 / phi), std::cbrt(0.25 * growth_volume(box, opt) / v_bounding));
  const double t_stop = (1.0 - s0) / opt.rate;
  RigidMixture model = RigidMixture::of(species, eps_d, GrowthLaw{s0, opt.rate, 0.0, t_stop});
  std::vector<double> radii(st.size()), masses(st.size());
  std::vector<Vec3> inertia(st.size());
  for (std::size_t i = 0; i < st.size(); ++i) {
    radii[i] = bounding_radius(species[st.species[i]].shape) * st.scale[i] * s0;
    const MassProperties m = model.body_mass(st, i);
    masses[i] = m.mass;
    inertia[i] = m.inertia_body.diagonal();
  }
  st.r = random_sphere_placement(radii, box, seed, opt.container);
  random_orientations(st, seed);
  maxwell_boltzmann(st, opt.kT, masses, seed);
  maxwell_boltzmann_spin(st, opt.kT, inertia, seed);
  GrowthResult res;
  if (s0 < 1.0) {
    GrowthOptions o = opt;
    o.phi_target = phi;
    res = run_growth(model, std::move(st), box, o,
                     [&](State& x) { return rescale_to_temperature(x, model, opt.kT); });
  } else {
    res.state = std::move(st), res.box = box, res.s0 = 1.0;
  }
  res.s0 = s0;
  res.phi = body_volume(species, res.state) / growth_volume(box, opt);
  return res;
}

}  // namespace hb
