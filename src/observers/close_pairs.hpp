// Candidate pairs of the overlap checks: every pair i < j whose minimum-image centre distance is
// below `range`, found on a fresh grid built from the positions alone (not the simulation's
// neighbour structures); brute force when the box holds fewer than 3 cells along an axis.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "math/types.hpp"
#include "core/box.hpp"
#include "core/field_view.hpp"

namespace hb {

// fn(i, j, d) with d the minimum image of r[j] - r[i].
void for_close_pairs(FieldView<Vec3> r, const Box& box, double range,
                     const std::function<void(std::uint32_t, std::uint32_t, const Vec3&)>& fn);

}  // namespace hb
