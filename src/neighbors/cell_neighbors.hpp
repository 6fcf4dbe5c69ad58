// Cell lists as the neighbour method of the event loop: candidates are the bodies of the 27
// cells around a body; the neighbour event is the body's next cell crossing, after which only
// the 9 newly adjacent cells need predicting.
#pragma once
#include "events/event.hpp"
#include "neighbors/cell_list.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

class CellNeighbors {
 public:
  static constexpr EventType kEventType = EventType::CellCross;

  // range: the largest centre distance at which two bodies can touch.
  explicit CellNeighbors(double range = 1.0) : range_(range) {}

  void init(const Box& box, State& s, double now) {
    cells_.init(box.L, range_, s.size(), box.periodic);
    for (std::uint32_t i = 0; i < s.size(); ++i) {
      s.advance_to(i, now);
      s.image[i] += box.wrap(s.r[i]);
      cells_.insert(i, s.r[i]);
    }
  }
  // Restore: bodies are placed in the given cells (positions are not streamed or re-binned,
  // since a body that just crossed a face sits on it and binning could pick the other side).
  void restore(const Box& box, const State& s, const std::vector<std::array<int, 3>>& coords) {
    cells_.init(box.L, range_, s.size(), box.periodic);
    for (std::uint32_t i = 0; i < s.size(); ++i) cells_.place_at(i, coords[i]);
  }
  std::vector<std::array<int, 3>> snapshot() const {
    std::vector<std::array<int, 3>> c(cells_.size());
    for (std::uint32_t i = 0; i < c.size(); ++i) c[i] = cells_.coord_of(i);
    return c;
  }
  const CellList& cells() const { return cells_; }
  // Axes with a single cell are never crossed, so positions there are not kept in the box:
  // pair code must then use the full minimum-image convention.
  bool needs_minimum_image() const { return cells_.needs_minimum_image(); }

  template <class Fn>
  void for_each_candidate(std::uint32_t i, const Box& box, Fn&& fn) const {
    cells_.for_each_neighbor(i, box.L, fn);
  }

  // Next cell crossing of body i (stored at time now).
  Event next_event(std::uint32_t i, const State& s, double now) const {
    Event e;
    e.owner = i;
    int face = -1;
    const double tc = cells_.crossing_time(i, s.r[i], s.v[i], face);
    if (face >= 0) {
      e.time = now + tc;
      e.partner = static_cast<std::uint32_t>(face);
      e.type = kEventType;
    }
    return e;
  }

  // Body i (already streamed to the event time) crosses into the next cell. Calls fn(j, shift)
  // for the bodies that became adjacent and returns true: the remembered best collision stays
  // valid (the trajectory did not change) and only these need predicting.
  template <class Fn>
  bool handle(std::uint32_t i, const Event& ev, State& s, const Box& box, Fn&& fn) {
    const int face = static_cast<int>(ev.partner);
    if (cells_.cross(i, face)) {
      const int k = face >> 1;
      s.r[i][k] -= ((face & 1) ? 1.0 : -1.0) * box.L[k];
      s.image[i][k] += (face & 1) ? 1 : -1;
    }
    cells_.for_each_new_neighbor(i, face, box.L, fn);
    return true;
  }

 private:
  double range_;
  CellList cells_;
};

}  // namespace hb
