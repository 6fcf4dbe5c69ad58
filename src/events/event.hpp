// Event record: what happens, when, to whom, and the per-particle event counters that tell
// whether the prediction is still valid when it comes up (lazy invalidation).
#pragma once
#include <cstdint>
#include <limits>

namespace hb {

enum class EventType : std::uint8_t {
  None = 0,       // no event predicted (time = +inf)
  Collision = 1,  // owner collides with partner
  CellCross = 2,  // owner leaves its cell through face `partner` (0..5 = -x,+x,-y,+y,-z,+z)
  Rebuild = 3,    // owner's neighbour-list box must be rebuilt
  Recheck = 4,    // nothing physical: re-predict the owner at this time (bounded search window)
  Wall = 5,       // owner hits wall `partner` (planar walls: box face 0..5 = -x,+x,-y,+y,-z,+z)
  Thermostat = 6, // owner's velocities are redrawn (Andersen thermostat)
};
inline constexpr int kEventTypes = 7;
inline const char* event_name(EventType t) {
  switch (t) {
    case EventType::None: return "none";
    case EventType::Collision: return "collision";
    case EventType::CellCross: return "cell_crossing";
    case EventType::Rebuild: return "nnl_rebuild";
    case EventType::Recheck: return "recheck";
    case EventType::Wall: return "wall";
    case EventType::Thermostat: return "thermostat";
  }
  return "unknown";
}

// One predicted event owned by particle `owner`. The partner counter records the partner's
// event count at prediction time; if it has changed when the event comes up, the partner's
// trajectory has changed and the event is stale.
struct Event {
  double time = std::numeric_limits<double>::infinity();
  std::uint32_t owner = 0;
  std::uint32_t partner = 0;
  std::uint32_t partner_count = 0;
  EventType type = EventType::None;
};

// Strict total order on events: by time, then owner id. Both queues pop in this order, so their
// pop sequences are identical even with ties.
inline bool earlier(const Event& a, const Event& b) {
  return a.time < b.time || (a.time == b.time && a.owner < b.owner);
}

}  // namespace hb
