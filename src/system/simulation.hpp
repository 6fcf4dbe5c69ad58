// The event loop: the one place that wires the state, the event calendar, the cell lists and the
// pair dynamics together. `Model` supplies the physics of a pair:
//   void contact_times(const State&, const Box&, i, const uint32_t* js, const Vec3* shifts,
//                      size_t n, bool min_image, double now, double* out)
//       times from now (or +inf) of body i against bodies js placed at their periodic image
//       r_j + shift (or at the minimum image when min_image is set)
//   CollisionRecord collide(State&, const Box&, i, j, double now)     // both bodies at `now`
//   double interaction_range() const                                  // max centre distance at contact
// Each body owns one slot of the calendar holding its earliest event; a collision event is
// checked against the partner's counter when it comes up (lazy invalidation).
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "collision/record.hpp"
#include "events/event.hpp"
#include "events/queue.hpp"
#include "neighbors/cell_list.hpp"
#include "system/box.hpp"
#include "system/state.hpp"

namespace hb {

struct StepInfo {
  EventType type = EventType::None;  // None: the time limit was reached
  bool stale = false;                // the event was invalid and only triggered a re-prediction
  CollisionRecord record;            // filled for real collisions
};

template <class Model, class Queue = IndexedHeap>
class Simulation {
 public:
  Simulation(const Box& box, State state, Model model, double now = 0.0)
      : box_(box), state_(std::move(state)), model_(std::move(model)), now_(now) {
    const std::size_t n = state_.size();
    if (n == 0) throw std::invalid_argument("no particles");
    cells_.init(box_.L, model_.interaction_range(), n);
    queue_.reset(static_cast<std::uint32_t>(n));
    best_.assign(n, Event{});
    for (std::uint32_t i = 0; i < n; ++i) {
      state_.advance_to(i, now_);
      state_.image[i] += box_.wrap(state_.r[i]);
      cells_.insert(i, state_.r[i]);
    }
    for (std::uint32_t i = 0; i < n; ++i) predict(i);
  }

  double now() const { return now_; }
  const Box& box() const { return box_; }
  const State& state() const { return state_; }
  const Model& model() const { return model_; }
  Model& model() { return model_; }
  const CellList& cells() const { return cells_; }
  const std::array<std::uint64_t, kEventTypes>& event_counts() const { return counts_; }
  std::uint64_t stale_events() const { return stale_; }
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
    const std::uint32_t i = ev.owner;
    switch (ev.type) {
      case EventType::Collision: {
        const std::uint32_t j = ev.partner;
        if (state_.count[j] != ev.partner_count) {  // partner moved differently since
          info.stale = true;
          ++stale_;
          predict(i);
          return info;
        }
        state_.advance_to(i, now_);
        state_.advance_to(j, now_);
        info.record = model_.collide(state_, box_, i, j, now_);
        info.record.time = now_;
        ++state_.count[i];
        ++state_.count[j];
        ++counts_[static_cast<int>(EventType::Collision)];
        predict(i);
        predict(j);
        return info;
      }
      case EventType::CellCross: {
        ++counts_[static_cast<int>(EventType::CellCross)];
        const int face = static_cast<int>(ev.partner);
        state_.advance_to(i, now_);
        if (cells_.cross(i, face)) {
          const int k = face >> 1;
          const double s = (face & 1) ? 1.0 : -1.0;
          state_.r[i][k] -= s * box_.L[k];
          state_.image[i][k] += (face & 1) ? 1 : -1;
        }
        // The trajectory is unchanged: if the remembered best collision is still valid, only
        // the bodies of the newly adjacent cells need predicting.
        const Event& b = best_[i];
        if (b.type == EventType::None || state_.count[b.partner] == b.partner_count) {
          Event best = b;
          cand_.clear();
          shift_.clear();
          cells_.for_each_new_neighbor(i, face, box_.L, collect());
          consider(i, best);
          schedule(i, best);
        } else {
          predict(i);
        }
        return info;
      }
      default:
        throw std::logic_error("unexpected event type in the calendar");
    }
  }

  // Stream every body to the current time (for output; does not change any trajectory).
  void synchronize() {
    for (std::uint32_t i = 0; i < state_.size(); ++i) state_.advance_to(i, now_);
  }
  // Mutable access for code that changes velocities of all bodies at once (e.g. rescaling);
  // call reschedule_all() afterwards.
  State& mutable_state() { return state_; }
  void reschedule_all() {
    synchronize();
    for (std::uint32_t i = 0; i < state_.size(); ++i) ++state_.count[i];
    for (std::uint32_t i = 0; i < state_.size(); ++i) predict(i);
  }

 private:
  // Predict body i against the candidates in cand_ and keep the earliest in `best`.
  void consider(std::uint32_t i, Event& best) {
    const std::size_t n = cand_.size();
    if (times_.size() < n) times_.resize(2 * n);
    model_.contact_times(state_, box_, i, cand_.data(), shift_.data(), n,
                         cells_.needs_minimum_image(), now_, times_.data());
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
  auto collect() {
    return [this](std::uint32_t j, const Vec3& shift) {
      cand_.push_back(j);
      shift_.push_back(shift);
    };
  }
  // Full prediction for body i: all bodies in its 27 cells, and its next cell crossing.
  void predict(std::uint32_t i) {
    state_.advance_to(i, now_);
    Event best;
    best.owner = i;
    cand_.clear();
    shift_.clear();
    cells_.for_each_neighbor(i, box_.L, collect());
    consider(i, best);
    schedule(i, best);
  }
  void schedule(std::uint32_t i, const Event& best) {
    best_[i] = best;
    int face = -1;
    const double tc = cells_.crossing_time(i, state_.r[i], state_.v[i], face);
    if (face >= 0 && now_ + tc < best.time) {
      Event c;
      c.time = now_ + tc;
      c.owner = i;
      c.partner = static_cast<std::uint32_t>(face);
      c.type = EventType::CellCross;
      queue_.set(c);
    } else {
      queue_.set(best);
    }
  }

  Box box_;
  State state_;
  Model model_;
  double now_ = 0.0;
  CellList cells_;
  Queue queue_;
  std::vector<Event> best_;  // each body's best predicted collision (for cell crossings)
  std::vector<std::uint32_t> cand_;  // candidate partners of the body being predicted
  std::vector<Vec3> shift_;          // their periodic image shifts
  std::vector<double> times_;        // their contact times
  std::array<std::uint64_t, kEventTypes> counts_{};
  std::uint64_t stale_ = 0;
};

}  // namespace hb
