// The penetration solver for every pair of engine shapes, compiled once (geometry/penetration.hpp).
#include "geometry/penetration.hpp"

#include <variant>

namespace hb {

PenetrationResult penetration(const AnyShape& a, const Pose& pa, const AnyShape& b,
                              const Pose& pb, std::span<const Vec3> hints,
                              const PenetrationOptions& o) {
  return std::visit([&](const auto& sa, const auto& sb) { return penetration(sa, pa, sb, pb, hints, o); },
                    a, b);
}

}  // namespace hb
