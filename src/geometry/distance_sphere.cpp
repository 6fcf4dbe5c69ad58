// The distance solver for Sphere against every engine shape, compiled once (see the end of
// geometry/distance.hpp).
#define HB_DISTANCE_INSTANTIATE
#include "geometry/distance.hpp"

namespace hb {
HB_DISTANCE_INSTANCES(, Sphere)
}  // namespace hb
