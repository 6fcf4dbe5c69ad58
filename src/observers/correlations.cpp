#include "observers/correlations.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

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
}

void TimeCorrelations::init_q(const Box& box) {
  box_L_ = box.L;
  qs_.clear();
  const Vec3 dq = (2.0 * kPi) * box.L.cwiseInverse();  // spacing of the reciprocal lattice
  const double target = spec_.q;
  const double dq_max = dq.maxCoeff();
  // Every candidate lies within |q| in [target - w, target + w]: the closest achievable modulus
  // is within dq_max of the target (along the coarsest axis), plus the tolerance shell.
  const double w = dq_max + 2.0 * spec_.q_tolerance * (target + dq_max);
  const double qlo = std::max(0.0, target - w), qhi = target + w;
  struct Cand {
    Vec3 q;
    double norm;
  };
  std::vector<Cand> cands;
  const int nx_max = static_cast<int>(std::ceil(qhi / dq.x()));
  const int ny_max = static_cast<int>(std::ceil(qhi / dq.y()));
  for (int nx = 0; nx <= nx_max; ++nx) {
    for (int ny = (nx == 0 ? 0 : -ny_max); ny <= ny_max; ++ny) {
      const double qxy2 = sqr(nx * dq.x()) + sqr(ny * dq.y());
      if (qxy2 > qhi * qhi) continue;
      const int nz_hi = static_cast<int>(std::floor(std::sqrt(qhi * qhi - qxy2) / dq.z()));
      const double rest_lo = qlo * qlo - qxy2;
      const int nz_lo_abs = rest_lo > 0.0 ? static_cast<int>(std::ceil(std::sqrt(rest_lo) / dq.z())) : 0;
      for (int nz = -nz_hi; nz <= nz_hi; ++nz) {
        if (std::abs(nz) < nz_lo_abs) continue;
        // One of each +-n pair: the first nonzero component positive.
        if (nx == 0 && ny == 0 && nz <= 0) continue;
        if (nx == 0 && ny < 0) continue;
        const Vec3 q(nx * dq.x(), ny * dq.y(), nz * dq.z());
        cands.push_back({q, q.norm()});
      }
    }
  }
  if (cands.empty()) throw std::invalid_argument("TimeCorrelations: no q vector fits the box");
  double best = cands.front().norm;
  for (const auto& c : cands)
    if (std::abs(c.norm - target) < std::abs(best - target)) best = c.norm;
  // (1e-12: the same n.n in another order may round differently)
  const double keep = (spec_.q_tolerance + 1e-12) * best;
  std::erase_if(cands, [&](const Cand& c) { return std::abs(c.norm - best) > keep; });
  std::stable_sort(cands.begin(), cands.end(), [&](const Cand& a, const Cand& b) {
    return std::abs(a.norm - best) < std::abs(b.norm - best);
  });
  if (cands.size() > static_cast<std::size_t>(spec_.max_q_vectors))
    cands.resize(static_cast<std::size_t>(spec_.max_q_vectors));
  for (const auto& c : cands) qs_.push_back(c.q);
}

double TimeCorrelations::q_used() const {
  if (qs_.empty()) return kNaN;
  double s = 0.0;
  for (const auto& q : qs_) s += q.norm();
  return s / double(qs_.size());
}

void TimeCorrelations::sample(double time, const State& state, const Box& box) {
  const std::size_t n = state.size();
  if (next_sample_ == 0) {
    first_time_ = time;
    n_ = n;
    if (qs_.empty() || box.L != box_L_) init_q(box);
  } else {
    const double expected = first_time_ + double(next_sample_) * spec_.interval;
    if (std::abs(time - expected) > 1e-6 * spec_.interval)
      throw std::invalid_argument("TimeCorrelations::sample: time " + std::to_string(time) +
                                  " is not first + k * interval = " + std::to_string(expected));
    if (n != n_) throw std::invalid_argument("TimeCorrelations::sample: number of bodies changed");
  }

  // Current unwrapped positions and axes (bodies behind `time` are streamed on a copy).
  r_now_.resize(n);
  u_now_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double dt = time - state.t[i];
    const Quat q = dt == 0.0 ? state.q[i] : orientation_at(state.body(i), dt);
    r_now_[i] = state.r[i] + state.v[i] * dt + state.image[i].cast<double>().cwiseProduct(box.L);
    u_now_[i] = q * spec_.body_axis;
  }

  const std::int64_t k = next_sample_++;
  const std::int64_t ring = static_cast<std::int64_t>(origins_.size());
  if (k % origin_every_ == 0) {
    Origin& o = origins_[static_cast<std::size_t>((k / origin_every_) % ring)];
    o.index = k;
    o.r = r_now_;
    o.u = u_now_;
  }

  const double inv_n = n > 0 ? 1.0 / double(n) : 0.0;
  const double inv_nq = qs_.empty() ? 0.0 : 1.0 / double(qs_.size());
  for (const Origin& o : origins_) {
    if (o.index < 0) continue;
    const std::int64_t lag = k - o.index;
    if (lag > spec_.max_lag_samples) continue;
    const int j = slot_[static_cast<std::size_t>(lag)];
    if (j < 0) continue;
    double s2 = 0.0, s4 = 0.0, sc1 = 0.0, sc2 = 0.0, sfs = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 d = r_now_[i] - o.r[i];
      const double d2 = d.squaredNorm();
      s2 += d2;
      s4 += d2 * d2;
      const double c = o.u[i].dot(u_now_[i]);
      sc1 += c;
      sc2 += 1.5 * c * c - 0.5;
      double f = 0.0;
      for (const Vec3& q : qs_) f += std::cos(q.dot(d));
      sfs += f * inv_nq;
    }
    sum_msd_[j] += s2 * inv_n;
    sum_r4_[j] += s4 * inv_n;
    sum_c1_[j] += sc1 * inv_n;
    sum_c2_[j] += sc2 * inv_n;
    sum_fs_[j] += sfs * inv_n;
    ++count_[j];
  }
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
  std::snprintf(buf, sizeof buf, "# q=%.10g q_target=%.10g q_vectors=%zu\n", q_used(), spec_.q,
                qs_.size());
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
