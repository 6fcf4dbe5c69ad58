// The event loop: the one place that wires the state, the event calendar, the neighbour
// method and the pair dynamics together.
//
// `Model` supplies the physics of a pair:
//   void contact_times(const State&, const Box&, i, const uint32_t* js, const Vec3* shifts,
//                      size_t n, double now, const double* horizons, double* out)
//       times from now (or +inf) of body i against bodies js; body j is placed at r_j + shift
//       when shifts is non-null, else at its minimum image (Box::near_image). Models with
//       kWindowed = true may report as +inf a contact with js[k] after the absolute time
//       horizons[k], and one later than a contact already found for an earlier candidate.
//       The loop sets horizons[k] = min(t_n, t_k): t_n body i's next neighbour event (where i
//       is re-predicted in full), t_k the time of the event in partner k's calendar slot. At
//       t_k the partner is re-predicted in full whatever that event turns out to be (a
//       collision, a stale collision, a neighbour event), and then it finds the contact with i
//       if there is one: a pair's contact later than either body's next event is never needed.
//       Non-windowed models get horizons = nullptr and predict without limit.
//   CollisionRecord collide(State&, const Box&, i, j, double now)     // both bodies at `now`
//   double interaction_range() const                                  // max centre distance at contact
//   void visit_body(const State&, i, double now, F f)
//       calls f(shape, MassProperties, BodyGrowth, law_end) with body i's shape (concrete type),
//       mass, growth at `now` and the time its growth law changes: what the single-body event
//       sources need (BodyEvents, only when they are active).
// `Neighbors` (CellNeighbors, ShellNeighbors) supplies the candidates of a body and its own
// event (cell crossing, list rebuild); see neighbors/.
// `BodyEvents` (system/body_events.hpp) holds the event sources of single bodies: hard walls.
//
// Each body owns one slot of the calendar holding its earliest event over all sources (pair
// collision, single-body event, neighbour event); a collision event is checked against the
// partner's counter when it comes up (lazy invalidation); a single-body event depends on its
// owner alone, whose every change re-predicts it.
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "collision/record.hpp"
#include "events/calendar_queue.hpp"
#include "events/event.hpp"
#include "events/queue.hpp"
#include "system/body_events.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

// Everything beyond the State that the event loop needs to continue exactly where it was:
// the calendar (each body's slot) and each body's remembered best collision. Together with the
// State (positions at their own time stamps, counters) and the neighbour structure's own
// snapshot, restoring it continues the run bit for bit.
struct LoopSnapshot {
  double now = 0.0;
  std::vector<Event> slot, best;
  std::array<std::uint64_t, kEventTypes> counts{};
  std::uint64_t stale = 0;
  std::uint64_t rescheduled = 0;
  // The pair model's memory between solves, if it has one (the rigid models' AxisMemo rows,
  // contact/axis_memo.hpp): it steers the solvers' paths, so a bit-for-bit resume needs it.
  std::vector<std::array<double, 4>> memo;
};

// The pair model's memo for a LoopSnapshot (empty if the model keeps none), and back.
template <class Model>
std::vector<std::array<double, 4>> model_memo(const Model& m) {
  if constexpr (requires { m.memo.rows(); }) return m.memo.rows();
  else return {};
}
template <class Model>
void restore_model_memo(Model& m, const std::vector<std::array<double, 4>>& rows) {
  if constexpr (requires { m.memo.restore(rows); }) m.memo.restore(rows);
  else if (!rows.empty()) throw std::invalid_argument("snapshot has a solver memo this model does not keep");
}

struct StepInfo {
  EventType type = EventType::None;  // None: the time limit was reached
  bool stale = false;                // the event was invalid and only triggered a re-prediction
  CollisionRecord record;            // filled for real collisions
};

// The pair model tells the State what it needs to stream its bodies (the kind of top of each
// species, State::tops) when it has a prepare(State&).
template <class Model>
void prepare_state(const Model& m, State& s) {
  if constexpr (requires { m.prepare(s); }) m.prepare(s);
}

// Queue: CalendarQueue by default (O(1) for events beyond the current time bucket; at N = 256000
// ellipsoids 2 % faster than IndexedHeap, the same at N = 256); IndexedHeap and BruteQueue pop
// in the same order, so any of them runs the same trajectory.
template <class Model, class Neighbors, class Queue = CalendarQueue>
class Simulation {
 public:
  using neighbors_type = Neighbors;
  using model_type = Model;

  Simulation(const Box& box, State state, Model model, Neighbors neighbors, double now = 0.0,
             BodyEvents events = {})
      : box_(box), state_(std::move(state)), model_(std::move(model)),
        nb_(std::move(neighbors)), events_(std::move(events)), now_(now) {
    prepare_state(model_, state_);
    check_body_events();
    const std::size_t n = state_.size();
    if (n == 0) throw std::invalid_argument("no particles");
    events_.prepare(n, now_);
    nb_.init(box_, state_, now_);
    queue_.reset(static_cast<std::uint32_t>(n));
    best_.assign(n, Event{});
    for (std::uint32_t i = 0; i < n; ++i) predict(i);
    tune_queue();
  }

  // Continue from a snapshot (no re-prediction, no streaming: bit-for-bit continuation).
  // `neighbors` must have been restored to the same moment (see the neighbour classes).
  Simulation(const Box& box, State state, Model model, Neighbors neighbors, const LoopSnapshot& snap,
             BodyEvents events = {})
      : box_(box), state_(std::move(state)), model_(std::move(model)), nb_(std::move(neighbors)),
        events_(std::move(events)), now_(snap.now), best_(snap.best), counts_(snap.counts),
        stale_(snap.stale), rescheduled_(snap.rescheduled) {
    prepare_state(model_, state_);
    check_body_events();
    const std::size_t n = state_.size();
    if (snap.slot.size() != n || snap.best.size() != n)
      throw std::invalid_argument("snapshot does not match the number of bodies");
    queue_.reset(static_cast<std::uint32_t>(n));
    for (const Event& e : snap.slot) queue_.set(e);
    tune_queue();
    restore_model_memo(model_, snap.memo);
  }
  // with_memo = false leaves the model's memo out (a checkpoint streams it from the model).
  LoopSnapshot snapshot(bool with_memo = true) const {
    LoopSnapshot s;
    s.now = now_;
    s.slot.resize(state_.size());
    for (std::uint32_t i = 0; i < state_.size(); ++i) s.slot[i] = queue_.event_of(i);
    s.best = best_;
    s.counts = counts_;
    s.stale = stale_;
    s.rescheduled = rescheduled_;
    if (with_memo) s.memo = model_memo(model_);
    return s;
  }

  double now() const { return now_; }
  const Box& box() const { return box_; }
  const State& state() const { return state_; }
  const Model& model() const { return model_; }
  Model& model() { return model_; }
  const Neighbors& neighbors() const { return nb_; }
  // For settings between events that leave the lists valid (e.g. the slow twins' switches).
  Neighbors& neighbors() { return nb_; }
  const BodyEvents& body_events() const { return events_; }
  const std::array<std::uint64_t, kEventTypes>& event_counts() const { return counts_; }
  std::uint64_t stale_events() const { return stale_; }
  // Collisions whose re-prediction just before running them found the contact moved (later, or
  // gone): they were rescheduled instead of run (set_recheck).
  std::uint64_t rescheduled_events() const { return rescheduled_; }
  // Re-check (on by default, as DynamO): before a collision runs, the pair's contact time is
  // predicted again from the current state; a contact more than the model's recheck tolerance
  // (Model::recheck_tolerance(), default 1e-9 time units) from now is rescheduled. It guards
  // against predictions that come up early (a stale or faulty prediction); a healthy run's
  // re-predictions are within the tolerance, so re-check changes no trajectory. Rigid models
  // (kRecheckInCollide) make the same check on the gap their collision's distance solve finds
  // (the gap the pair can close within the tolerance; rigid_bodies.hpp recheck_moved).
  void set_recheck(bool on) { recheck_ = on; }
  bool recheck() const { return recheck_; }
  // After a collision of i and j, i's prediction leaves j out (predict's `skip`); false: both
  // predict the pair (the slow twin of the tests).
  void set_skip_partner(bool on) { skip_partner_ = on; }
  std::uint64_t collisions() const { return counts_[static_cast<int>(EventType::Collision)]; }
  double next_event_time() const { return queue_.top().time; }

  // Process the next event if it happens no later than t_limit; otherwise move the clock to
  // t_limit and return type None.
  StepInfo step(double t_limit) {
    StepInfo info;
    const Event ev = queue_.top();
    if (!(ev.time <= t_limit)) {
      now_ = t_limit;
      return info;
    }
    now_ = ev.time;
    info.type = ev.type;
    prefetch_next_event();
    const std::uint32_t i = ev.owner;
    if (ev.type == EventType::Collision) {
      const std::uint32_t j = ev.partner;
      if (state_.count[j] != ev.partner_count) {  // partner moved differently since
        info.stale = true;
        ++stale_;
        predict(i);
        return info;
      }
      prefetch_neighbors(i);  // read when both are predicted after the impulse
      prefetch_neighbors(j);
      state_.advance_to(i, now_);
      state_.advance_to(j, now_);
      bool moved;
      if constexpr (requires { Model::kRecheckInCollide; }) {
        // the model checks the contact on the distance its collision computes anyway
        info.record = model_.collide(state_, box_, i, j, now_, recheck_ ? recheck_tolerance() : -1.0);
        moved = info.record.moved;
      } else {
        moved = recheck_ && !contact_now(i, j);
        if (!moved) info.record = model_.collide(state_, box_, i, j, now_);
      }
      if (moved) {  // the contact moved: predict i again
        info.record = CollisionRecord{};
        info.stale = true;
        ++rescheduled_;
        if (++reschedule_streak_ > 1000)
          throw std::runtime_error("re-check: more than 1000 collisions in a row moved when re-predicted "
                                   "(bodies " + std::to_string(i) + ", " + std::to_string(j) + ")");
        predict(i);
        return info;
      }
      reschedule_streak_ = 0;
      info.record.time = now_;
      // Guard against an endless sequence of collisions at one instant (a solver/impulse
      // inconsistency): fail loudly instead of hanging.
      if (now_ == last_collision_time_) {
        if (++same_time_collisions_ > 100000)
          throw std::runtime_error("more than 100000 collisions at the same instant t = " +
                                   std::to_string(now_) + " (bodies " + std::to_string(i) +
                                   ", " + std::to_string(j) + ")");
      } else {
        last_collision_time_ = now_;
        same_time_collisions_ = 0;
      }
      ++state_.count[i];
      ++state_.count[j];
      ++counts_[static_cast<int>(EventType::Collision)];
      predict(i, skip_partner_ ? j : kNoSkip);  // the pair itself is j's to predict, right below
      predict(j);
      return info;
    }
    if (ev.type == EventType::Wall || ev.type == EventType::Thermostat) {
      state_.advance_to(i, now_);
      if constexpr (with_bodies()) info.record = events_.run(model_, state_, box_, ev, now_);
      ++state_.count[i];
      ++counts_[static_cast<int>(ev.type)];
      predict(i);
      return info;
    }
    if (ev.type != Neighbors::kEventType) throw std::logic_error("unexpected event type");
    ++counts_[static_cast<int>(ev.type)];
    state_.advance_to(i, now_);
    cand_.clear();
    shift_.clear();
    const bool partial = nb_.handle(i, ev, state_, box_, collect()) && !windowed();
    // The trajectory is unchanged: if the remembered best event is still valid (a collision
    // whose partner has not changed, or a single-body event), only the new candidates need
    // predicting.
    const Event& b = best_[i];
    if (partial && (b.type != EventType::Collision || state_.count[b.partner] == b.partner_count)) {
      Event best = b;
      consider(i, best);
      schedule(i, best);
    } else {
      predict(i);
    }
    return info;
  }

  // Switch the thermostat on or off (an equilibration-only thermostat at the start of the
  // measured stretch): every body is predicted again.
  void set_thermostat(bool on) {
    if (events_.thermostat().on() == on) return;
    events_.thermostat().set_on(on);
    for (std::uint32_t i = 0; i < state_.size(); ++i) predict(i);
  }

  // Stream every body to the current time (for output; does not change any trajectory).
  void synchronize() {
    for (std::uint32_t i = 0; i < state_.size(); ++i) state_.advance_to(i, now_);
  }

 private:
  // Models that describe single bodies (visit_body) can meet the single-body event sources.
  static constexpr bool with_bodies() { return requires { Model::kBodyEvents; }; }
  void check_body_events() const {
    if (events_.active() && !with_bodies())
      throw std::invalid_argument("this pair model cannot meet walls (no visit_body)");
  }
  // A model with a memo between solves (rigid models: AxisMemo) remembers what each solve
  // found, and which candidates a prediction solves, and with what window, depends on the order
  // it meets them (the windows shrink to the earliest contact found so far). That order comes
  // from the neighbour structure's history (list swaps, cell insertions), which a restored
  // structure does not repeat. In index order, the memo, and so every later solve, is the same
  // after a resume.
  static constexpr bool keeps_memo() { return requires(const Model& m) { m.memo.rows(); }; }
  // Candidates (and their image shifts) sorted by index, images of one body kept in their order:
  // an insertion sort (a few tens of candidates; neighbour lists come sorted already,
  // AdjacencyLists, and then it only checks).
  void in_index_order() {
    for (std::size_t k = 1; k < cand_.size(); ++k) {
      const std::uint32_t j = cand_[k];
      if (!(j < cand_[k - 1])) continue;
      const Vec3 sh = shift_[k];
      std::size_t m = k;
      for (; m > 0 && j < cand_[m - 1]; --m) cand_[m] = cand_[m - 1], shift_[m] = shift_[m - 1];
      cand_[m] = j, shift_[m] = sh;
    }
  }
  static constexpr bool windowed() {
    if constexpr (requires { Model::kWindowed; }) return Model::kWindowed;
    else return false;
  }
  auto collect() {
    return [this](std::uint32_t j, const Vec3& shift) {
      // windowed models read each candidate's calendar entry for its horizon (consider), after
      // the owner's neighbour event is computed: ask for it now
      if constexpr (windowed() && requires { queue_.prefetch(j); }) queue_.prefetch(j);
      state_.prefetch(j);
      cand_.push_back(j);
      shift_.push_back(shift);
    };
  }
  // A calendar (CalendarQueue) starts with buckets of width 1, a guess: with every event
  // within the first time unit, all N sat in its sorted heap and nothing re-tuned the width
  // before that unit had passed (ellipsoids, N = 256000, phi = 0.5: a heap of 256000 for the
  // whole benchmark; docs/benchmarks/README.md, "Second session of 2026-12-08"). Once every
  // slot is set, the width is judged from the events' times. The pops, and so the trajectory,
  // do not depend on it.
  void tune_queue() {
    if constexpr (requires { queue_.tune(now_); }) queue_.tune(now_);
  }
  // Hints for the event after this one (if the queue can tell which it will be): its slot, its
  // bodies' records, counter, box, list and memo. At large N each is a cache miss, and they came
  // one after another when the event was run (the slot, then the partner's counter, then the
  // records, then the lists); asked for a whole event ahead, they are at hand (measured at
  // N = 256000 ellipsoids: -6 % a collision; N = 256 unchanged; docs/benchmarks/README.md,
  // "Second session of 2026-12-08").
  [[gnu::always_inline]] void prefetch_next_event() const {
    if constexpr (requires(std::uint32_t a, std::uint32_t b) { queue_.next_event(a, b); }) {
      std::uint32_t k, p;
      if (!queue_.next_event(k, p)) return;
      queue_.prefetch(k);
      state_.prefetch(k);
      prefetch_neighbors(k);
      if (p == k) return;
      state_.prefetch(p);
      __builtin_prefetch(&state_.count[p]);
      prefetch_neighbors(p);
    }
  }
  // Hints for a body about to be predicted: its neighbour policy's records (ObbNeighbors: box
  // and list), if the policy offers them, and its slots of the model's memo, if it keeps one.
  // Every hint function is always_inline: GCC 12 counts __builtin_prefetch as free of side
  // effects, so a const function made of prefetches alone is found pure (ipa-pure-const) and
  // its call deleted as dead code before the inliner reaches it. That had silently deleted
  // ObbNeighbors::prefetch here (never executed), and AxisMemo::prefetch whenever the code
  // around it changed shape (its hint is worth ~10 % at N = 256000); inlined first, the
  // prefetches stay (docs/benchmarks/README.md, "Session of 2026-12-08").
  [[gnu::always_inline]] void prefetch_neighbors(std::uint32_t i) const {
    if constexpr (requires { nb_.prefetch(i); }) nb_.prefetch(i);
    if constexpr (requires { model_.memo.prefetch(i); }) model_.memo.prefetch(i);  // AxisMemo
  }
  // Is the pair (i, j), both streamed to now, in contact now? Its contact time from the current
  // state is within the tolerance (the search looks no further than twice the tolerance). Models
  // with kRecheckInCollide (the rigid ones) check the gap in their collide() instead: a contact
  // time search at contact costs them ~4 pair predictions, the gap nothing extra.
  double recheck_tolerance() const {
    if constexpr (requires { model_.recheck_tolerance(); }) return model_.recheck_tolerance();
    return 1e-9;
  }
  bool contact_now(std::uint32_t i, std::uint32_t j) {
    double dt = kInf;
    const double tol = recheck_tolerance();
    const double horizon = now_ + 2.0 * tol;
    model_.contact_times(state_, box_, i, &j, nullptr, 1, now_, &horizon, &dt);
    return dt <= tol;
  }
  // Predict body i against the candidates in cand_ and keep the earliest in `best`.
  void consider(std::uint32_t i, Event& best, double horizon = kInf) {
    if constexpr (keeps_memo()) in_index_order();
    const std::size_t n = cand_.size();
    if (times_.size() < n) times_.resize(2 * n), limits_.resize(2 * n);
    const double* limits = nullptr;
    if constexpr (windowed()) {
      for (std::size_t k = 0; k < n; ++k)
        limits_[k] = std::min(horizon, queue_.event_of(cand_[k]).time);
      limits = limits_.data();
    }
    model_.contact_times(state_, box_, i, cand_.data(),
                         nb_.needs_minimum_image() ? nullptr : shift_.data(), n, now_, limits,
                         times_.data());
    std::size_t kbest = n;
    double tbest = best.time - now_;
    for (std::size_t k = 0; k < n; ++k)
      if (times_[k] < tbest) tbest = times_[k], kbest = k;
    if (kbest < n) {
      const std::uint32_t j = cand_[kbest];
      best.time = now_ + tbest;
      best.owner = i;
      best.partner = j;
      best.partner_count = state_.count[j];
      best.type = EventType::Collision;
    }
  }
  // Full prediction for body i: all its candidates, its single-body events and its next
  // neighbour event. Windowed models look only up to the neighbour event, where i is predicted
  // in full again; the others keep the best event for partial re-predictions (see step()).
  // `skip`: a candidate left out because it is predicted in full right after i, against i
  // among the others (the partner of a collision): its prediction finds the pair's next contact
  // and holds it in its own slot, so i's slot need not (a contact of the pair is needed only
  // before either body's next event, and the partner's prediction looks up to both). It spares
  // the solve of a pair that has just touched, the costliest kind (measured on ellipsoids at
  // phi = 0.5: 5.4 % of the solves, every one redone by the partner's prediction).
  void predict(std::uint32_t i, std::uint32_t skip = kNoSkip) {
    state_.advance_to(i, now_);
    Event best;
    best.owner = i;
    cand_.clear();
    shift_.clear();
    nb_.for_each_candidate(i, box_, collect());
    if (skip != kNoSkip) drop_candidate(skip);
    const Event ne = nb_.next_event(i, state_, now_);
    if constexpr (with_bodies())
      if (events_.active()) best = predict_body_events(i, windowed() ? ne.time : kInf);
    consider(i, best, std::min(ne.time, best.time));  // nothing after i's own next event is needed
    best_[i] = best;
    queue_.set(ne.time < best.time ? ne : best);
  }
  static constexpr std::uint32_t kNoSkip = 0xffffffffu;
  // Remove body j from the candidates (every image of it), keeping the others' order.
  void drop_candidate(std::uint32_t j) {
    std::size_t w = 0;
    for (std::size_t k = 0; k < cand_.size(); ++k)
      if (cand_[k] != j) cand_[w] = cand_[k], shift_[w] = shift_[k], ++w;
    cand_.resize(w);
    shift_.resize(w);
  }
  // Out of line: the pair loop of predict() keeps its registers (measured: inlined, the branch
  // cost the hard-sphere loop ~2 instructions per candidate).
  [[gnu::noinline]] Event predict_body_events(std::uint32_t i, double t_end) const {
    return events_.predict(model_, state_, box_, i, now_, t_end);
  }
  void schedule(std::uint32_t i, const Event& best) {
    best_[i] = best;
    const Event ne = nb_.next_event(i, state_, now_);
    queue_.set(ne.time < best.time ? ne : best);
  }

  Box box_;
  State state_;
  Model model_;
  Neighbors nb_;
  BodyEvents events_;
  double now_ = 0.0;
  Queue queue_;
  std::vector<Event> best_;          // each body's best predicted collision
  std::vector<std::uint32_t> cand_;  // candidate partners of the body being predicted
  std::vector<Vec3> shift_;          // their periodic image shifts
  std::vector<double> times_;        // their contact times
  std::vector<double> limits_;       // their prediction horizons (windowed models)
  std::array<std::uint64_t, kEventTypes> counts_{};
  std::uint64_t stale_ = 0;
  bool recheck_ = true;
  bool skip_partner_ = true;
  std::uint64_t rescheduled_ = 0, reschedule_streak_ = 0;
  double last_collision_time_ = -kInf;
  std::uint64_t same_time_collisions_ = 0;
};

}  // namespace hb
