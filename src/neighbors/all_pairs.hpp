// The slow, obviously right neighbour method: every body is a candidate of every other, always,
// at its minimum image; there are no neighbour events and nothing to rebuild. O(N) candidates
// per prediction: the twin the fast lists (cells, sphere shells, oriented boxes) are tested
// against, not for production runs.
#pragma once
#include <cstdint>

#include "core/box.hpp"
#include "core/state.hpp"
#include "events/event.hpp"

namespace hb {

class AllPairs {
 public:
  static constexpr EventType kEventType = EventType::Rebuild;  // never scheduled

  void init(const Box&, State& s, double) { n_ = static_cast<std::uint32_t>(s.size()); }
  bool needs_minimum_image() const { return true; }

  template <class Fn>
  void for_each_candidate(std::uint32_t i, const Box&, Fn&& fn) const {
    static const Vec3 zero = Vec3::Zero();
    for (std::uint32_t j = 0; j < n_; ++j)
      if (j != i) fn(j, zero);
  }
  Event next_event(std::uint32_t i, const State&, double) const {
    Event e;
    e.owner = i;
    return e;  // none
  }
  template <class Fn>
  bool handle(std::uint32_t, const Event&, State&, const Box&, Fn&&) {
    return false;
  }

 private:
  std::uint32_t n_ = 0;
};

}  // namespace hb
