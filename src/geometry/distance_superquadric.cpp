// The distance solver for Superquadric against every engine shape, compiled once (see the end of
// geometry/distance.hpp).
#define HB_DISTANCE_INSTANTIATE
#include "geometry/distance.hpp"

namespace hb {
HB_DISTANCE_INSTANCES(, Superquadric)
}  // namespace hb
