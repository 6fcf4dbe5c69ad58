// Event calendars with one slot per particle: each particle holds exactly its earliest
// predicted event. Setting a slot replaces (deletes) the old event in O(log N); events that
// name a partner are validated lazily by the partner's counter when they reach the top.
//
// IndexedHeap is the fast calendar (binary min-heap over particle slots with a position map);
// BruteQueue is its obviously-right twin (linear scan), used by the tests.
#pragma once
#include <cassert>
#include <cstdint>
#include <vector>

#include "events/event.hpp"

namespace hb {

class IndexedHeap {
 public:
  explicit IndexedHeap(std::uint32_t n = 0) { reset(n); }

  void reset(std::uint32_t n) {
    ev_.assign(n, Event{});
    heap_.resize(n);
    pos_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      ev_[i].owner = i;
      heap_[i] = i;
      pos_[i] = i;
    }
  }
  std::uint32_t size() const { return static_cast<std::uint32_t>(ev_.size()); }

  // Replace the event of slot e.owner.
  void set(const Event& e) {
    const std::uint32_t i = e.owner;
    const bool up = earlier(e, ev_[i]);
    ev_[i] = e;
    if (up) sift_up(pos_[i]); else sift_down(pos_[i]);
  }
  // Remove the event of slot i (it becomes "never").
  void clear(std::uint32_t i) {
    Event e;
    e.owner = i;
    set(e);
  }
  const Event& top() const { return ev_[heap_[0]]; }
  const Event& event_of(std::uint32_t i) const { return ev_[i]; }
  [[gnu::always_inline]] void prefetch(std::uint32_t i) const { __builtin_prefetch(&ev_[i]); }  // a hint, ahead of event_of(i)

 private:
  bool less(std::uint32_t a, std::uint32_t b) const { return earlier(ev_[a], ev_[b]); }
  void place(std::uint32_t k, std::uint32_t slot) {
    heap_[k] = slot;
    pos_[slot] = k;
  }
  void sift_up(std::uint32_t k) {
    const std::uint32_t s = heap_[k];
    while (k > 0) {
      const std::uint32_t p = (k - 1) >> 1;
      if (!less(s, heap_[p])) break;
      place(k, heap_[p]);
      k = p;
    }
    place(k, s);
  }
  void sift_down(std::uint32_t k) {
    const std::uint32_t n = size();
    const std::uint32_t s = heap_[k];
    for (;;) {
      std::uint32_t c = 2 * k + 1;
      if (c >= n) break;
      if (c + 1 < n && less(heap_[c + 1], heap_[c])) ++c;
      if (!less(heap_[c], s)) break;
      place(k, heap_[c]);
      k = c;
    }
    place(k, s);
  }

  std::vector<Event> ev_;            // event of each particle slot
  std::vector<std::uint32_t> heap_;  // heap of slots
  std::vector<std::uint32_t> pos_;   // position of each slot in heap_
};

// Reference twin: the same interface, answered by a linear scan.
class BruteQueue {
 public:
  explicit BruteQueue(std::uint32_t n = 0) { reset(n); }
  void reset(std::uint32_t n) {
    ev_.assign(n, Event{});
    for (std::uint32_t i = 0; i < n; ++i) ev_[i].owner = i;
  }
  std::uint32_t size() const { return static_cast<std::uint32_t>(ev_.size()); }
  void set(const Event& e) { ev_[e.owner] = e; }
  void clear(std::uint32_t i) {
    ev_[i] = Event{};
    ev_[i].owner = i;
  }
  const Event& top() const {
    std::uint32_t best = 0;
    for (std::uint32_t i = 1; i < size(); ++i)
      if (earlier(ev_[i], ev_[best])) best = i;
    return ev_[best];
  }
  const Event& event_of(std::uint32_t i) const { return ev_[i]; }

 private:
  std::vector<Event> ev_;
};

}  // namespace hb
