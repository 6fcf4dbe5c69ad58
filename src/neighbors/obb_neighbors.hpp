// Oriented-bounding-box neighbour lists (the paper's NNL, section 3.3) as a neighbour policy of
// the event loop (system/simulation.hpp), with per-body rebuilds (DESIGN.md).
//
// Each body i has a box B_i fixed at its last rebuild: centre = the body's centre then, axes =
// the body's axes then (or both led along its flight, below), half-extents = the body's extents
// along its axes + shell (Delta_NNL).
// Bodies i and j are partners iff B_i and B_j overlap (15-axis SAT, geometry/obb.hpp, minimum
// image). Body i's neighbour event (Rebuild) is its escape time from B_i shrunk by a margin
// (contact/escape_time.hpp); at the event only B_i is rebuilt around the body's current pose
// and the lists that contain i are updated symmetrically (found through a cell list over box
// centres with cells at least twice the box circumradius wide, so overlapping boxes sit in
// adjacent cells). `handle` returns false: the loop predicts i against its whole new list.
//
// Why no collision is missed. While body i is inside B_i and body j inside B_j, the two bodies
// lie in B_i and B_j; if the boxes are disjoint, so are the bodies: they cannot touch. Body i
// stays inside B_i until its escape event (the escape time is never later than the first
// contact with the shrunken, hence with the real, box), where B_i is rebuilt before i can reach
// anything outside its old box; the same for j. So a pair that is not listed cannot touch before
// one of them rebuilds, and at that rebuild the pair is re-tested. A listed pair is predicted by
// the loop (with the pair model's window ending at the owner's next rebuild, RigidBodies::
// kWindowed); a contact after that window is found when the owner re-predicts at its rebuild.
// A new partner j of i needs no re-prediction of j: the contact of i and j is found from i's
// side (contact times are symmetric), and j's next collision or rebuild re-predicts j in full.
//
// Boxes led along the flight. Nothing above needs B_i centred on the body: only that the body is
// inside B_i from the rebuild to its escape event. So at a rebuild the body gets the box of the
// pose free flight gives it after a lead tau (centre r + v tau along the periodic axes, axes of
// its orientation then), provided it stands at least margin + 0.1 (shell - margin) inside every
// face of that box now (clearance: its exact support values). It then crosses the box instead
// of leaving it from the middle: in a dilute fluid up to twice the time between rebuilds. tau:
// a trial of one shell's travel, shell / |v|, then the secant of the clearance (shell at tau =
// 0, falling about linearly) to the aim, halved up to three times if that is short; else the
// centred box. The aim is 0.2 (shell - margin) of room behind the body when it ran free since
// its last rebuild (the vector from it to its box centre is parallel to v: no collision turned
// v), and 0.6 after a collision: a body that bounces back in a cage would find a rear face at
// 0.2 near (in the dense e1, aim 0.2 after collisions measured +2 % per collision, 0.6 none;
// docs/benchmarks). Decided from the state and the boxes alone, so a restored checkpoint
// decides the same way. The centre is wrapped into [0, L) on its own, so the escape search
// takes the box's image nearest to the body (box_near). set_lead(false): every box centred,
// the paper's (the slow twin).
//
// Escape search: the box is shrunk by margin = min(0.01 inscribed radius, shell / 4) and the
// grazing step is eps = margin (paper: epsilon_d^nnl ~ 1e-2 b), so a grazing exit that the
// search misses leaves the body inside the real box. When no exit is found within the search
// window (window_end: a quarter of the circumradius' flight at the body's speed bound K, cut at
// twice its mean time between collisions; a spinning body may never leave), the body is
// predicted anew at the window's end and keeps its box (with set_short_windows(false): 8
// circumradii' flight and a rebuild there; harmless either way, a rebuild at any time is valid,
// and so is a new prediction). For the
// same reason the root of the exit face is not refined to a few ulps: its bracket stops once the
// body is within margin / 10 of the shrunken face (FirstRootOptions::value_tol), a rebuild at
// most that distance's travel early (measured: 10 % of a superquadric collision at phi = 0.256).
//
// Mixtures (ObbNeighbors<AnyShape>): body i is the shape of its species resized by its scale
// (State::species, State::scale; shapes/registry.hpp `resized`). Its box extents, escape margin
// and speed bound are those of that body; the cell list over box centres is sized by the largest
// box (every species at its largest scale), so overlapping boxes still sit in adjacent cells.
//
// Positions: at its rebuild the body's stored position is wrapped into the periodic box (image
// counter updated), so the box centres lie in [0, L); list entries are ids and the pair code
// uses the near image (needs_minimum_image() is true). The minimum-image SAT is exact when every
// box side L_k > 4 * circumradius (at most one image can overlap); with at least 3 cells per axis
// this always holds.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "contact/escape_time.hpp"
#include "events/event.hpp"
#include "geometry/obb.hpp"
#include "geometry/segment.hpp"
#include "neighbors/cell_list.hpp"
#include "neighbors/cell_members.hpp"
#include "neighbors/shell_neighbors.hpp"
#include "shapes/registry.hpp"
#include "shapes/shape.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

// The boxes of every body, for checkpoints: centre, the body orientation at the rebuild (the
// box axes are its rotation matrix, so restoring gives bit-identical axes) and half-extents.
struct ObbSnapshot {
  std::vector<Vec3> centre;
  std::vector<Quat> q;
  std::vector<Vec3> half;
};

// The shapes ObbNeighbors works with: one support shape for every body, or AnyShape (a mixture).
template <class S>
concept ObbBodyShape = SupportShape<S> || std::is_same_v<S, AnyShape>;

// Extents of a shape along its own axes (the half-extents of the smallest body-aligned box
// around it; the max with the support values guards shapes whose half_extents are loose).
template <SupportShape S>
Vec3 obb_extents(const S& shape) {
  Vec3 ext;
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = Vec3::Unit(k);
    ext[k] = std::max({shape.half_extents()[k], shape.support(e), shape.support(Vec3(-e))});
  }
  return ext;
}

template <ObbBodyShape S>
class ObbNeighbors {
  static constexpr bool kMixture = std::is_same_v<S, AnyShape>;

 public:
  static constexpr EventType kEventType = EventType::Rebuild;

  // Every body has `shape`.
  ObbNeighbors(const S& shape, double shell)
    requires(!kMixture)
      : shape_(shape), shell_(shell) {
    check_shell(shell);
    ext_ = obb_extents(shape);
    margin_ = body_margin(shape.inscribed_radius());
    eps_ = margin_;
    rc_ = (ext_.array() + shell_).matrix().norm();
    kbound_l_ = shape.bounding_radius();
    capsules_ = elongated(Vec3(ext_.array() + shell_));
    boxes_ = anisotropic(Vec3(ext_.array() + shell_));
    core_ = obb_core(Vec3(ext_.array() + shell_));
  }
  // A mixture: body i is species_shapes[species_i] resized by scale_i <= max_scale[species_i].
  ObbNeighbors(const std::vector<AnyShape>& species_shapes, const std::vector<double>& max_scale,
               double shell)
    requires kMixture
      : shell_(shell) {
    check_shell(shell);
    if (species_shapes.empty() || species_shapes.size() != max_scale.size())
      throw std::invalid_argument("ObbNeighbors: one shape and one largest scale per species");
    for (std::size_t k = 0; k < species_shapes.size(); ++k) {
      Kind kind{species_shapes[k], Vec3::Zero(), inscribed_radius(species_shapes[k]),
                bounding_radius(species_shapes[k])};
      kind.ext = std::visit([](const auto& x) { return obb_extents(x); }, species_shapes[k]);
      kinds_.push_back(kind);
      rc_ = std::max(rc_, (kind.ext.array() * max_scale[k] + shell_).matrix().norm());
      capsules_ = capsules_ || elongated(Vec3(kind.ext.array() + shell_));
      boxes_ = boxes_ || anisotropic(Vec3(kind.ext.array() + shell_));
    }
  }

  void init(const Box& box, State& s, double now) {
    setup(box, s.size());
    for (std::uint32_t i = 0; i < s.size(); ++i) {
      s.advance_to(i, now);
      s.image[i] += box.wrap(s.r[i]);
      set_box(i, s.r[i], s.q[i], half_extents_of(s, i));
      place(i);
    }
    build_all(box);
  }

  ObbSnapshot snapshot() const {
    ObbSnapshot sn;
    sn.centre.resize(obb_.size());
    sn.half.resize(obb_.size());
    sn.q = q_;
    for (std::size_t i = 0; i < obb_.size(); ++i) {
      sn.centre[i] = obb_[i].centre;
      sn.half[i] = obb_[i].half;
    }
    return sn;
  }
  void restore(const Box& box, const State& s, const ObbSnapshot& sn) {
    const std::size_t n = s.size();
    if (sn.centre.size() != n || sn.q.size() != n || sn.half.size() != n)
      throw std::invalid_argument("neighbour-list snapshot does not match the number of bodies");
    setup(box, n);
    for (std::uint32_t i = 0; i < n; ++i) {
      set_box(i, sn.centre[i], sn.q[i], sn.half[i]);
      place(i);
    }
    build_all(box);
  }

  const AdjacencyLists& lists() const { return lists_; }
  const Obb& box_of(std::uint32_t i) const { return obb_[i]; }
  double shell() const { return shell_; }
  double margin() const { return margin_; }
  double circumradius() const { return rc_; }
  std::uint64_t rebuilds() const { return rebuilds_; }
  std::uint64_t window_ends() const { return window_ends_; }  // window ends without a rebuild
  std::uint64_t truncated_searches() const { return truncated_; }
  bool needs_minimum_image() const { return true; }
  // Body i's box at the periodic image nearest to the point r (a led box's centre is wrapped
  // on its own, so it may lie across the periodic boundary from its body).
  Obb box_near(std::uint32_t i, const Vec3& r) const {
    Obb b = obb_[i];
    const Vec3 d = b.centre - r;
    b.centre += pbox_.near_image(d) - d;  // whole periods: the same bits when none
    return b;
  }
  // The escape search's window (next_event): [now, now + f rc / K], rc the box's circumradius
  // and K the body's speed bound. The window's end is also the body's horizon: its pair
  // predictions look no further (Simulation::predict), so a shorter window makes cheaper pair
  // searches (fewer axis steps) and escape searches, at the cost of more events. Where the
  // body is still inside its box at the window's end, the box stays and the body is predicted
  // anew from there (no rebuild, no cell walk, no list update).
  // On (the default): f = 1/4, no rebuild at the window's end. Off: f = 8 and a rebuild there,
  // the earlier rule (the slow twin of the tests).
  // Measured (callgrind, instructions a collision, docs/benchmarks/README.md, "Session of
  // 2026-12-05, sixth part"), off -> on: ellipsoids X0 = 2 at phi = 0.5, N = 256 (e1) 106.1k
  // -> 97.4k; at phi = 0.3 142.7k -> 140.1k; X0 = 1 and 10 at phi = 0.4 -2.2 % and -0.4 %;
  // superquadrics (2, 2, 8) at phi = 0.256 -2.6 %, (2, 2, 2) +1.2 %. f = 1/8 gains more at
  // phi = 0.5 (92.3k) but loses 10 % at phi = 0.3 and X0 = 1 (the window ends too often).
  void set_short_windows(bool on) { short_windows_ = on; }
  bool short_windows() const { return short_windows_; }
  double window() const { return short_windows_ ? 0.25 : 8.0; }
  // With short windows, body i's window is also cut at c tau_i (c = 2 by default,
  // set_mean_free_cap(c); 0: off), tau_i = now / count_i its mean time between velocity changes
  // since time 0 (State::count: collisions, bounces), but never below 1/32 of the window above:
  // a caged body changes course long before it could cross its box, so its pair searches need
  // not look that far (fewer axis steps and escape steps). The cut is never longer than the
  // geometric window and never zero, so a state whose counts come from before time 0 (none: the
  // growth resets them, setup/growth.hpp) only ends windows early. Decided from the state alone:
  // a restored checkpoint cuts the same way. Measured (callgrind, instructions a collision,
  // docs/benchmarks/README.md, "Session of 2026-12-05, eighth part"), off -> on: e1 97.4k ->
  // 93.2k, X0 = 10 at phi = 0.4 115.2k -> 92.2k; phi = 0.3, X0 = 1, superquadrics p = 2 within
  // 0.5 %, p = 8 +1.3 %. Off: the geometric window only (the slow twin of the tests).
  void set_mean_free_cap(double c) {
    if (!(c >= 0.0)) throw std::invalid_argument("ObbNeighbors: the mean-free cap must be >= 0");
    mean_free_cap_ = c;
  }
  double mean_free_cap() const { return mean_free_cap_; }
  static constexpr double kMinWindowFraction = 1.0 / 32.0;
  // End of body i's escape-search window from `now`; reach: its box's circumradius, K: its
  // speed bound (> 0).
  double window_end(std::uint32_t i, const State& s, double now, double reach, double K) const {
    const double geometric = window() * reach / K;
    if (!(mean_free_cap_ > 0.0 && short_windows_ && s.count[i] > 0 && now > 0.0)) return now + geometric;
    const double tau = now / double(s.count[i]);
    return now + std::clamp(mean_free_cap_ * tau, kMinWindowFraction * geometric, geometric);
  }
  // Boxes led along the flight (on by default); off: every box centred on its body at its
  // rebuild, the paper's (the slow twin of the tests).
  void set_lead(bool on) { lead_ = on; }
  bool lead() const { return lead_; }
  std::uint64_t leads() const { return leads_; }  // rebuilds that led the box

  // A hint: body i's box and list, ahead of a prediction of i (system/simulation.hpp issues it
  // before a collision's impulse, whose distance solve hides the cache misses at large N).
  [[gnu::always_inline]] void prefetch(std::uint32_t i) const {
    const char* b = reinterpret_cast<const char*>(&obb_[i]);
    __builtin_prefetch(b);
    __builtin_prefetch(b + 64);
    lists_.prefetch(i);
  }

  template <class Fn>
  void for_each_candidate(std::uint32_t i, const Box&, Fn&& fn) const {
    static const Vec3 zero = Vec3::Zero();
    for (const std::uint32_t* p = lists_.begin(i); p != lists_.end(i); ++p) fn(*p, zero);
  }

  // Escape time of body i (stored at its own time, normally `now`) from its box.
  Event next_event(std::uint32_t i, const State& s, double now) const {
    Event e;
    e.owner = i;
    const BodyState b = s.body(i);
    if constexpr (kMixture) {
      const Kind& kind = kinds_[s.species[i]];
      const double sc = s.scale[i];
      const double K = b.v.norm() + b.w.norm() * kind.bound * sc;
      if (K == 0.0) return e;  // at rest: never leaves
      const double t_cap = window_end(i, s, now, obb_[i].half.norm(), K);
      const double margin = body_margin(kind.inscribed * sc);
      const AnyShape shape = sc == 1.0 ? kind.shape : resized(kind.shape, sc);
      return escape_event(e, now, t_cap, std::visit([&](const auto& x) {
        EscapeInput<std::decay_t<decltype(x)>> in{x, b, s.t[i], now, t_cap, box_near(i, b.r), margin, margin};
        in.revolution = revolution_;
        return escape_time(in, escape_options(margin));
      }, shape));
    } else {
      const double K = b.v.norm() + b.w.norm() * kbound_l_;
      if (K == 0.0) return e;  // at rest: never leaves
      const double t_cap = window_end(i, s, now, rc_, K);
      EscapeInput<S> in{shape_, b, s.t[i], now, t_cap, box_near(i, b.r), margin_, eps_};
      in.revolution = revolution_;
      return escape_event(e, now, t_cap, escape_time(in, escape_options(margin_)));
    }
  }

 private:
  // The neighbour event of an escape search `r` (window [now, t_cap]).
  Event escape_event(Event e, double now, double t_cap, const EscapeResult& r) const {
    if (r.truncated) ++truncated_;
    e.type = kEventType;
    switch (r.status) {
      case EscapeStatus::escapes:
        e.time = r.time;
        e.partner = static_cast<std::uint32_t>(r.face);
        break;
      case EscapeStatus::outside:
        e.time = now;
        e.partner = static_cast<std::uint32_t>(r.face);
        break;
      case EscapeStatus::inside:
        e.time = r.truncated ? r.time : t_cap;
        e.partner = kWindowEnd;
        break;
    }
    return e;
  }

 public:

  // Body i's neighbour event (body already streamed to the event time). At the end of a short
  // window, i still inside its box: nothing changes. Otherwise: rebuild i's box around its
  // current pose and update the lists it appears in. Returns false: predict i against its whole
  // list.
  template <class Fn>
  bool handle(std::uint32_t i, const Event& ev, State& s, const Box& box, Fn&&) {
    if (ev.partner == kWindowEnd && short_windows_) {  // still inside: keep the box, predict anew
      ++window_ends_;
      return false;
    }
    ++rebuilds_;
    s.image[i] += box.wrap(s.r[i]);
    members_.remove(cells_.cell_of(i), i);
    cells_.remove(i);
    set_lead_box(i, s, box, obb_[i].half);
    place(i);
    // i leaves its partners' lists: ask for them all before the first removal (each is a cache
    // miss at large N, and each removal's search would wait for its own)
    for (const std::uint32_t* p = lists_.begin(i); p != lists_.end(i); ++p) lists_.prefetch(*p);
    for (const std::uint32_t* p = lists_.begin(i); p != lists_.end(i); ++p) lists_.remove(*p, i);
    lists_.clear(i);
    link(i, box, [i](std::uint32_t j) { return j != i; });
    return false;
  }

  // Do the boxes of i and j overlap (d: j's centre at its image minus i's, link below)?
  [[gnu::always_inline]] bool overlap(std::uint32_t i, std::uint32_t j, const Vec3& d) const {
    if (d.squaredNorm() > 4.0 * rc_ * rc_) return false;  // circumspheres apart
    const Obb &a = obb_[i], &b = obb_[j];
    if (capsules_) {  // elongated boxes
      ObbCore ca = core_, cb = core_;  // one shape: every box's
      double ra = rc_, rb = rc_;
      if constexpr (kMixture) ca = obb_core(a.half), cb = obb_core(b.half), ra = a.half.norm(), rb = b.half.norm();
      // the capsules inside the boxes meet: the boxes overlap (most listed pairs)
      if (inner_ && obb_inner_capsules_meet(a, ca, b, cb, d)) return true;
      // the capsules around the long axes apart: first each capsule against the other's
      // circumsphere (obb_capsule_ball_apart), then the two capsules
      if (obb_capsule_ball_apart(a, ca, rb, d) || obb_capsule_ball_apart(b, cb, ra, Vec3(-d)) ||
          obb_capsules_apart(a, ca, b, cb, d))
        return false;
    }
    return obb_overlap(a, b, Vec3(d - (b.centre - a.centre)));
  }
  // The inner capsule test ahead of the capsule tests (on by default, with them: elongated
  // boxes): two boxes whose inner capsules meet (geometry/obb.hpp, obb_inner_capsules_meet)
  // overlap, and the 15-axis test, which must try all 15 axes to say so, is not run. Off: the
  // slow twin. The lists are the same either way (the test only finds boxes that overlap).
  // Measured (callgrind, instructions a collision, the same trajectories; docs/benchmarks/
  // README.md, "Session of 2026-12-07"): ellipsoids X0 = 2, phi = 0.5, N = 256 (e1) 88.9k ->
  // 87.7k (-1.4 %), X0 = 10 at phi = 0.4 -0.3 %. Boxes that are not elongated (where the inner
  // capsule is short or a ball) do not take it: there it cost superquadrics (2, 2, 2) and
  // (2, 2, 8) at phi = 0.256 +0.7 % and gained X0 = 1 at phi = 0.4 0.6 %.
  void set_inner_test(bool on) { inner_ = on; }
  bool inner_test() const { return inner_; }
  // The capsule tests ahead of obb_overlap (geometry/obb.hpp: obb_capsule_ball_apart both ways,
  // then obb_capsules_apart), on by default where some box is elongated; off: every pair within
  // reach goes to obb_overlap (the slow twin of the tests). The lists are the same either way
  // (the capsule tests only rule out disjoint boxes). Measured at X0 = 10, phi = 0.4 (calls per
  // rebuild; docs/benchmarks/README.md, "Session of 2026-12-01"): of the ~400 pairs within the
  // circumspheres' reach, the ball tests rule out ~206 and the two-capsule test ~170; ~24 go on
  // to the SAT.
  void set_capsule_test(bool on) { capsules_ = on; }
  bool capsule_test() const { return capsules_; }
  // The axis-aligned box test in link's walk (on by default for anisotropic boxes; off: the
  // circumspheres only, the slow twin). Off is safe at any time; on belongs before init:
  // bodies placed while it is off keep no box (their members hold inf, which the test passes),
  // so until their next rebuild they would not be ruled out (still correct, only slower).
  void set_box_test(bool on) { boxes_ = on; }
  bool box_test() const { return boxes_; }
  // Escape searches of bodies of revolution bounded by the spin across the axis (EscapeInput::
  // revolution; false: by |w|, the slow twin).
  void set_revolution_bounds(bool on) { revolution_ = on; }

 private:
  // A box is elongated when its longest half-extent exceeds the others by 20 % (the capsule
  // around its long axis is then narrower than its circumsphere by a useful margin).
  static bool elongated(const Vec3& h) {
    const CoreSegment c = core_segment(h);  // its long axis and the second largest extent
    return h[c.axis] > 1.2 * c.thick;
  }
  // A box is anisotropic when its longest half-extent exceeds its shortest by 20 %: aligned
  // bodies then have axis-aligned boxes thinner than their circumspheres along some axis
  // (link's box test, CellMembers::for_each_within_box).
  static bool anisotropic(const Vec3& h) { return h.maxCoeff() > 1.2 * h.minCoeff(); }
  static void check_shell(double shell) {
    if (!(shell > 0.0)) throw std::invalid_argument("neighbour-list shell must be positive");
  }
  // Escape margin and grazing step of a body of inscribed radius r_in (see the header).
  double body_margin(double r_in) const { return std::min(0.01 * r_in, 0.25 * shell_); }
  // The escape search stops refining a face's root once the body is within a fraction of the
  // margin of the shrunken face (see the header).
  static EscapeOptions escape_options(double margin) {
    EscapeOptions o;
    o.value_tol = 0.1 * margin;
    return o;
  }
  // Half-extents of body i's box: its extents at its scale plus the shell.
  Vec3 half_extents_of(const State& s, std::uint32_t i) const {
    if constexpr (kMixture) return Vec3(kinds_[s.species[i]].ext.array() * s.scale[i] + shell_);
    else return Vec3(ext_.array() + shell_);
  }

  void setup(const Box& box, std::size_t n) {
    pbox_ = box;
    const double reach = 2.0 * rc_;
    const double rho = double(n) / box.volume();
    const double expect = rho * 4.18879 * reach * reach * reach;  // centres within 2 rc
    lists_.init(n, static_cast<std::uint32_t>(std::min<double>(expect + 16, double(n))));
    cells_.init(box.L, reach, n, box.periodic, /*max_per_body=*/1.0);
    members_.init(cells_.n_cells(), n);
    obb_.assign(n, LineObb{});
    q_.assign(n, Quat::Identity());
  }
  // Body i's new box (see "Boxes led along the flight" in the header): the box of the pose
  // free flight gives the body after a lead tau, when the body ran free since its last rebuild
  // and then stands at least margin + kLeadNeed (shell - margin) inside every face; else the
  // box centred on the body (the paper's; and the slow twin, set_lead(false)).
  void set_lead_box(std::uint32_t i, const State& s, const Box& box, const Vec3& half) {
    const Vec3& v = s.v[i];
    if (lead_ && v.squaredNorm() > 0.0) {
      // ran free: the body moved along v since its box was built (led or centred), so the
      // body-to-centre vector is parallel to v; a collision in between turns v
      const Vec3 d = box_near(i, s.r[i]).centre - s.r[i];
      const bool ran_free = d.cross(v).squaredNorm() <= 1e-18 * d.squaredNorm() * v.squaredNorm();
      const double aim = ran_free ? kLeadAim : kLeadAimAfterCollision;
      const BodyState b = s.body(i);
      double margin;
      if constexpr (kMixture) margin = body_margin(kinds_[s.species[i]].inscribed * s.scale[i]);
      else margin = margin_;
      const double room = shell_ - margin;
      const Motion m(b);
      Obb cand;
      cand.half = half;
      Quat q;
      auto clearance_after = [&](double tau) {
        Vec3 w;
        m.pose(tau, q, w);
        cand.centre = b.r;
        for (int k = 0; k < 3; ++k)
          if (box.periodic[k]) cand.centre[k] += b.v[k] * tau;
        cand.axes = q.toRotationMatrix();
        if constexpr (kMixture) {
          const Kind& kind = kinds_[s.species[i]];
          const double sc = s.scale[i];
          const AnyShape shape = sc == 1.0 ? kind.shape : resized(kind.shape, sc);
          return std::visit([&](const auto& x) { return clearance(x, b.r, b.q, cand); }, shape);
        } else {
          return clearance(shape_, b.r, b.q, cand);
        }
      };
      // a trial lead of one shell's travel, then the secant to the aim: the clearance falls
      // from shell (no lead) about linearly with tau
      double tau = shell_ / std::sqrt(v.squaredNorm());
      double c = clearance_after(tau);
      if (c < shell_) {
        tau *= (shell_ - (margin + aim * room)) / (shell_ - c);
        c = clearance_after(tau);
      }
      for (int attempt = 0; attempt < 3 && c < margin + kLeadNeed * room; ++attempt) {
        tau *= 0.5;
        c = clearance_after(tau);
      }
      if (c >= margin + kLeadNeed * room) {
        ++leads_;
        box.wrap(cand.centre);
        q_[i] = q;
        obb_[i] = cand;
        return;
      }
    }
    set_box(i, s.r[i], s.q[i], half);
  }
  // The smallest distance of a body (centre r, orientation q) from the faces of box b, inside
  // (negative: through a face).
  template <SupportShape S2>
  static double clearance(const S2& sh, const Vec3& r, const Quat& q, const Obb& b) {
    const Mat3 Rn = q.toRotationMatrix().transpose() * b.axes;
    const Vec3 x = b.axes.transpose() * (r - b.centre);
    double c = kInf;
    for (int k = 0; k < 3; ++k) {
      const Vec3 n = Rn.col(k);
      const double hp = sh.support(n);
      double hm;
      if constexpr (CentrallySymmetric<S2>) hm = hp;
      else hm = sh.support(Vec3(-n));
      c = std::min({c, b.half[k] - x[k] - hp, b.half[k] + x[k] - hm});
    }
    return c;
  }
  void set_box(std::uint32_t i, const Vec3& centre, const Quat& q, const Vec3& half) {
    q_[i] = q;
    obb_[i].centre = centre;
    obb_[i].axes = q.toRotationMatrix();
    obb_[i].half = half;
  }
  // Body i into the cell of its box centre, with its axis-aligned box when the box test is on
  // (off: none, which isotropic boxes never read).
  void place(std::uint32_t i) {
    cells_.insert(i, obb_[i].centre);
    if (boxes_) members_.insert(cells_.cell_of(i), i, obb_[i].centre, aabb_half(obb_[i]));
    else members_.insert(cells_.cell_of(i), i, obb_[i].centre);
  }
  // Half-extents of the axis-aligned box around an oriented one: sum_m |A_km| half_m along
  // lab axis k (the box's corners' extreme coordinates).
  static Vec3 aabb_half(const Obb& b) { return b.axes.cwiseAbs() * b.half; }
  void build_all(const Box& box) {
    for (std::uint32_t i = 0; i < obb_.size(); ++i) link(i, box, [i](std::uint32_t j) { return j > i; });
  }
  // List i and j both ways for every j of the cell stencil with take(j) whose box overlaps i's.
  // Two passes: the cell walk gathers the candidates and asks for their boxes, then the overlap
  // tests read them. At large N the boxes of a cell's bodies lie all over memory; one pass waited
  // for each box before walking on (measured at N = 256000: 63 % of Simulation::step on that
  // load). The walk reads the cells' packed members (CellMembers): their single-precision
  // centres rule out, before any box is loaded, the ~85 % of the stencil's bodies whose
  // circumspheres are apart by more than the rounding (the exact test, overlap, decides the
  // rest). With single-cell axes (minimum image: small boxes, such as N ~ 1000 needles, where the
  // one cell holds every body) the test takes the nearest image of the separation (near_image;
  // where two images tie within rounding, both are as far, and the exact test takes its own);
  // it used to send every member to the exact test. The lists are sorted, so the order of the
  // candidates does not matter.
  template <class Take>
  void link(std::uint32_t i, const Box& box, Take take) {
    near_.clear();
    const Vec3 ci = obb_[i].centre;
    const bool image = cells_.needs_minimum_image();
    // the cut-off widened by the centres' rounding (for_each_within adds its own arithmetic's)
    const double reach = 2.0 * rc_ + members_.rounding_bound();
    // With single-cell axes, the nearest image of a separation (centres are kept inside the box,
    // so |x| < L along each axis): the walk folds each axis once (CellMembers::for_each_within,
    // P = kInf along an axis that is not periodic), and the exact test takes Box::near_image, one
    // compare each way per axis here (it used Box::minimum_image, three divisions).
    Vec3 fold = Vec3::Constant(kInf);  // the walk's periods
    if (image)
      for (int k = 0; k < 3; ++k)
        if (box.periodic[k]) fold[k] = box.L[k];
    // i's axis-aligned box, widened like the reach by the centres' rounding (boxes_ only)
    const Vec3 half =
        boxes_ ? Vec3(aabb_half(obb_[i]).array() + members_.rounding_bound()) : Vec3::Zero();
    // The stencil's cells first (at most 3 x 3 x 3), a hint for each cell's size and first
    // kWalkHintBlocks blocks of members (and their boxes), then the walk, cell by cell in the
    // same order. At large N every cell's blocks miss; walked as they came, one cell's loads
    // waited for the last's (measured at N = 256000: -8 % a collision with two blocks, a further
    // -5 % with four; docs/benchmarks/README.md, both sessions of 2026-12-08).
    std::uint32_t cells[27];
    Vec3 shifts[27];
    int n_cells = 0;
    cells_.for_each_stencil_cell(i, box.L, [&](std::uint32_t c, const Vec3& shift) {
      cells[n_cells] = c, shifts[n_cells] = shift, ++n_cells;
    });
    for (int k = 0; k < n_cells; ++k) members_.prefetch(cells[k], kWalkHintBlocks, boxes_);
    for (int k = 0; k < n_cells; ++k) {
      const std::uint32_t c = cells[k];
      const Vec3& shift = shifts[k];
      auto keep = [&](std::uint32_t j) {
        if (!take(j)) return;
        __builtin_prefetch(&obb_[j]);
        __builtin_prefetch(reinterpret_cast<const char*>(&obb_[j]) + 64);
        near_.push_back({j, shift});
      };
      // j's centre minus ci - shift: the centre separation
      if (boxes_) members_.for_each_within_box(c, Vec3(ci - shift), fold, reach, half, keep);
      else members_.for_each_within(c, Vec3(ci - shift), fold, reach, keep);
    }
    for (const auto& [j, shift] : near_) {
      const Vec3 d = obb_[j].centre + shift - ci;
      if (overlap(i, j, image ? box.near_image(d) : d)) lists_.add(i, j), lists_.add(j, i);
    }
  }

  static constexpr int kWalkHintBlocks = 4;  // link's hint: blocks of four members a cell
  // A species of a mixture at scale 1.
  struct Kind {
    AnyShape shape;
    Vec3 ext;          // extents along its axes
    double inscribed;  // inscribed radius
    double bound;      // bounding radius
  };

  S shape_{};                // one shape (not a mixture)
  std::vector<Kind> kinds_;  // a mixture's species
  double shell_;
  Box pbox_;
  bool lead_ = true;            // boxes led along the flight (set_lead)
  bool short_windows_ = true;   // set_short_windows
  double mean_free_cap_ = 2.0;  // c of set_mean_free_cap (0: off)
  std::uint64_t window_ends_ = 0;  // neighbour events at a window's end that kept the box
  static constexpr std::uint32_t kWindowEnd = 6;  // the partner of such an event (faces: 0-5)
  std::uint64_t leads_ = 0;     // rebuilds that led the box
  // the clearance the secant aims at (after a free run; after a collision) and the least it
  // accepts, in units of shell - margin
  static constexpr double kLeadAim = 0.2, kLeadAimAfterCollision = 0.6, kLeadNeed = 0.1;
  Vec3 ext_ = Vec3::Ones();  // body extents along its axes (max of half_extents and support)
  double margin_ = 0.0, eps_ = 0.0;
  double rc_ = 0.0;          // box circumradius (a mixture: the largest)
  double kbound_l_ = 0.0;    // bounding radius (speed bound of the body's points)
  CellList cells_;           // over box centres; changes only at rebuilds
  CellMembers members_;      // its cells' bodies, packed with their centres (link's walk)
  // A box on two whole cache lines (its 120 bytes padded to 128, aligned): the link's overlap
  // tests read the boxes of a rebuild's ~50 candidates from all over memory at large N, and an
  // unaligned box of 120 bytes straddled three lines in most slots.
  struct alignas(64) LineObb : Obb {
    LineObb& operator=(const Obb& b) {
      Obb::operator=(b);
      return *this;
    }
  };
  static_assert(sizeof(LineObb) == 128);
  std::vector<LineObb> obb_;
  std::vector<Quat> q_;
  std::vector<std::pair<std::uint32_t, Vec3>> near_;  // link's candidates (scratch)
  AdjacencyLists lists_;
  bool capsules_ = false;     // the capsule test ahead of obb_overlap (set_capsule_test)
  bool inner_ = true;         // the inner capsule test ahead of both (set_inner_test)
  bool revolution_ = true;    // set_revolution_bounds
  bool boxes_ = false;        // the axis-aligned box test in link's walk (set_box_test)
  ObbCore core_;             // one shape: every box's core (the capsule tests)
  std::uint64_t rebuilds_ = 0;
  mutable std::uint64_t truncated_ = 0;
};

}  // namespace hb
