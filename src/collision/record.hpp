// What a collision leaves behind for observers: impulse magnitude J on B along the unit
// normal n (A -> B), the minimum-image centre separation r_AB = r_B - r_A at contact, and the
// kinetic-energy change dE (zero for an elastic collision up to rounding).
#pragma once
#include <cstdint>

#include "math/types.hpp"

namespace hb {

struct CollisionRecord {
  double time = 0.0;
  std::uint32_t a = 0, b = 0;
  double J = 0.0;
  Vec3 n = Vec3::Zero();
  Vec3 r_AB = Vec3::Zero();
  double dE = 0.0;
  // set by a model's collide(..., recheck) when the pair was found not in contact: nothing was
  // changed and the event must be predicted again (system/simulation.hpp, re-check)
  bool moved = false;
};

}  // namespace hb
