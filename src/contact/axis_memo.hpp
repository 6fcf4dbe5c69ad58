// The last separating axis of each pair, kept between solves: where the pair's next axis search
// starts (ContactInput::axis_start, contact_time.hpp), one more fixed axis for the pre-filter of
// predict_contacts (clear_along_axis, axis_gap.hpp), and where the distance solve starts when the
// pair collides (touching_guess; the axis is then the contact normal the solver predicted).
// Any unit vector is a valid start and any fixed axis gives a valid bound, so the memo changes
// how many steps a search takes, never whether an answer is right. It does change the last bits
// of a contact time (the path of the search), so a checkpoint saves it (AxisMemo::rows) for
// `--resume` to continue bit for bit.
//
// Layout: per body i, kSlots slots direct-mapped by the partner index (j mod kSlots), each the
// unit axis from i to j in the lab frame and j; a slot whose j differs is a miss. Measured
// (callgrind, ellipsoids X0 = 2, phi = 0.5, N = 256; docs/benchmarks/README.md):
// 16 / 32 / 64 slots -6.5 / -9.3 / -10.0 % instructions; 32 slots of floats -7.3 % (the
// collision's distance solve then needs one more Newton step), of 16-bit octahedral pairs
// -4.8 %. 32 slots of doubles: 1 kB a body.
//
// Both sides: every solve stores its axis in i's slot for j and, negated, in j's slot for i
// (store_both), so each side's slot holds the pair's latest axis (unless another partner took
// the slot since) and a lookup from either side finds it in its own slots. Storing only the
// solving side's slot left the other side's older axis in place, which find_either then
// preferred, and at large N sent a lookup to the partner's slots (a cache miss) whenever the
// own slot missed. Measured (docs/benchmarks/README.md, "Session of 2026-12-03, fifth part"):
// solves per collision -7 % at X0 = 10, phi = 0.4, -5 % at X0 = 2, phi = 0.5; time -1 % at
// N = 256000 (three alternating rounds, each faster), -1 to -3 % at X0 = 10.
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "math/types.hpp"

namespace hb {

class AxisMemo {
 public:
  static constexpr std::uint32_t kSlots = 32;
  static constexpr std::uint32_t kNone = 0xffffffffu;
  // One slot as the checkpoint stores it: x, y, z, j (j = kNone: empty), exact as doubles.
  using Row = std::array<double, 4>;

  // false: no memo (every search starts cold; the slow twin of the tests).
  bool on = true;

  // The axis from i to j of the pair's last solve in n (true), or false (n unchanged).
  bool find(std::uint32_t i, std::uint32_t j, Vec3& n) const {
    if (!on) return false;
    const std::size_t k = index(i, j);
    if (k >= slots_.size() || slots_[k].j != j) return false;
    n = slots_[k].n;
    return true;
  }
  // The pair's axis from i to j: i's slot for j, else j's slot for i negated.
  bool find_either(std::uint32_t i, std::uint32_t j, Vec3& n) const {
    return find(i, j, n) || find_from_partner(i, j, n);
  }
  // For the pre-filter of every candidate (system/rigid_bodies.hpp, memo_or_centres_clear_time):
  // find_either while the memo holds at most kPartnerSideBodies bodies (2 MB, within a core's
  // cache), else i's own slot alone. In a large system the partner's slot is a cache miss that
  // the prediction waits on, for every candidate whose own slot misses (most are pairs never
  // solved, in neither memo); the few axes it finds (its own slot lost to another partner) save
  // less than the wait. Measured (docs/benchmarks/README.md, "Session of 2026-12-07, second
  // part"), own slot alone against either, ellipsoids X0 = 2 at phi = 0.5, alternating runs:
  // N = 256 +1.7 % (instructions +1.9 %), 4096 -2.8 %, 32000 -9.4 %, 256000 -11.8 %.
  // (The size is compared only after the own slot missed: e1 asks ~34 times a collision.)
  static constexpr std::size_t kPartnerSideBodies = 2048;
  bool find_near(std::uint32_t i, std::uint32_t j, Vec3& n) const {
    return find(i, j, n) ||
           (slots_.size() <= kPartnerSideBodies * kSlots && find_from_partner(i, j, n));
  }
  // Axis n of a solve or the contact normal of a collision of i and j (from i to j), for both
  // sides (see the header).
  void store_both(std::size_t n_bodies, std::uint32_t i, std::uint32_t j, const Vec3& n) {
    store(n_bodies, i, j, n);
    store(n_bodies, j, i, Vec3(-n));
  }
  // Remembers axis n (from i to j, unit length) for the pair; n = 0 is not kept. n_bodies sizes
  // the memo on first use.
  void store(std::size_t n_bodies, std::uint32_t i, std::uint32_t j, const Vec3& n) {
    if (!on || !(n.squaredNorm() > 0.0)) return;
    if (slots_.size() < n_bodies * kSlots) slots_.resize(n_bodies * kSlots);
    slots_[index(i, j)] = Slot{n, j};
  }

  // A hint: body i's slots (1 kB), ahead of a prediction of i (at N = 256000 they are not in
  // any cache).
  [[gnu::always_inline]] void prefetch(std::uint32_t i) const {
    if (std::size_t(i + 1) * kSlots > slots_.size()) return;
    const char* p = reinterpret_cast<const char*>(slots_.data() + std::size_t(i) * kSlots);
    for (std::size_t b = 0; b < kSlots * sizeof(Slot); b += 64) __builtin_prefetch(p + b);
  }
  // The memo as rows (empty if nothing was stored): one at a time (a checkpoint streams them)
  // or all, and back.
  std::size_t size() const { return slots_.size(); }
  Row row(std::size_t k) const {
    return {slots_[k].n.x(), slots_[k].n.y(), slots_[k].n.z(), double(slots_[k].j)};
  }
  std::vector<Row> rows() const {
    std::vector<Row> r(slots_.size());
    for (std::size_t k = 0; k < slots_.size(); ++k) r[k] = row(k);
    return r;
  }
  void restore(const std::vector<Row>& r) {
    if (r.size() % kSlots != 0) throw std::invalid_argument("axis memo: not whole bodies of slots");
    slots_.resize(r.size());
    for (std::size_t k = 0; k < r.size(); ++k)
      slots_[k] = Slot{Vec3(r[k][0], r[k][1], r[k][2]), std::uint32_t(r[k][3])};
  }

 private:
  // j's slot for i, negated: the axis from i to j (n unchanged on a miss).
  bool find_from_partner(std::uint32_t i, std::uint32_t j, Vec3& n) const {
    if (!find(j, i, n)) return false;
    n = -n;
    return true;
  }
  struct Slot {
    Vec3 n = Vec3::Zero();
    std::uint32_t j = kNone;
  };
  static std::size_t index(std::uint32_t i, std::uint32_t j) {
    return std::size_t(i) * kSlots + (j % kSlots);
  }
  std::vector<Slot> slots_;
};

}  // namespace hb
