#include "observers/structure.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "core/interrupt.hpp"

namespace hb {

namespace {

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

// The cell grid of a pair search: nc cells per edge; along edge d the stencil spans +-k[d]
// cells, or every cell of the edge when it has fewer than 2 k + 1 (so the visited cells are
// distinct). Any two bodies within r_max lie in each other's stencils.
struct Grid {
  std::array<int, 3> nc{1, 1, 1};
  std::array<int, 3> k{1, 1, 1};
  std::size_t cells() const { return std::size_t(nc[0]) * std::size_t(nc[1]) * std::size_t(nc[2]); }
  bool whole(int d) const { return nc[d] < 2 * k[d] + 1; }
  int span(int d) const { return whole(d) ? nc[d] : 2 * k[d] + 1; }
  // Expected bodies in a stencil (uniform density).
  double stencil_bodies(std::size_t n) const {
    double f = double(n);
    for (int d = 0; d < 3; ++d) f *= double(span(d)) / double(nc[d]);
    return f;
  }
};

Grid plan_grid(const Box& box, std::size_t n, double r_max, double cell_side) {
  // Automatic: cells of side >= r_max / 4 (a stencil close to the sphere of radius r_max) and
  // >= the mean spacing (V / N)^(1/3), so there are at most about N cells.
  double side = cell_side > 0.0 ? cell_side
                                : std::max(0.25 * r_max, std::cbrt(box.volume() / double(std::max<std::size_t>(n, 1))));
  Grid g;
  for (;;) {
    for (int d = 0; d < 3; ++d)
      g.nc[d] = static_cast<int>(std::clamp(std::floor(box.L[d] / side), 1.0, double(1 << 20)));
    if (cell_side > 0.0 || double(g.cells()) <= 2.0 * double(n) + 64.0) break;
    side *= 1.25;  // thin boxes: keep the cell count O(N)
  }
  for (int d = 0; d < 3; ++d) {
    // k cells of the actual side cover r_max, with a margin for the rounding of cell indices.
    const double a = box.L[d] / double(g.nc[d]);
    g.k[d] = std::max(1, static_cast<int>(std::ceil(r_max * (1.0 + 1e-9) / a)));
  }
  return g;
}

// The common pair search of pair_histogram and PartialRadialDistribution: calls
// visit(i, j, bin) for every counted pair within r_max (i the centre in subset mode).
template <class Visit>
PairCount for_each_pair(FieldView<Vec3> p, const Box& box, double r_max, std::size_t bins,
                        const PairSearch& search, Visit&& visit) {
  check_range(box, r_max);
  if (bins == 0) throw std::invalid_argument("g(r): no bins");
  const std::size_t n = p.size();
  const Grid grid = plan_grid(box, n, r_max, search.cell_side);
  PairCount pc;
  pc.cells = grid.nc;
  pc.stencil = *std::max_element(grid.k.begin(), grid.k.end());
  const double work = double(n) * grid.stencil_bodies(n);  // ordered (centre, body) visits
  pc.all_pairs = 0.5 * work <= search.max_pairs;
  if (!pc.all_pairs) {
    pc.stride = static_cast<std::size_t>(std::clamp(std::ceil(work / std::max(search.max_pairs, 1.0)), 2.0, double(n)));
    pc.offset = search.offset % pc.stride;
  }
  pc.centres = n == 0 ? 0 : (pc.all_pairs ? n : (n - pc.offset + pc.stride - 1) / pc.stride);
  if (n < 2) return pc;

  // Counting sort of the bodies by cell.
  const std::size_t ncell = grid.cells();
  auto coord = [&](const Vec3& x, int d) {
    return std::clamp(static_cast<int>(x[d] / box.L[d] * grid.nc[d]), 0, grid.nc[d] - 1);
  };
  std::vector<std::size_t> start(ncell + 1, 0), order(n), cell(n);
  for (std::size_t i = 0; i < n; ++i) {
    cell[i] = (std::size_t(coord(p[i], 2)) * grid.nc[1] + coord(p[i], 1)) * grid.nc[0] + coord(p[i], 0);
    ++start[cell[i] + 1];
    if ((i & 0xffff) == 0) poll_interrupt("g(r)");
  }
  for (std::size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
  // The positions in cell order too, so that the inner loops read memory in sequence.
  std::vector<Vec3> ps(n);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t at = fill[cell[i]]++;
      order[at] = i;
      ps[at] = p[i];
    }
  }

  const double r_max2 = r_max * r_max, inv_dr = double(bins) / r_max;
  const Vec3 L = box.L, half = 0.5 * box.L;
  // The pair (body i at x, body order[t]). The minimum image as Box::near_image computes it for
  // |d| < L (both bodies in [0, L)), without branches. near_image(-d) = -near_image(d) exactly,
  // so the distance does not depend on which body comes first.
  auto pair = [&](std::size_t i, const Vec3& x, std::size_t t) {
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      double d = ps[t][k] - x[k];
      d -= L[k] * double(d > half[k]);
      d += L[k] * double(d < -half[k]);
      d2 += d * d;
    }
    if (d2 >= r_max2) return;
    visit(i, order[t], std::min(static_cast<std::size_t>(std::sqrt(d2) * inv_dr), bins - 1));
  };
  // The stencil cells along edge d of cell coordinate c, each once.
  auto stencil = [&](int d, int c, std::array<int, 16>& out) {
    const int m = grid.span(d);
    if (m > 16) throw std::logic_error("g(r): stencil wider than 16 cells");
    for (int s = 0; s < m; ++s)
      out[std::size_t(s)] = grid.whole(d) ? s : ((c - grid.k[d] + s) % grid.nc[d] + grid.nc[d]) % grid.nc[d];
    return m;
  };
  // Calls f(b) for every cell b in the stencil of cell (cx, cy, cz).
  auto for_stencil = [&](int cx, int cy, int cz, auto&& f) {
    std::array<int, 16> sx{}, sy{}, sz{};
    const int mx = stencil(0, cx, sx), my = stencil(1, cy, sy), mz = stencil(2, cz, sz);
    for (int z = 0; z < mz; ++z)
      for (int y = 0; y < my; ++y)
        for (int x = 0; x < mx; ++x) f((std::size_t(sz[std::size_t(z)]) * grid.nc[1] + std::size_t(sy[std::size_t(y)])) * grid.nc[0] + std::size_t(sx[std::size_t(x)]));
  };

  if (pc.all_pairs) {
    // Each unordered pair of cells once (b > a), pairs within a cell once (t > s).
    for (int cz = 0; cz < grid.nc[2]; ++cz)
      for (int cy = 0; cy < grid.nc[1]; ++cy)
        for (int cx = 0; cx < grid.nc[0]; ++cx) {
          const std::size_t a = (std::size_t(cz) * grid.nc[1] + cy) * grid.nc[0] + cx;
          poll_interrupt("g(r)");
          for_stencil(cx, cy, cz, [&](std::size_t b) {
            if (b < a) return;
            for (std::size_t s = start[a]; s < start[a + 1]; ++s) {
              const std::size_t from = b == a ? s + 1 : start[b];
              pc.distances += start[b + 1] - std::min(from, start[b + 1]);
              for (std::size_t t = from; t < start[b + 1]; ++t) pair(order[s], ps[s], t);
            }
          });
        }
  } else {
    for (std::size_t i = pc.offset; i < n; i += pc.stride) {
      poll_interrupt("g(r)");
      const std::size_t c = cell[i];
      const int cx = int(c % std::size_t(grid.nc[0])), cy = int(c / std::size_t(grid.nc[0]) % std::size_t(grid.nc[1])),
                cz = int(c / (std::size_t(grid.nc[0]) * std::size_t(grid.nc[1])));
      const Vec3 x = p[i];
      for_stencil(cx, cy, cz, [&](std::size_t b) {
        pc.distances += start[b + 1] - start[b] - (b == c ? 1 : 0);
        for (std::size_t t = start[b]; t < start[b + 1]; ++t)
          if (order[t] != i) pair(i, x, t);
      });
    }
  }
  return pc;
}

void add_into(std::vector<std::uint64_t>& to, const std::vector<std::uint64_t>& from) {
  for (std::size_t k = 0; k < to.size(); ++k) to[k] += from[k];
}

// Ideal-gas shell volumes of the bins of [0, r_max].
std::vector<double> shell_volumes(double r_max, std::size_t bins) {
  std::vector<double> v(bins);
  const double dr = r_max / double(bins);
  for (std::size_t k = 0; k < bins; ++k)
    v[k] = 4.0 / 3.0 * kPi * (std::pow(double(k + 1) * dr, 3) - std::pow(double(k) * dr, 3));
  return v;
}

// The wrapped centres of the bodies at `time`.
void wrapped_positions(const State& state, const Box& box, double time, std::vector<Vec3>& out) {
  out.resize(state.size());
  for (std::size_t i = 0; i < state.size(); ++i) {
    out[i] = state.position_at(i, time);
    box.wrap(out[i]);
  }
}

}  // namespace

PairCount pair_histogram(FieldView<Vec3> p, const Box& box, double r_max,
                         std::vector<std::uint64_t>& hist, const PairSearch& search) {
  std::vector<std::uint64_t> h(hist.size(), 0);
  const PairCount pc = for_each_pair(p, box, r_max, h.size(), search,
                                     [&](std::size_t, std::size_t, std::size_t bin) { ++h[bin]; });
  add_into(hist, h);
  return pc;
}

RadialDistribution::RadialDistribution(const RdfSpec& spec) : spec_(spec) {
  if (spec.bins < 1) throw std::invalid_argument("RdfSpec: bins must be >= 1");
  if (!(spec.r_max >= 0.0) || !std::isfinite(spec.r_max))
    throw std::invalid_argument("RdfSpec: r_max must be >= 0 (0: half the shortest box edge)");
  if (!(spec.max_neighbours >= 1.0)) throw std::invalid_argument("RdfSpec: max_neighbours must be >= 1");
  if (!(spec.max_pairs >= 1.0)) throw std::invalid_argument("RdfSpec: max_pairs must be >= 1");
  reset();
}

void RadialDistribution::reset() {
  r_max_ = spec_.r_max;
  r_max_capped_ = false;
  samples_ = subset_samples_ = 0;
  last_n_ = 0;
  sum_pair_density_ = sum_n_ = sum_centres_ = 0.0;
  hist_.assign(static_cast<std::size_t>(spec_.bins), 0);
  pending_ = {};
}

void RadialDistribution::sample(double time, const State& state, const Box& box) {
  prepare(time, state, box);
  commit();
}

std::pair<double, bool> RadialDistribution::automatic_r_max(const Box& box, std::size_t n) const {
  if (r_max_ > 0.0) return {r_max_, r_max_capped_};
  const double half = 0.5 * box.L.minCoeff();
  if (n < 2) return {half, false};
  // Ideal gas: (N - 1) / V x 4/3 pi r^3 neighbours within r.
  const double cap = std::cbrt(spec_.max_neighbours * box.volume() / (4.0 / 3.0 * kPi * double(n - 1)));
  return cap < half ? std::pair{cap, true} : std::pair{half, false};
}

double RadialDistribution::r_max_for(const Box& box, std::size_t n) const { return automatic_r_max(box, n).first; }

void RadialDistribution::prepare(double time, const State& state, const Box& box) {
  pending_.ready = false;
  const std::size_t n = state.size();
  std::tie(pending_.r_max, pending_.capped) = automatic_r_max(box, n);
  wrapped_positions(state, box, time, pos_);
  pending_.hist.assign(hist_.size(), 0);
  PairSearch search;
  search.max_pairs = spec_.max_pairs;
  search.offset = std::size_t(samples_);
  pending_.count = pair_histogram(pos_, box, pending_.r_max, pending_.hist, search);
  pending_.n = n;
  const double centres = double(pending_.count.centres), nn = double(n);
  pending_.pair_density = pending_.count.all_pairs ? 0.5 * nn * (nn - 1.0) / box.volume()
                                                   : centres * (nn - 1.0) / box.volume();
  pending_.ready = true;
}

void RadialDistribution::commit() noexcept {
  if (!pending_.ready) return;
  r_max_ = pending_.r_max;
  r_max_capped_ = pending_.capped;
  add_into(hist_, pending_.hist);
  ++samples_;
  if (!pending_.count.all_pairs) ++subset_samples_;
  last_n_ = pending_.n;
  sum_n_ += pending_.count.all_pairs ? double(pending_.n) : 2.0 * double(pending_.count.centres);
  sum_centres_ += double(pending_.count.centres);
  sum_pair_density_ += pending_.pair_density;
  pending_.ready = false;
}

// Record: r_max, samples, N, pair density sum, centre-weight sum, bins, the bins, then (since
// the subset search) centres sum, subset samples, r_max capped. Records without the last three
// (written before) load with all pairs assumed.
std::vector<double> RadialDistribution::save() const {
  std::vector<double> d{r_max_, double(samples_), double(last_n_), sum_pair_density_, sum_n_,
                        double(hist_.size())};
  for (auto h : hist_) d.push_back(double(h));
  d.insert(d.end(), {sum_centres_, double(subset_samples_), r_max_capped_ ? 1.0 : 0.0});
  return d;
}

void RadialDistribution::load(const std::vector<double>& d) {
  const std::size_t nb = hist_.size();
  if (d.size() < 6 || d[5] != double(nb) || (d.size() != 6 + nb && d.size() != 9 + nb))
    throw std::invalid_argument("g(r) record: wrong length or bin count");
  r_max_ = d[0];
  samples_ = int(d[1]);
  last_n_ = std::size_t(d[2]);
  sum_pair_density_ = d[3];
  sum_n_ = d[4];
  for (std::size_t k = 0; k < nb; ++k) hist_[k] = std::uint64_t(d[6 + k]);
  const bool tail = d.size() == 9 + nb;
  sum_centres_ = tail ? d[6 + nb] : sum_n_;
  subset_samples_ = tail ? int(d[7 + nb]) : 0;
  r_max_capped_ = tail && d[8 + nb] != 0.0;
  pending_ = {};
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
  const auto shell = shell_volumes(r_max_, hist_.size());
  for (std::size_t k = 0; k < g.size(); ++k) g[k] = double(hist_[k]) / (sum_pair_density_ * shell[k]);
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
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "# hardbody radial distribution function\n"
                "# samples=%d N=%zu r_max=%.10g bins=%zu pair_search=%s centres_per_sample=%.10g\n",
                samples_, last_n_, r_max_, hist_.size(), subset_samples_ > 0 ? "subset" : "all",
                samples_ > 0 ? sum_centres_ / samples_ : 0.0);
  std::string out = buf;
  if (r_max_capped_)
    out += "# r_max is below half the box: capped at " + std::to_string(long(spec_.max_neighbours)) +
           " ideal-gas neighbours per body (docs/observables.md)\n";
  if (subset_samples_ > 0)
    out += "# pairs are (centre, other body) pairs of a subset of centres per sample (docs/observables.md)\n";
  out += "r\tg\tn_r\tpairs\n";
  const auto r = this->r(), g = this->g(), c = coordination();
  for (std::size_t k = 0; k < r.size(); ++k) {
    append_row(out, {r[k], g[k], c[k]});
    out += '\t' + std::to_string(hist_[k]) + '\n';
  }
  return out;
}

PartialRadialDistribution::PartialRadialDistribution(std::size_t species, int bins, double max_pairs)
    : ns_(species), bins_(bins), max_pairs_(max_pairs) {
  if (bins < 1) throw std::invalid_argument("PartialRadialDistribution: bins must be >= 1");
  if (!(max_pairs >= 1.0)) throw std::invalid_argument("PartialRadialDistribution: max_pairs must be >= 1");
  density_.assign(ns_ * (ns_ + 1) / 2, 0.0);
  hist_.assign(density_.size(), std::vector<std::uint64_t>(std::size_t(bins), 0));
}

std::size_t PartialRadialDistribution::pair_index(std::size_t a, std::size_t b) const {
  return species_pair_index(a, b, ns_);
}

void PartialRadialDistribution::sample(double time, const State& state, const Box& box, double r_max) {
  prepare(time, state, box, r_max);
  commit();
}

void PartialRadialDistribution::prepare(double time, const State& state, const Box& box, double r_max) {
  pending_.ready = false;
  if (samples_ > 0 && r_max != r_max_) throw std::invalid_argument("PartialRadialDistribution: r_max changed");
  std::vector<Vec3> pos;
  wrapped_positions(state, box, time, pos);
  const std::size_t np = density_.size();
  pending_.hist.assign(np, std::vector<std::uint64_t>(std::size_t(bins_), 0));
  PairSearch search;
  search.max_pairs = max_pairs_;
  search.offset = std::size_t(samples_);
  const auto& sp = state.species;
  const PairCount pc = for_each_pair(pos, box, r_max, std::size_t(bins_), search,
                                     [&](std::size_t i, std::size_t j, std::size_t bin) {
                                       ++pending_.hist[pair_index(std::min(sp[i], sp[j]), std::max(sp[i], sp[j]))][bin];
                                     });
  // Bodies and centres per species.
  std::vector<double> count(ns_, 0.0), centres(ns_, 0.0);
  for (std::size_t i = 0; i < state.size(); ++i) {
    count[sp[i]] += 1.0;
    if (!pc.all_pairs && i >= pc.offset && (i - pc.offset) % pc.stride == 0) centres[sp[i]] += 1.0;
  }
  const double V = box.volume();
  pending_.density.assign(np, 0.0);
  for (std::size_t a = 0; a < ns_; ++a)
    for (std::size_t b = a; b < ns_; ++b) {
      const double na = count[a], nb = count[b];
      double d = 0.0;
      if (pc.all_pairs) d = a == b ? 0.5 * na * (na - 1.0) : na * nb;
      else d = a == b ? centres[a] * (na - 1.0) : centres[a] * nb + centres[b] * na;
      pending_.density[pair_index(a, b)] = d / V;
    }
  pending_.r_max = r_max;
  pending_.ready = true;
}

void PartialRadialDistribution::commit() noexcept {
  if (!pending_.ready) return;
  r_max_ = pending_.r_max;
  for (std::size_t k = 0; k < density_.size(); ++k) {
    add_into(hist_[k], pending_.hist[k]);
    density_[k] += pending_.density[k];
  }
  ++samples_;
  pending_.ready = false;
}

std::vector<double> PartialRadialDistribution::g(std::size_t a, std::size_t b) const {
  const std::size_t k = pair_index(a, b);
  std::vector<double> g(std::size_t(bins_), 0.0);
  if (density_[k] <= 0.0) return g;
  const auto shell = shell_volumes(r_max_, std::size_t(bins_));
  for (int i = 0; i < bins_; ++i) g[i] = double(hist_[k][i]) / (density_[k] * shell[std::size_t(i)]);
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
  pending_ = {};
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

NematicResult nematic_order(FieldView<Quat> orientations, const Vec3& body_axis) {
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
