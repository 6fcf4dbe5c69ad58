#include "observers/structure.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace hb {

namespace {

// Add the pair (lo, hi), lo < hi, to the histogram. Both pair searches go through here with the
// same operand order, so they produce bit-identical bins.
inline void add_pair(const std::vector<Vec3>& p, std::size_t lo, std::size_t hi, const Box& box,
                     double r_max2, double inv_dr, std::vector<std::uint64_t>& hist) {
  const Vec3 d = box.near_image(p[hi] - p[lo]);
  const double d2 = d.squaredNorm();
  if (d2 >= r_max2) return;
  const auto k = static_cast<std::size_t>(std::sqrt(d2) * inv_dr);
  ++hist[std::min(k, hist.size() - 1)];
}

void check_range(const Box& box, double r_max) {
  if (!(r_max > 0.0) || r_max > 0.5 * box.L.minCoeff() * (1.0 + 1e-12))
    throw std::invalid_argument("g(r): r_max = " + std::to_string(r_max) +
                                " must be in (0, min(L)/2 = " + std::to_string(0.5 * box.L.minCoeff()) + "]");
}

void append_row(std::string& out, const std::vector<double>& xs) {
  char buf[48];
  for (std::size_t k = 0; k < xs.size(); ++k) {
    std::snprintf(buf, sizeof buf, k == 0 ? "%.10g" : "\t%.10g", xs[k]);
    out += buf;
  }
}
void append_row(std::string& out, std::initializer_list<double> xs) {
  char buf[48];
  bool first = true;
  for (double x : xs) {
    std::snprintf(buf, sizeof buf, first ? "%.10g" : "\t%.10g", x);
    out += buf;
    first = false;
  }
}

}  // namespace

void pair_histogram_brute(const std::vector<Vec3>& p, const Box& box, double r_max,
                          std::vector<std::uint64_t>& hist) {
  check_range(box, r_max);
  const double r_max2 = r_max * r_max, inv_dr = double(hist.size()) / r_max;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) add_pair(p, i, j, box, r_max2, inv_dr, hist);
}

void pair_histogram_cells(const std::vector<Vec3>& p, const Box& box, double r_max,
                          std::vector<std::uint64_t>& hist) {
  check_range(box, r_max);
  std::array<int, 3> nc{};
  for (int k = 0; k < 3; ++k) nc[k] = static_cast<int>(std::floor(box.L[k] / r_max));
  // With fewer than 3 cells on an edge the neighbour cells are not distinct.
  if (*std::min_element(nc.begin(), nc.end()) < 3) return pair_histogram_brute(p, box, r_max, hist);
  for (int k = 0; k < 3; ++k) nc[k] = std::min(nc[k], 1024);  // keeps the cell count bounded
  const std::size_t ncell = std::size_t(nc[0]) * nc[1] * nc[2];

  // Counting sort of the bodies by cell.
  auto cell_of = [&](const Vec3& x) {
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(x[k] / box.L[k] * nc[k]), 0, nc[k] - 1);
    return (std::size_t(c[2]) * nc[1] + c[1]) * nc[0] + c[0];
  };
  std::vector<std::size_t> start(ncell + 1, 0), order(p.size()), cell(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) ++start[(cell[i] = cell_of(p[i])) + 1];
  for (std::size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < p.size(); ++i) order[fill[cell[i]]++] = i;
  }

  const double r_max2 = r_max * r_max, inv_dr = double(hist.size()) / r_max;
  // Half shell: the 13 offsets lexicographically after (0,0,0), plus pairs within a cell.
  std::vector<std::array<int, 3>> half;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dz > 0 || (dz == 0 && (dy > 0 || (dy == 0 && dx > 0)))) half.push_back({dx, dy, dz});

  for (int cz = 0; cz < nc[2]; ++cz)
    for (int cy = 0; cy < nc[1]; ++cy)
      for (int cx = 0; cx < nc[0]; ++cx) {
        const std::size_t a = (std::size_t(cz) * nc[1] + cy) * nc[0] + cx;
        for (std::size_t s = start[a]; s < start[a + 1]; ++s)
          for (std::size_t t = s + 1; t < start[a + 1]; ++t) {
            const auto [lo, hi] = std::minmax(order[s], order[t]);
            add_pair(p, lo, hi, box, r_max2, inv_dr, hist);
          }
        for (const auto& o : half) {
          const int bx = (cx + o[0] + nc[0]) % nc[0], by = (cy + o[1] + nc[1]) % nc[1],
                    bz = (cz + o[2] + nc[2]) % nc[2];
          const std::size_t b = (std::size_t(bz) * nc[1] + by) * nc[0] + bx;
          for (std::size_t s = start[a]; s < start[a + 1]; ++s)
            for (std::size_t t = start[b]; t < start[b + 1]; ++t) {
              const auto [lo, hi] = std::minmax(order[s], order[t]);
              add_pair(p, lo, hi, box, r_max2, inv_dr, hist);
            }
        }
      }
}

RadialDistribution::RadialDistribution(const RdfSpec& spec) : spec_(spec) {
  if (spec.bins < 1) throw std::invalid_argument("RdfSpec: bins must be >= 1");
  if (!(spec.r_max >= 0.0) || !std::isfinite(spec.r_max))
    throw std::invalid_argument("RdfSpec: r_max must be >= 0 (0: half the shortest box edge)");
  reset();
}

void RadialDistribution::reset() {
  r_max_ = spec_.r_max;
  samples_ = 0;
  last_n_ = 0;
  sum_pair_density_ = sum_n_ = 0.0;
  hist_.assign(static_cast<std::size_t>(spec_.bins), 0);
}

void RadialDistribution::sample(double time, const State& state, const Box& box) {
  if (r_max_ == 0.0) r_max_ = 0.5 * box.L.minCoeff();
  const std::size_t n = state.size();
  pos_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    pos_[i] = state.position_at(i, time);
    box.wrap(pos_[i]);
  }
  const bool cells = spec_.method == RdfSpec::Method::cells ||
                     (spec_.method == RdfSpec::Method::automatic && n > spec_.cells_above);
  if (cells) pair_histogram_cells(pos_, box, r_max_, hist_);
  else pair_histogram_brute(pos_, box, r_max_, hist_);
  ++samples_;
  last_n_ = n;
  sum_n_ += double(n);
  sum_pair_density_ += 0.5 * double(n) * (double(n) - 1.0) / box.volume();
}

std::vector<double> RadialDistribution::save() const {
  std::vector<double> d{r_max_, double(samples_), double(last_n_), sum_pair_density_, sum_n_,
                        double(hist_.size())};
  for (auto h : hist_) d.push_back(double(h));
  return d;
}

void RadialDistribution::load(const std::vector<double>& d) {
  if (d.size() < 6 || d[5] != double(hist_.size()) || d.size() != 6 + hist_.size())
    throw std::invalid_argument("g(r) record: wrong length or bin count");
  r_max_ = d[0];
  samples_ = int(d[1]);
  last_n_ = std::size_t(d[2]);
  sum_pair_density_ = d[3];
  sum_n_ = d[4];
  for (std::size_t k = 0; k < hist_.size(); ++k) hist_[k] = std::uint64_t(d[6 + k]);
}

std::vector<double> RadialDistribution::r() const {
  std::vector<double> r(hist_.size());
  const double dr = r_max_ / double(hist_.size());
  for (std::size_t k = 0; k < r.size(); ++k) r[k] = (double(k) + 0.5) * dr;
  return r;
}

std::vector<double> RadialDistribution::g() const {
  std::vector<double> g(hist_.size(), 0.0);
  if (sum_pair_density_ <= 0.0) return g;
  const double dr = r_max_ / double(hist_.size());
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double shell = 4.0 / 3.0 * kPi * (std::pow((k + 1) * dr, 3) - std::pow(k * dr, 3));
    g[k] = double(hist_[k]) / (sum_pair_density_ * shell);
  }
  return g;
}

std::vector<double> RadialDistribution::coordination() const {
  std::vector<double> c(hist_.size(), 0.0);
  if (sum_n_ <= 0.0) return c;
  double cum = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    cum += double(hist_[k]);
    c[k] = 2.0 * cum / sum_n_;
  }
  return c;
}

std::string RadialDistribution::to_tsv() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "# hardbody radial distribution function\n# samples=%d N=%zu r_max=%.10g bins=%zu\n",
                samples_, last_n_, r_max_, hist_.size());
  std::string out = buf;
  out += "r\tg\tn_r\tpairs\n";
  const auto r = this->r(), g = this->g(), c = coordination();
  for (std::size_t k = 0; k < r.size(); ++k) {
    append_row(out, {r[k], g[k], c[k]});
    out += '\t' + std::to_string(hist_[k]) + '\n';
  }
  return out;
}

PartialRadialDistribution::PartialRadialDistribution(std::size_t species, int bins)
    : ns_(species), bins_(bins) {
  if (bins < 1) throw std::invalid_argument("PartialRadialDistribution: bins must be >= 1");
  density_.assign(ns_ * (ns_ + 1) / 2, 0.0);
  hist_.assign(density_.size(), std::vector<std::uint64_t>(std::size_t(bins), 0));
}

std::size_t PartialRadialDistribution::pair_index(std::size_t a, std::size_t b) const {
  return species_pair_index(a, b, ns_);
}

void PartialRadialDistribution::sample(double time, const State& state, const Box& box, double r_max) {
  if (samples_ > 0 && r_max != r_max_) throw std::invalid_argument("PartialRadialDistribution: r_max changed");
  r_max_ = r_max;
  std::vector<std::vector<Vec3>> pos(ns_);
  for (std::size_t i = 0; i < state.size(); ++i) {
    Vec3 p = state.position_at(i, time);
    box.wrap(p);
    pos[state.species[i]].push_back(p);
  }
  auto histogram = [&](const std::vector<Vec3>& x) {
    std::vector<std::uint64_t> h(std::size_t(bins_), 0);
    if (x.size() > 20000) pair_histogram_cells(x, box, r_max, h);
    else pair_histogram_brute(x, box, r_max, h);
    return h;
  };
  std::vector<std::vector<std::uint64_t>> own(ns_);
  for (std::size_t a = 0; a < ns_; ++a) own[a] = histogram(pos[a]);
  const double V = box.volume();
  for (std::size_t a = 0; a < ns_; ++a)
    for (std::size_t b = a; b < ns_; ++b) {
      const std::size_t k = pair_index(a, b);
      const double na = double(pos[a].size()), nb = double(pos[b].size());
      if (a == b) {
        for (int i = 0; i < bins_; ++i) hist_[k][i] += own[a][i];
        density_[k] += 0.5 * na * (na - 1.0) / V;
      } else {
        std::vector<Vec3> both = pos[a];
        both.insert(both.end(), pos[b].begin(), pos[b].end());
        const auto h = histogram(both);
        for (int i = 0; i < bins_; ++i) hist_[k][i] += h[i] - own[a][i] - own[b][i];
        density_[k] += na * nb / V;
      }
    }
  ++samples_;
}

std::vector<double> PartialRadialDistribution::g(std::size_t a, std::size_t b) const {
  const std::size_t k = pair_index(a, b);
  std::vector<double> g(std::size_t(bins_), 0.0);
  if (density_[k] <= 0.0) return g;
  const double dr = r_max_ / double(bins_);
  for (int i = 0; i < bins_; ++i) {
    const double shell = 4.0 / 3.0 * kPi * (std::pow((i + 1) * dr, 3) - std::pow(i * dr, 3));
    g[i] = double(hist_[k][i]) / (density_[k] * shell);
  }
  return g;
}

std::vector<double> PartialRadialDistribution::save() const {
  std::vector<double> d{r_max_, double(samples_), double(ns_), double(bins_)};
  d.insert(d.end(), density_.begin(), density_.end());
  for (const auto& h : hist_)
    for (auto x : h) d.push_back(double(x));
  return d;
}

void PartialRadialDistribution::load(const std::vector<double>& d) {
  const std::size_t np = density_.size();
  if (d.size() != 4 + np + np * std::size_t(bins_) || d[2] != double(ns_) || d[3] != double(bins_))
    throw std::invalid_argument("partial g(r) record: wrong length, species or bin count");
  r_max_ = d[0];
  samples_ = int(d[1]);
  for (std::size_t k = 0; k < np; ++k) density_[k] = d[4 + k];
  for (std::size_t k = 0; k < np; ++k)
    for (int i = 0; i < bins_; ++i) hist_[k][i] = std::uint64_t(d[4 + np + k * bins_ + i]);
}

std::string PartialRadialDistribution::to_tsv(const std::vector<std::string>& names) const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "# hardbody partial radial distribution functions g_ab(r)\n# samples=%d r_max=%.10g bins=%d\n",
                samples_, r_max_, bins_);
  std::string out = buf;
  out += "r";
  for (std::size_t a = 0; a < ns_; ++a)
    for (std::size_t b = a; b < ns_; ++b) out += "\tg_" + names.at(a) + "_" + names.at(b);
  out += "\n";
  std::vector<std::vector<double>> gs;
  for (std::size_t a = 0; a < ns_; ++a)
    for (std::size_t b = a; b < ns_; ++b) gs.push_back(g(a, b));
  const double dr = r_max_ / double(bins_);
  for (int i = 0; i < bins_; ++i) {
    std::vector<double> row{(double(i) + 0.5) * dr};
    for (const auto& g : gs) row.push_back(g[i]);
    append_row(out, row);
    out += "\n";
  }
  return out;
}

NematicResult nematic_order(const std::vector<Quat>& orientations, const Vec3& body_axis) {
  NematicResult res;
  if (orientations.empty()) return res;
  const Vec3 a = body_axis.normalized();
  Mat3 Q = Mat3::Zero();
  for (const Quat& q : orientations) {
    const Vec3 u = q * a;
    Q.noalias() += u * u.transpose();
  }
  Q = 1.5 * Q / double(orientations.size()) - 0.5 * Mat3::Identity();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(Q);
  res.eigenvalues = eig.eigenvalues();  // ascending
  res.S2 = res.eigenvalues[2];
  Vec3 n = eig.eigenvectors().col(2).normalized();
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  if (n[k] < 0.0) n = -n;
  res.director = n;
  return res;
}

NematicOrder::NematicOrder(const Vec3& body_axis) : axis_(body_axis) {
  if (!body_axis.allFinite() || body_axis.norm() == 0.0)
    throw std::invalid_argument("NematicOrder: body_axis must be nonzero");
  axis_.normalize();
}

void NematicOrder::reset() {
  times_.clear();
  series_.clear();
}

void NematicOrder::sample(double time, const State& state, const Box& /*box*/) {
  q_.resize(state.size());
  for (std::size_t i = 0; i < state.size(); ++i) {
    const double dt = time - state.t[i];
    q_[i] = dt == 0.0 ? state.q[i] : orientation_at(state.body(i), dt);
  }
  times_.push_back(time);
  series_.push_back(nematic_order(q_, axis_));
}

std::vector<double> NematicOrder::save() const {
  std::vector<double> d;
  d.reserve(8 * times_.size());
  for (std::size_t k = 0; k < times_.size(); ++k) {
    const auto& s = series_[k];
    d.insert(d.end(), {times_[k], s.S2, s.director.x(), s.director.y(), s.director.z(),
                       s.eigenvalues.x(), s.eigenvalues.y(), s.eigenvalues.z()});
  }
  return d;
}

void NematicOrder::load(const std::vector<double>& d) {
  if (d.size() % 8 != 0) throw std::invalid_argument("nematic record: length is not a multiple of 8");
  reset();
  for (std::size_t k = 0; k < d.size(); k += 8) {
    times_.push_back(d[k]);
    series_.push_back({d[k + 1], Vec3(d[k + 2], d[k + 3], d[k + 4]), Vec3(d[k + 5], d[k + 6], d[k + 7])});
  }
}

MeanError NematicOrder::S2() const {
  std::vector<double> s(series_.size());
  for (std::size_t k = 0; k < s.size(); ++k) s[k] = series_[k].S2;
  return block_average(std::move(s));
}

std::string NematicOrder::to_tsv() const {
  const MeanError m = S2();
  char buf[160];
  std::snprintf(buf, sizeof buf, "# hardbody nematic order\n# S2_mean=%.10g S2_error=%.10g samples=%zu\n", m.mean,
                m.error, series_.size());
  std::string out = buf;
  out += "time\tS2\tdirector_x\tdirector_y\tdirector_z\n";
  for (std::size_t k = 0; k < series_.size(); ++k) {
    const auto& s = series_[k];
    append_row(out, {times_[k], s.S2, s.director.x(), s.director.y(), s.director.z()});
    out += '\n';
  }
  return out;
}

}  // namespace hb
