// Morton (Z-order) codes: the bits of three cell indices interleaved, so that sorting by the code
// puts cells that are close in space mostly close in the order (a space-filling curve).  Used to
// lay bodies out in memory so that the neighbours a prediction reads sit near each other: the
// hard-sphere loop re-sorts its records by it (system/sphere_engine.hpp), the lattice start
// numbers its sites by it (setup/rigid_setup.hpp).
#pragma once
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace hb {

// Interleaves the low 21 bits of x, y and z (x in the lowest bit).
inline std::uint64_t morton_code(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  std::uint64_t m = 0;
  for (int b = 0; b < 21; ++b)
    m |= (std::uint64_t((x >> b) & 1u) << (3 * b)) | (std::uint64_t((y >> b) & 1u) << (3 * b + 1)) |
         (std::uint64_t((z >> b) & 1u) << (3 * b + 2));
  return m;
}

// The permutation that sorts key (stable: equal keys keep their order): perm[k] is the index of
// the k-th smallest.
inline std::vector<std::uint32_t> sorting_permutation(const std::vector<std::uint64_t>& key) {
  std::vector<std::uint32_t> perm(key.size());
  std::iota(perm.begin(), perm.end(), std::uint32_t(0));
  std::stable_sort(perm.begin(), perm.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
  return perm;
}

}  // namespace hb
