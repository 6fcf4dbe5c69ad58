// State of all bodies with delayed (per-particle) times: body i is stored as it was at its own
// time t[i] and is streamed forward only when an event touches it. The hot fields r, v, q, w, t
// live in one record per body (HotRecord); the others are arrays.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/field_view.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"

namespace hb {

// The fields that every prediction reads for each partner (position, velocity, orientation, spin
// and time stamp) kept together in one record per body: 112 bytes padded to two whole cache
// lines, so a partner costs two line fills instead of five (one per array). At N = 256000
// ellipsoids this made a collision about 5 % cheaper; see docs/benchmarks/README.md.
struct alignas(64) HotRecord {
  Vec3 r = Vec3::Zero();
  Vec3 v = Vec3::Zero();
  Quat q = Quat::Identity();
  Vec3 w = Vec3::Zero();
  double t = 0.0;
};

// One field of every body's record, indexed like the std::vector it replaces (s.r[i]). A view
// cannot be copied, since the copy would alias the body's records. It converts to a
// std::vector<T> (a copy of the values) only explicitly: an implicit copy could be bound to a
// reference that outlives it. Functions that only read a field take a FieldView, to which a view
// converts implicitly (no copy: it reads the records in place). Assigning a vector to a view
// writes its values into the records; a vector of another length first resizes the records of
// every field (assign the fields of a new State at one length).
template <class T, T HotRecord::*M>
class HotField {
 public:
  explicit HotField(std::vector<HotRecord>* h) : h_(h) {}
  HotField(const HotField&) = delete;  // a copy would alias the body's record: copy to a vector
  HotField& operator=(const HotField& o) { return *this = std::vector<T>(o); }
  T& operator[](std::size_t i) { return (*h_)[i].*M; }
  const T& operator[](std::size_t i) const { return (*h_)[i].*M; }
  std::size_t size() const { return h_->size(); }
  bool empty() const { return h_->empty(); }
  void assign(std::size_t n, const T& x) {
    h_->resize(n);
    for (auto& e : *h_) e.*M = x;
  }
  HotField& operator=(const std::vector<T>& x) {
    h_->resize(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) (*h_)[i].*M = x[i];
    return *this;
  }
  explicit operator std::vector<T>() const {
    std::vector<T> out;
    out.reserve(h_->size());
    for (const auto& e : *h_) out.push_back(e.*M);
    return out;
  }
  operator FieldView<T>() const {  // NOLINT: implicit by design (read-only, no copy)
    return h_->empty() ? FieldView<T>() : FieldView<T>(&((*h_)[0].*M), sizeof(HotRecord), h_->size());
  }
  template <class H, class V>
  struct Iter {
    H* h;
    std::size_t i;
    using difference_type = std::ptrdiff_t;
    using value_type = T;
    V& operator*() const { return (*h)[i].*M; }
    Iter& operator++() { ++i; return *this; }
    bool operator==(const Iter& o) const { return i == o.i; }
    bool operator!=(const Iter& o) const { return i != o.i; }
  };
  Iter<std::vector<HotRecord>, T> begin() { return {h_, 0}; }
  Iter<std::vector<HotRecord>, T> end() { return {h_, h_->size()}; }
  Iter<const std::vector<HotRecord>, const T> begin() const { return {h_, 0}; }
  Iter<const std::vector<HotRecord>, const T> end() const { return {h_, h_->size()}; }

 private:
  std::vector<HotRecord>* h_;
};

// The records and the views on them. Copying or moving it copies or moves the records; the views
// always look at the records of the object they belong to.
struct HotArrays {
  std::vector<HotRecord> hot_;
  HotField<Vec3, &HotRecord::r> r{&hot_};  // position at t[i] (wrapped into the box at events)
  HotField<Vec3, &HotRecord::v> v{&hot_};  // velocity
  HotField<Quat, &HotRecord::q> q{&hot_};  // orientation body -> lab at t[i]
  HotField<Vec3, &HotRecord::w> w{&hot_};  // angular velocity (lab frame)
  HotField<double, &HotRecord::t> t{&hot_};  // time stamp of the stored state
  HotArrays() = default;
  HotArrays(const HotArrays& o) : hot_(o.hot_) {}
  HotArrays(HotArrays&& o) noexcept : hot_(std::move(o.hot_)) {}
  HotArrays& operator=(const HotArrays& o) { hot_ = o.hot_; return *this; }
  HotArrays& operator=(HotArrays&& o) noexcept { hot_ = std::move(o.hot_); return *this; }
};

struct State : HotArrays {
  std::vector<std::uint32_t> count;   // number of velocity changes (event counter)
  std::vector<Eigen::Vector3i> image; // periodic images crossed (for unwrapped positions)
  std::vector<std::uint16_t> species; // index into the run's species table (core/species.hpp)
  std::vector<double> scale;          // size scale of the body (1 unless polydisperse)
  // Per species: the principal moments that govern the free rotation (BodyState::top). Empty,
  // or equal moments: spherical tops (w constant). Set by the pair model (prepare()).
  std::vector<Vec3> tops;

  std::size_t size() const { return r.size(); }

 private:
  struct RotationCache {
    Quat q = Quat::Identity();
    Vec3 w = Vec3::Zero();
    bool valid = false;
    FreeRotation rot;
  };
  mutable std::vector<RotationCache> rot_cache_;  // per body, for tops only (free_rotation)

 public:
  void resize(std::size_t n) {
    hot_.assign(n, HotRecord{});
    count.assign(n, 0);
    image.assign(n, Eigen::Vector3i::Zero());
    species.assign(n, 0);
    scale.assign(n, 1.0);
  }

  // Ask the memory system for body i's stored state ahead of its use (a hint, no effect on any
  // result): the prediction loop touches neighbours' records from all over the box, and each
  // contact-time solve is long enough to hide the next one's cache misses.
  [[gnu::always_inline]] void prefetch(std::size_t i) const {
    const char* p = reinterpret_cast<const char*>(&hot_[i]);
    __builtin_prefetch(p);
    __builtin_prefetch(p + 64);
  }
  // Position of body i at time `now` (no state change).
  Vec3 position_at(std::size_t i, double now) const { return r[i] + v[i] * (now - t[i]); }
  Vec3 top(std::size_t i) const { return tops.empty() ? Vec3::Zero() : tops[species[i]]; }
  // The exact free rotation of body i (a top that is not spherical) from its stored q and w, set
  // up once and kept until q or w change: a pure function of them, so no result depends on when
  // it was set up (checkpoints resume bit for bit).
  const FreeRotation& free_rotation(std::size_t i) const {
    if (rot_cache_.size() != r.size()) rot_cache_.assign(r.size(), RotationCache{});
    RotationCache& c = rot_cache_[i];
    if (!c.valid || c.q.coeffs() != q[i].coeffs() || c.w != w[i]) {
      c.rot = FreeRotation::make(top(i), q[i], w[i]);
      c.q = q[i], c.w = w[i], c.valid = true;
    }
    return c.rot;
  }
  BodyState body(std::size_t i) const {
    BodyState b{r[i], q[i], v[i], w[i], top(i)};
    if (!spherical_top(b.top)) b.rot = &free_rotation(i);
    return b;
  }
  BodyState body_at(std::size_t i, double now) const {
    BodyState b = body(i);
    advance(b, now - t[i]);
    return b;
  }
  // Stream body i forward to `now`.
  void advance_to(std::size_t i, double now) {
    const double dt = now - t[i];
    if (dt != 0.0) {
      r[i] += v[i] * dt;
      if (w[i].squaredNorm() != 0.0) {
        const Vec3 I = top(i);
        if (spherical_top(I)) q[i] = orientation_at(BodyState{r[i], q[i], v[i], w[i]}, dt);
        else free_rotation(i).evaluate(dt, q[i], w[i]);
      }
      t[i] = now;
    }
  }
};

}  // namespace hb
