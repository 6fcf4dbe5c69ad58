// The contact-time solver for Superquadric against every engine shape, compiled once (see the end of
// contact/contact_time.hpp).
#define HB_CONTACT_INSTANTIATE
#include "contact/contact_time.hpp"

namespace hb {
HB_CONTACT_INSTANCES(, Superquadric)
}  // namespace hb
