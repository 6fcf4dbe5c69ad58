// The fast calendars (IndexedHeap, CalendarQueue) against their brute-force twin: identical
// pops for the same random set / invalidate / pop sequences, with lazy invalidation by
// per-particle counters.
#include <gtest/gtest.h>

#include <pcg_random.hpp>
#include <random>
#include <vector>

#include "events/calendar_queue.hpp"
#include "events/queue.hpp"
#include "math/types.hpp"

using namespace hb;

namespace {

template <class Q>
std::vector<Event> drive(std::uint32_t n, std::uint64_t seed, int ops) {
  Q q(n);
  std::vector<std::uint32_t> count(n, 0);
  pcg32 rng(seed);
  std::uniform_int_distribution<std::uint32_t> pick(0, n - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> coarse(0, 20);  // coarse times force ties
  double now = 0.0;
  std::vector<Event> popped;
  for (int k = 0; k < ops; ++k) {
    const double r = u(rng);
    if (r < 0.5) {  // predict: replace an owner's event
      Event e;
      e.owner = pick(rng);
      e.partner = pick(rng);
      e.partner_count = count[e.partner];
      e.type = EventType::Collision;
      e.time = now + (u(rng) < 0.3 ? coarse(rng) * 0.1 : u(rng));
      if (u(rng) < 0.05) e.time = kInf, e.type = EventType::None;
      q.set(e);
    } else if (r < 0.6) {  // the partner's trajectory changes: its events elsewhere go stale
      ++count[pick(rng)];
    } else if (r < 0.65) {
      q.clear(pick(rng));
    } else {  // pop: drop stale events, record valid ones
      const Event e = q.top();
      if (e.time == kInf) continue;
      now = e.time;
      const bool valid = count[e.partner] == e.partner_count;
      Event rec = e;
      rec.type = valid ? EventType::Collision : EventType::Recheck;
      popped.push_back(rec);
      q.clear(e.owner);
    }
  }
  return popped;
}

}  // namespace

// Queue Q against the brute-force twin: the same pops, ties included, for the same sequences.
template <class Q>
void expect_pops_like_brute_force() {
  for (std::uint32_t n : {1u, 2u, 7u, 64u, 1000u}) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const auto a = drive<Q>(n, seed, 20000);
      const auto b = drive<BruteQueue>(n, seed, 20000);
      ASSERT_EQ(a.size(), b.size()) << "n=" << n << " seed=" << seed;
      ASSERT_GT(a.size(), 100u);
      for (std::size_t k = 0; k < a.size(); ++k) {
        ASSERT_EQ(a[k].owner, b[k].owner) << "pop " << k << " n=" << n;
        ASSERT_EQ(a[k].time, b[k].time) << "pop " << k;
        ASSERT_EQ(a[k].type, b[k].type) << "pop " << k;
      }
    }
  }
}

TEST(Queue, IndexedHeapPopsLikeBruteForce) { expect_pops_like_brute_force<IndexedHeap>(); }

// The hard-sphere calendar behind the same interface (events/calendar_queue.hpp), the generic
// loop's queue.
TEST(Queue, CalendarQueuePopsLikeBruteForce) { expect_pops_like_brute_force<CalendarQueue>(); }

// Tuned after its first fill (what the generic loop does: Simulation::tune_queue), with every
// time far within the width it starts with, the calendar still pops like the brute-force queue;
// and the event it names as the next one (next_event, the loop's hint) is the brute-force
// queue's second, with the partner of a collision and the owner again for other events.
TEST(Queue, TunedCalendarQueuePopsLikeBruteForce) {
  const std::uint32_t n = 1000;
  CalendarQueue q(n);
  BruteQueue b(n);
  std::vector<double> t(n);
  pcg32 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto set = [&](std::uint32_t i, double time) {
    Event e;
    e.owner = i;
    e.partner = (i + 7) % n;
    e.type = i % 3 == 0 ? EventType::Rebuild : EventType::Collision;
    e.time = t[i] = time;
    q.set(e);
    b.set(e);
  };
  for (std::uint32_t i = 0; i < n; ++i) set(i, 0.01 * u(rng));
  q.tune(0.0);
  int named = 0;
  for (int k = 0; k < 5000; ++k) {
    const Event e = q.top();
    ASSERT_EQ(e.owner, b.top().owner) << "pop " << k;
    ASSERT_EQ(e.time, b.top().time) << "pop " << k;
    std::uint32_t next, other;
    if (q.next_event(next, other)) {
      std::uint32_t second = e.owner == 0 ? 1 : 0;
      for (std::uint32_t i = 0; i < n; ++i)
        if (i != e.owner && t[i] < t[second]) second = i;
      ASSERT_EQ(next, second) << "pop " << k;
      ASSERT_EQ(other, next % 3 == 0 ? next : (next + 7) % n) << "pop " << k;
      ++named;
    }
    set(e.owner, e.time + 0.01 * u(rng));
  }
  EXPECT_GT(named, 1000);
}

TEST(Queue, PopsInNonDecreasingTimeOrder) {
  const std::uint32_t n = 500;
  IndexedHeap q(n);
  pcg32 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::uint32_t i = 0; i < n; ++i) {
    Event e;
    e.owner = i;
    e.time = u(rng);
    e.type = EventType::Collision;
    q.set(e);
  }
  double last = -1.0;
  for (std::uint32_t k = 0; k < n; ++k) {
    const Event e = q.top();
    EXPECT_GE(e.time, last);
    last = e.time;
    q.clear(e.owner);
  }
  EXPECT_EQ(q.top().time, kInf);
}
