#include "observers/correlations.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/interrupt.hpp"

namespace hb {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("CorrelationSpec: ") + what);
}

std::vector<int> make_lag_grid(const CorrelationSpec& s) {
  std::vector<int> lags;
  const int linear_until = s.log_lags ? std::min(10, s.max_lag_samples) : s.max_lag_samples;
  for (int k = 0; k <= linear_until; ++k) lags.push_back(k);
  if (s.log_lags) {
    for (int j = 1;; ++j) {
      const double x = 10.0 * std::pow(10.0, double(j) / s.lags_per_decade);
      const int k = static_cast<int>(std::lround(x));
      if (k >= s.max_lag_samples) break;
      if (k > lags.back()) lags.push_back(k);
    }
    if (lags.back() != s.max_lag_samples) lags.push_back(s.max_lag_samples);
  }
  return lags;
}

void append(std::string& out, const char* fmt, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, x);
  out += buf;
}

}  // namespace

TimeCorrelations::TimeCorrelations(const CorrelationSpec& spec) : spec_(spec) {
  require(std::isfinite(spec.interval) && spec.interval > 0.0, "interval must be > 0");
  require(spec.origin_every >= 1, "origin_every must be >= 1");
  require(spec.max_lag_samples >= 1, "max_lag_samples must be >= 1");
  require(spec.max_origins >= 1, "max_origins must be >= 1");
  require(spec.lags_per_decade >= 1, "lags_per_decade must be >= 1");
  require(std::isfinite(spec.q) && spec.q > 0.0, "q must be > 0");
  require(spec.q_tolerance >= 0.0, "q_tolerance must be >= 0");
  require(spec.max_q_vectors >= 1, "max_q_vectors must be >= 1");
  require(spec.body_axis.allFinite() && spec.body_axis.norm() > 0.0, "body_axis must be nonzero");
  require(spec.fit_from >= 0.0 && spec.fit_from < spec.fit_to && spec.fit_to <= 1.0,
          "need 0 <= fit_from < fit_to <= 1");
  spec_.body_axis.normalize();

  // Origins live while their lag is <= max_lag: at most floor(max_lag / every) + 1 at once.
  origin_every_ = spec.origin_every;
  if (spec.max_origins == 1) {
    origin_every_ = std::max(origin_every_, spec.max_lag_samples + 1);
  } else {
    const int need = (spec.max_lag_samples + spec.max_origins - 2) / (spec.max_origins - 1);
    origin_every_ = std::max(origin_every_, need);
  }
  origins_.resize(static_cast<std::size_t>(spec.max_lag_samples / origin_every_ + 1));

  lags_ = make_lag_grid(spec_);
  slot_.assign(static_cast<std::size_t>(spec.max_lag_samples) + 1, -1);
  for (std::size_t j = 0; j < lags_.size(); ++j) slot_[static_cast<std::size_t>(lags_[j])] = int(j);
  reset();
}

void TimeCorrelations::reset() {
  for (auto& o : origins_) o.index = -1;
  next_sample_ = 0;
  first_time_ = 0.0;
  const std::size_t m = lags_.size();
  sum_msd_.assign(m, 0.0);
  sum_r4_.assign(m, 0.0);
  sum_c1_.assign(m, 0.0);
  sum_c2_.assign(m, 0.0);
  sum_fs_.assign(m, 0.0);
  count_.assign(m, 0);
  pending_.ready = false;
}

namespace {
constexpr double kCorrelationsRecord = 1.0;  // record version
}

std::vector<double> TimeCorrelations::save() const {
  const std::size_t m = lags_.size();
  std::vector<double> d{kCorrelationsRecord, double(m), double(spec_.max_lag_samples),
                        double(origin_every_), double(origins_.size()), double(next_sample_),
                        first_time_, double(n_), box_L_.x(), box_L_.y(), box_L_.z(),
                        double(qs_.size())};
  for (const auto* v : {&sum_msd_, &sum_r4_, &sum_c1_, &sum_c2_, &sum_fs_}) d.insert(d.end(), v->begin(), v->end());
  for (auto c : count_) d.push_back(double(c));
  for (const auto& q : qs_) d.insert(d.end(), {q.x(), q.y(), q.z()});
  for (const auto& o : origins_) {
    d.push_back(double(o.index));
    if (o.index < 0) continue;
    for (const auto* v : {&o.r, &o.u})
      for (const auto& x : *v) d.insert(d.end(), {x.x(), x.y(), x.z()});
  }
  return d;
}

void TimeCorrelations::load(const std::vector<double>& d) {
  auto fail = [](const char* why) {
    throw std::invalid_argument(std::string("time-correlation record: ") + why);
  };
  const std::size_t m = lags_.size();
  if (d.size() < 12 || d[0] != kCorrelationsRecord) fail("unknown version or too short");
  if (d[1] != double(m) || d[2] != double(spec_.max_lag_samples) || d[3] != double(origin_every_) ||
      d[4] != double(origins_.size()))
    fail("written with another lag grid or origin spacing");
  const std::size_t n = std::size_t(d[7]), nq = std::size_t(d[11]);
  std::size_t at = 12;
  auto take = [&](std::size_t k) {
    if (d.size() - at < k) fail("truncated");
    const std::size_t from = at;
    at += k;
    return d.begin() + std::ptrdiff_t(from);
  };
  auto vecs = [&](std::vector<Vec3>& out, std::size_t k) {
    auto it = take(3 * k);
    out.resize(k);
    for (auto& x : out) {
      x = Vec3(it[0], it[1], it[2]);
      it += 3;
    }
  };
  std::vector<double>* sums[] = {&sum_msd_, &sum_r4_, &sum_c1_, &sum_c2_, &sum_fs_};
  for (auto* v : sums) {
    auto it = take(m);
    v->assign(it, it + std::ptrdiff_t(m));
  }
  {
    auto it = take(m);
    for (std::size_t j = 0; j < m; ++j) count_[j] = std::int64_t(it[std::ptrdiff_t(j)]);
  }
  vecs(qs_, nq);
  for (auto& o : origins_) {
    o.index = std::int64_t(*take(1));
    if (o.index < 0) continue;
    vecs(o.r, n);
    vecs(o.u, n);
  }
  if (at != d.size()) fail("trailing data");
  next_sample_ = std::int64_t(d[5]);
  first_time_ = d[6];
  n_ = n;
  box_L_ = Vec3(d[8], d[9], d[10]);
  pending_.ready = false;
}

namespace {

// A lattice vector and its key in the selection order.
struct QCand {
  double dist;  // | |k| - reference |
  int nx, ny, nz;
  Vec3 q;
};
bool before(const QCand& a, const QCand& b) {
  if (a.dist != b.dist) return a.dist < b.dist;
  if (a.nx != b.nx) return a.nx < b.nx;
  if (a.ny != b.ny) return a.ny < b.ny;
  return a.nz < b.nz;
}

// Calls f(nx, ny, nz, k, |k|) for the lattice vectors (one of each +-k pair) whose modulus may
// lie in [lo, hi] (a superset: the caller tests |k|), in (nx, ny, nz) order. The loops run over
// the (nx, ny) columns of the shell and, in each, over the nz of the shell only.
template <class F>
void for_lattice_shell(const Vec3& dq, double lo, double hi, F&& f) {
  lo = std::max(0.0, lo);
  const int nx_max = static_cast<int>(std::ceil(hi / dq.x()));
  for (int nx = 0; nx <= nx_max; ++nx) {
    poll_interrupt("F_self q vectors");
    const double rest_x = hi * hi - sqr(nx * dq.x());
    if (rest_x < 0.0) break;
    const int ny_max = static_cast<int>(std::floor(std::sqrt(rest_x) / dq.y())) + 1;
    for (int ny = (nx == 0 ? 0 : -ny_max); ny <= ny_max; ++ny) {
      const double qxy2 = sqr(nx * dq.x()) + sqr(ny * dq.y());
      if (qxy2 > hi * hi) continue;
      const int z_hi = static_cast<int>(std::floor(std::sqrt(hi * hi - qxy2) / dq.z())) + 1;
      const double rest_lo = lo * lo - qxy2;
      const int z_lo = rest_lo > 0.0 ? std::max(0, static_cast<int>(std::ceil(std::sqrt(rest_lo) / dq.z())) - 1) : 0;
      for (int nz = -z_hi; nz <= z_hi; ++nz) {
        if (std::abs(nz) < z_lo) {  // jump over the inside of the shell
          nz = z_lo - 1;
          continue;
        }
        if (nx == 0 && ny == 0 && nz <= 0) continue;
        const Vec3 k(nx * dq.x(), ny * dq.y(), nz * dq.z());
        f(nx, ny, nz, k, k.norm());
      }
    }
  }
}

// Deterministic 64-bit generator (splitmix64) for the random directions.
std::uint64_t splitmix64(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
double uniform01(std::uint64_t& s) { return double(splitmix64(s) >> 11) * 0x1.0p-53; }

std::vector<Vec3> random_lattice_q(const Vec3& dq, double target, int max_vectors) {
  std::uint64_t seed = 0x5eedf5e1fULL;
  std::vector<Eigen::Vector3d> ns;
  std::vector<Vec3> out;
  for (long attempt = 0; attempt < 100L * max_vectors && int(out.size()) < max_vectors; ++attempt) {
    if ((attempt & 0xff) == 0) poll_interrupt("F_self q vectors");
    const double z = 2.0 * uniform01(seed) - 1.0, phi = 2.0 * kPi * uniform01(seed);
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 dir(s * std::cos(phi), s * std::sin(phi), z);
    Eigen::Vector3d n;
    for (int d = 0; d < 3; ++d) n[d] = std::round(target * dir[d] / dq[d]);
    if (n.cwiseAbs().maxCoeff() > 2e9)
      throw std::invalid_argument("TimeCorrelations: q L is too large for the lattice q vectors");
    // One of each +-n pair: the first nonzero component positive.
    for (int d = 0; d < 3; ++d)
      if (n[d] != 0.0) {
        if (n[d] < 0.0) n = -n;
        break;
      }
    if (n.isZero() || std::find(ns.begin(), ns.end(), n) != ns.end()) continue;
    ns.push_back(n);
    out.push_back(n.cwiseProduct(dq));
  }
  return out;
}

}  // namespace

bool lattice_q_is_random(const Vec3& L, double q, double tolerance) {
  const Vec3 dq = (2.0 * kPi) * L.cwiseInverse();
  const double hi = q * (1.0 + tolerance) + dq.maxCoeff();
  return (hi / dq.x() + 1.0) * (2.0 * hi / dq.y() + 1.0) > kMaxQColumns;
}

QSelection lattice_q_vectors(const Vec3& L, double target, double tolerance, int max_vectors) {
  QSelection sel;
  const Vec3 dq = (2.0 * kPi) * L.cwiseInverse();  // spacing of the reciprocal lattice
  const std::size_t m = static_cast<std::size_t>(std::max(1, max_vectors));
  if (lattice_q_is_random(L, target, tolerance)) {
    sel.random = true;
    sel.q = random_lattice_q(dq, target, max_vectors);
    if (sel.q.empty()) throw std::invalid_argument("TimeCorrelations: no q vector fits the box");
    return sel;
  }
  // The closest achievable modulus: the point (round(target / dq_x), 0, 0) is within dq_x / 2,
  // so it lies in the shell of half-width dq_max; the first in (nx, ny, nz) order on ties.
  const double dq_max = dq.maxCoeff();
  double best = -1.0, best_dist = 0.0;
  for_lattice_shell(dq, target - dq_max, target + dq_max, [&](int, int, int, const Vec3&, double norm) {
    const double d = std::abs(norm - target);
    if (best < 0.0 || d < best_dist) {
      best = norm;
      best_dist = d;
    }
  });
  if (best < 0.0) throw std::invalid_argument("TimeCorrelations: no q vector fits the box");
  // (1e-12: the same n.n in another order may round differently)
  const double keep = (tolerance + 1e-12) * best;
  // Widen the shell |k| in [best - delta, best + delta] from about 4 max_vectors expected
  // lattice points (2 pi best^2 x 2 delta / cell volume in the half space) until it holds
  // max_vectors or reaches the tolerance; keep only the max_vectors first (a bounded heap).
  const double cell = dq.x() * dq.y() * dq.z();
  double delta = std::min(keep, std::max(1e-12 * best, double(m) * cell / (kPi * best * best)));
  std::vector<QCand> heap;
  for (;;) {
    heap.clear();
    std::size_t seen = 0;
    for_lattice_shell(dq, best - delta, best + delta, [&](int nx, int ny, int nz, const Vec3& k, double norm) {
      const double d = std::abs(norm - best);
      if (d > delta) return;
      ++seen;
      const QCand c{d, nx, ny, nz, k};
      if (heap.size() == m && !before(c, heap.front())) return;
      heap.push_back(c);
      std::push_heap(heap.begin(), heap.end(), before);
      if (heap.size() > m) {
        std::pop_heap(heap.begin(), heap.end(), before);
        heap.pop_back();
      }
    });
    if (seen >= m || delta >= keep) break;
    delta = std::min(keep, 2.0 * delta);
  }
  std::sort_heap(heap.begin(), heap.end(), before);
  for (const auto& c : heap) sel.q.push_back(c.q);
  return sel;
}

const char* TimeCorrelations::q_selection() const {
  if (qs_.empty()) return "none";
  return lattice_q_is_random(box_L_, spec_.q, spec_.q_tolerance) ? "random" : "shell";
}

double TimeCorrelations::q_used() const {
  if (qs_.empty()) return kNaN;
  double s = 0.0;
  for (const auto& q : qs_) s += q.norm();
  return s / double(qs_.size());
}

void TimeCorrelations::sample(double time, const State& state, const Box& box) {
  prepare(time, state, box);
  commit();
}

TimeCorrelations::Term TimeCorrelations::correlate(const std::vector<Vec3>& r0, const std::vector<Vec3>& u0,
                                                   int j, const std::vector<Vec3>& qs) const {
  const std::size_t n = r_now_.size();
  const double inv_n = n > 0 ? 1.0 / double(n) : 0.0;
  const double inv_nq = qs.empty() ? 0.0 : 1.0 / double(qs.size());
  double s2 = 0.0, s4 = 0.0, sc1 = 0.0, sc2 = 0.0, sfs = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if ((i & 0xfff) == 0xfff) poll_interrupt("correlations");
    const Vec3 d = r_now_[i] - r0[i];
    const double d2 = d.squaredNorm();
    s2 += d2;
    s4 += d2 * d2;
    const double c = u0[i].dot(u_now_[i]);
    sc1 += c;
    sc2 += 1.5 * c * c - 0.5;
    double f = 0.0;
    for (const Vec3& q : qs) f += std::cos(q.dot(d));
    sfs += f * inv_nq;
  }
  return {j, s2 * inv_n, s4 * inv_n, sc1 * inv_n, sc2 * inv_n, sfs * inv_n};
}

void TimeCorrelations::prepare(double time, const State& state, const Box& box) {
  Pending& p = pending_;
  p.ready = p.first = p.new_q = p.new_origin = false;
  p.terms.clear();
  const std::size_t n = state.size();
  if (next_sample_ == 0) {
    p.first = true;
    p.first_time = time;
    p.n = n;
    if (qs_.empty() || box.L != box_L_) {
      p.new_q = true;
      p.qs = lattice_q_vectors(box.L, spec_.q, spec_.q_tolerance, spec_.max_q_vectors).q;
      p.box_L = box.L;
    }
  } else {
    const double expected = first_time_ + double(next_sample_) * spec_.interval;
    if (std::abs(time - expected) > 1e-6 * spec_.interval)
      throw std::invalid_argument("TimeCorrelations::sample: time " + std::to_string(time) +
                                  " is not first + k * interval = " + std::to_string(expected));
    if (n != n_) throw std::invalid_argument("TimeCorrelations::sample: number of bodies changed");
  }
  const std::vector<Vec3>& qs = p.new_q ? p.qs : qs_;

  // Current unwrapped positions and axes (bodies behind `time` are streamed on a copy).
  r_now_.resize(n);
  u_now_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if ((i & 0xffff) == 0xffff) poll_interrupt("correlations");
    const double dt = time - state.t[i];
    const Quat q = dt == 0.0 ? state.q[i] : orientation_at(state.body(i), dt);
    r_now_[i] = state.r[i] + state.v[i] * dt + state.image[i].cast<double>().cwiseProduct(box.L);
    u_now_[i] = q * spec_.body_axis;
  }

  // Live origins at a grid lag; the slot a new origin replaces holds one beyond max_lag.
  const std::int64_t k = next_sample_;
  for (const Origin& o : origins_) {
    if (o.index < 0) continue;
    const std::int64_t lag = k - o.index;
    if (lag > spec_.max_lag_samples) continue;
    const int j = slot_[static_cast<std::size_t>(lag)];
    if (j >= 0) p.terms.push_back(correlate(o.r, o.u, j, qs));
  }
  if (k % origin_every_ == 0) {
    p.new_origin = true;
    p.slot = static_cast<std::size_t>((k / origin_every_) % static_cast<std::int64_t>(origins_.size()));
    p.index = k;
    p.r = r_now_;
    p.u = u_now_;
    p.terms.push_back(correlate(p.r, p.u, slot_[0], qs));  // lag 0
  }
  p.ready = true;
}

void TimeCorrelations::commit() noexcept {
  Pending& p = pending_;
  if (!p.ready) return;
  if (p.first) {
    first_time_ = p.first_time;
    n_ = p.n;
  }
  if (p.new_q) {
    qs_.swap(p.qs);
    box_L_ = p.box_L;
  }
  if (p.new_origin) {
    Origin& o = origins_[p.slot];
    o.index = p.index;
    o.r.swap(p.r);
    o.u.swap(p.u);
  }
  for (const Term& t : p.terms) {
    const auto j = static_cast<std::size_t>(t.j);
    sum_msd_[j] += t.s2;
    sum_r4_[j] += t.s4;
    sum_c1_[j] += t.c1;
    sum_c2_[j] += t.c2;
    sum_fs_[j] += t.fs;
    ++count_[j];
  }
  ++next_sample_;
  p.ready = false;
}

std::vector<double> TimeCorrelations::ratio(const std::vector<double>& sum) const {
  std::vector<double> out(sum.size());
  for (std::size_t j = 0; j < sum.size(); ++j) out[j] = count_[j] > 0 ? sum[j] / double(count_[j]) : kNaN;
  return out;
}

std::vector<double> TimeCorrelations::times() const {
  std::vector<double> t(lags_.size());
  for (std::size_t j = 0; j < lags_.size(); ++j) t[j] = lags_[j] * spec_.interval;
  return t;
}
std::vector<double> TimeCorrelations::msd() const { return ratio(sum_msd_); }
std::vector<double> TimeCorrelations::c1() const { return ratio(sum_c1_); }
std::vector<double> TimeCorrelations::c2() const { return ratio(sum_c2_); }
std::vector<double> TimeCorrelations::fself() const { return ratio(sum_fs_); }

std::vector<double> TimeCorrelations::alpha2() const {
  const auto m2 = ratio(sum_msd_), m4 = ratio(sum_r4_);
  std::vector<double> a(m2.size(), kNaN);
  for (std::size_t j = 0; j < a.size(); ++j)
    if (count_[j] > 0 && m2[j] > 0.0) a[j] = 3.0 * m4[j] / (5.0 * m2[j] * m2[j]) - 1.0;
  return a;
}

DiffusionFit TimeCorrelations::diffusion() const {
  DiffusionFit fit;
  const auto t = times();
  const auto m = msd();
  double t_max = 0.0;
  for (std::size_t j = 0; j < t.size(); ++j)
    if (count_[j] > 0) t_max = std::max(t_max, t[j]);
  fit.t_from = spec_.fit_from * t_max;
  fit.t_to = spec_.fit_to * t_max;
  double st = 0, sm = 0;
  int np = 0;
  for (std::size_t j = 0; j < t.size(); ++j) {
    if (count_[j] == 0 || t[j] < fit.t_from || t[j] > fit.t_to) continue;
    st += t[j];
    sm += m[j];
    ++np;
  }
  if (np < 2) return fit;
  const double tb = st / np, mb = sm / np;
  double sxx = 0, sxy = 0;
  for (std::size_t j = 0; j < t.size(); ++j) {
    if (count_[j] == 0 || t[j] < fit.t_from || t[j] > fit.t_to) continue;
    sxx += sqr(t[j] - tb);
    sxy += (t[j] - tb) * (m[j] - mb);
  }
  if (sxx <= 0.0) return fit;
  const double slope = sxy / sxx;
  fit.intercept = mb - slope * tb;
  fit.D = slope / 6.0;
  fit.points = np;
  if (np > 2) {
    double ssr = 0;
    for (std::size_t j = 0; j < t.size(); ++j) {
      if (count_[j] == 0 || t[j] < fit.t_from || t[j] > fit.t_to) continue;
      ssr += sqr(m[j] - fit.intercept - slope * t[j]);
    }
    fit.D_error = std::sqrt(ssr / (np - 2) / sxx) / 6.0;
  }
  return fit;
}

std::string TimeCorrelations::to_tsv() const {
  std::string out = "# hardbody time correlations\n";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "# interval=%.10g origin_every=%d max_lag_samples=%d samples=%lld "
                "body_axis=%.6g,%.6g,%.6g\n",
                spec_.interval, origin_every_, spec_.max_lag_samples,
                static_cast<long long>(next_sample_), spec_.body_axis.x(), spec_.body_axis.y(),
                spec_.body_axis.z());
  out += buf;
  std::snprintf(buf, sizeof buf, "# q=%.10g q_target=%.10g q_vectors=%zu q_selection=%s\n", q_used(), spec_.q,
                qs_.size(), q_selection());
  out += buf;
  const DiffusionFit f = diffusion();
  std::snprintf(buf, sizeof buf,
                "# D=%.10g D_error=%.10g intercept=%.10g fit_t_from=%.10g fit_t_to=%.10g "
                "fit_points=%d\n",
                f.points > 0 ? f.D : kNaN, f.points > 0 ? f.D_error : kNaN, f.intercept, f.t_from,
                f.t_to, f.points);
  out += buf;
  out += "time\tmsd\tmsd_samples\tc2\tfself\tc1\talpha2\n";
  const auto t = times();
  const auto m = msd(), a = c2(), fs = fself(), b = c1(), al = alpha2();
  for (std::size_t j = 0; j < t.size(); ++j) {
    if (count_[j] == 0) continue;
    append(out, "%.10g", t[j]);
    append(out, "\t%.10g", m[j]);
    out += '\t' + std::to_string(count_[j]);
    append(out, "\t%.10g", a[j]);
    append(out, "\t%.10g", fs[j]);
    append(out, "\t%.10g", b[j]);
    append(out, "\t%.10g", al[j]);
    out += '\n';
  }
  return out;
}

}  // namespace hb
