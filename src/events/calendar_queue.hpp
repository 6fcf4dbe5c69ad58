// The event calendar of the hard-sphere loop (events/calendar.hpp) behind the interface of
// IndexedHeap (events/queue.hpp), for the generic loop (system/simulation.hpp): one Event per
// body slot, kept here; the Calendar orders the slots by (time, slot), which is `earlier`'s
// (time, owner) order, so the pops are those of IndexedHeap and BruteQueue, ties included
// (tests/events/test_queue.cpp), and a simulation runs the same trajectory on either.
//
// Why: IndexedHeap sifts through log2 N levels of a heap spread over memory on every set; at
// N = 256000 ellipsoids that was 4 % of the run (perf), against below 1 % at N = 256. The
// calendar sets a later event in O(1) (an unsorted list per time bucket) and keeps only the
// current bucket sorted. Its bucket width is judged from the events' times (tune(), which the
// loop calls once every slot is set) and re-tuned at the end of each turn of its lists, so no
// time scale is needed here. Untuned, a calendar whose events all fall within its first bucket
// is one binary heap over all N (it was, for the generic loop, until the second session of
// 2026-12-08).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "events/calendar.hpp"
#include "events/event.hpp"

namespace hb {

class CalendarQueue {
 public:
  explicit CalendarQueue(std::uint32_t n = 0) { reset(n); }

  void reset(std::uint32_t n) {
    ev_.assign(n, Event{});
    for (std::uint32_t i = 0; i < n; ++i) ev_[i].owner = i;
    // the sphere loop's number of lists (a quarter of the slots, at least 16); width 1 to start,
    // until tune() judges it from the first events' times
    cal_.reset(n, 1.0, std::max<std::uint32_t>(16, n / 4), 0.0);
  }
  std::uint32_t size() const { return static_cast<std::uint32_t>(ev_.size()); }

  // Replace the event of slot e.owner.
  void set(const Event& e) {
    ev_[e.owner] = e;
    // the tag: the other body the event reads (a collision's partner), for next_event
    cal_.set(e.owner, e.time, e.type == EventType::Collision ? e.partner : e.owner);
  }
  // After every slot was set (a new calendar, or one restored): buckets sized from the events'
  // times (Calendar::tune_width). The pop order does not depend on them.
  void tune(double now) { cal_.tune_width(now); }
  // Remove the event of slot i (it becomes "never").
  void clear(std::uint32_t i) {
    Event e;
    e.owner = i;
    set(e);
  }
  // The earliest event (const as IndexedHeap's: the calendar moves its current bucket on to
  // find it, which changes no event).
  const Event& top() const { return ev_[cal_.top()]; }
  const Event& event_of(std::uint32_t i) const { return ev_[i]; }
  [[gnu::always_inline]] void prefetch(std::uint32_t i) const { __builtin_prefetch(&ev_[i]); }
  // After top(): the event that comes next unless a new one is set before it (Calendar::
  // next_slot), as its owner and the other body it reads (a collision's partner, else the owner
  // again), from the calendar's heap alone; false if the calendar cannot tell. For hints.
  bool next_event(std::uint32_t& owner, std::uint32_t& other) const {
    return cal_.next_slot(owner, other);
  }

 private:
  std::vector<Event> ev_;
  mutable Calendar cal_;
};

}  // namespace hb
