// A calendar of one event time per slot with O(1) insertion for events that are not imminent
// (issue 15): the queue of the dedicated hard-sphere loop (system/sphere_engine.hpp).
//
// Time is cut into buckets of width w; bucket b holds the times in [b w, (b + 1) w).  With cur
// the current bucket:
//  * slots whose bucket is <= cur are in a small binary heap keyed by (time, slot), the only
//    sorted part;
//  * slots whose bucket b is in (cur, cur + nb) sit unsorted in the circular list number b mod nb
//    (doubly linked through the slot indices, with one sentinel per list: O(1) insertion and
//    removal);
//  * later slots (and infinite times) sit in an overflow list, scanned once per turn of the
//    lists (when cur reaches a multiple of nb).
// When the heap is empty, cur moves on and the next list is poured into the heap.  The pop order
// is exactly that of a heap over all slots keyed by (time, slot): the test compares the two
// (tests/events/test_calendar.cpp) on random and adversarial sequences.
//
// The width adapts: at the end of each turn, if the heap entries per bucket passed left
// [1.5, 24] (judged over at least half a turn), the calendar is rebuilt with w scaled to about 6
// entries per bucket (the fastest of 3, 6 and 16 in the hard-sphere benchmark; O(N), at most
// once per turn); a heap crowded beyond max(256, N / 8) entries (the
// width far too large) also rebuilds, at most once per N entries.  A whole turn without any
// entry means every slot is in the overflow: cur then jumps to the earliest of them.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace hb {

class Calendar {
 public:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr double kPerBucket = 6.0;  // heap entries per bucket aimed at

  // n slots, all at time +inf; buckets of the given width (> 0), nb lists (>= 1), starting at
  // time now.
  void reset(std::uint32_t n, double width, std::uint32_t lists, double now) {
    n_ = n;
    nb_ = lists < 1 ? 1 : lists;
    width_ = width;
    inv_w_ = 1.0 / width;
    slot_.assign(n, Slot{});
    link_.resize(std::size_t(n) + nb_ + 1);
    for (std::uint32_t s = 0; s <= nb_; ++s) link_[n + s] = Link{n + s, n + s};
    heap_.clear();
    cur_ = bucket(now);
    entries_ = passed_ = 0;
    for (std::uint32_t i = 0; i < n; ++i) link_after(i, overflow());
  }

  std::uint32_t size() const { return n_; }
  double time_of(std::uint32_t i) const { return slot_[i].time; }
  // A hint: slot i's line, ahead of a time_of(i).
  [[gnu::always_inline]] void prefetch_slot(std::uint32_t i) const { __builtin_prefetch(&slot_[i]); }
  // The two numbers stored with slot i's time (the event's partner and the partner's stamp).
  std::uint32_t tag_of(std::uint32_t i) const { return slot_[i].tag; }
  std::uint32_t stamp_of(std::uint32_t i) const { return slot_[i].stamp; }
  double width() const { return width_; }
  std::uint32_t lists() const { return nb_; }
  // Bytes held, for the memory figure of the benchmarks.
  std::size_t bytes() const {
    return slot_.capacity() * sizeof(Slot) + link_.capacity() * sizeof(Link) +
           heap_.capacity() * sizeof(Node);
  }

  // Set slot i's time (replacing its old one), with two numbers carried along: tag (also held
  // in the heap, where it is known with the top without touching the slot) and stamp.
  void set(std::uint32_t i, double t, std::uint32_t tag = 0, std::uint32_t stamp = 0) {
    const std::int64_t b = bucket(t);
    if (link_[i].next == kHeap) {
      const std::uint32_t k = link_[i].prev;
      if (b <= cur_) {  // stays in the heap
        const bool up = Node{t, i} < heap_[k];
        slot_[i] = Slot{t, tag, stamp};
        heap_[k].time = t;
        heap_[k].tag = tag;
        if (up) sift_up(k); else sift_down(k);
        return;
      }
      heap_remove(k);
    } else {
      unlink(i);
    }
    slot_[i] = Slot{t, tag, stamp};
    place(i, b);
  }

  // The slot with the earliest (time, slot) (n >= 1).  Moves the current bucket on when the heap
  // is empty; with every time infinite it returns the lowest such slot without moving it.
  std::uint32_t top() {
    if (heap_.size() > kCrowded && heap_.size() > n_ / 8 && since_rebuild_ > n_)
      rebuild(width_ * kPerBucket / heap_.size());  // the width is far too large
    std::uint32_t idle = 0;
    while (heap_.empty()) {
      if (++idle > nb_ + 1) {  // a whole turn without an event: all are in the overflow
        const std::uint32_t first = earliest_overflow();
        if (first == kHeap || slot_[first].time == kInf) return first;  // nothing finite ahead
        ++jumps_;
        cur_ = bucket(slot_[first].time);  // jump to it (the overflow keeps b >= cur + nb)
        rescan_overflow();
        idle = 0;
        continue;
      }
      // a turn's end that re-placed slots (a rescan or a rebuild) may have put some in lists
      // ahead: the idle count starts again, so the jump above never passes them by
      if (advance()) idle = 0;
    }
    return heap_[0].id;
  }

  // Re-place every slot (O(N)) with buckets of about kPerBucket slots, judged from their times:
  // a slot's next event is some mean time tau after now, so about size() / tau of them happen
  // per unit time (the width aimed at: kPerBucket tau / size()). For a calendar just filled
  // (every slot set once): the width it starts with is only a guess, and until the turn of its
  // lists ends (nb buckets later) nothing else re-tunes it. No change when no time is finite.
  void tune_width(double now) {
    double sum = 0.0;
    std::size_t finite = 0;
    for (std::uint32_t i = 0; i < n_; ++i)
      if (slot_[i].time < kInf) sum += slot_[i].time - now, ++finite;
    if (finite > 0 && sum > 0.0) rebuild(kPerBucket * (sum / double(finite)) / double(n_));
  }

  // After top(): the tag of the top slot, read from the heap (no access to the slot).
  std::uint32_t top_tag() const { return heap_.empty() ? 0u : heap_[0].tag; }
  // After top(): the heap entries that come next unless a new time is set before them (the root's
  // children), a hint for asking their data from memory one event ahead.  Writes up to 2 (slot,
  // tag) pairs and returns how many.
  int next_after_top(std::uint32_t slot[2], std::uint32_t tag[2]) const {
    int m = 0;
    for (std::size_t k = 1; k <= 2 && k < heap_.size(); ++k, ++m) slot[m] = heap_[k].id, tag[m] = heap_[k].tag;
    return m;
  }
  // After top(): the slot that comes next unless a new time is set before it, with its tag, or
  // false when the heap holds the top alone (the next slot is then in a later bucket's list).
  // It is the earlier of the root's children: every slot in a list is in a later bucket than
  // every slot in the heap.
  bool next_slot(std::uint32_t& slot, std::uint32_t& tag) const {
    if (heap_.size() < 2) return false;
    const std::size_t k = heap_.size() > 2 && heap_[2] < heap_[1] ? 2 : 1;
    slot = heap_[k].id, tag = heap_[k].tag;
    return true;
  }

  // A hint for large calendars, once per event: one more node of the next bucket's list is asked
  // for from memory.  Pouring a list into the heap follows its links, one cache miss after the
  // other when the slots are spread over a large memory; walked ahead one node per event, the
  // list is in the cache when its turn comes (a bucket holds about as many slots as events pass
  // in it).  The walk only reads: a node that left the list under it ends the walk or follows its
  // new list, both harmless.
  void prefetch_ahead() {
    if (ahead_ >= n_) return;
    const std::uint32_t nx = link_[ahead_].next;
    ahead_ = nx;
    if (nx < n_) {
      __builtin_prefetch(&link_[nx]);
      __builtin_prefetch(&slot_[nx]);
    }
  }

  // How often the width was re-tuned and the idle buckets jumped (for the tests).
  std::uint64_t rebuilds() const { return rebuilds_; }
  std::size_t heap_entries() const { return heap_.size(); }  // the sorted part's size
  std::uint64_t jumps() const { return jumps_; }

 private:
  static constexpr std::uint32_t kHeap = 0xffffffffu;  // link.next of a slot in the heap
  static constexpr std::size_t kCrowded = 256;  // heap size that calls for a narrower width
  static constexpr std::int64_t kFar = std::numeric_limits<std::int64_t>::max();
  struct Link {
    std::uint32_t prev, next;  // in the heap: prev = heap position, next = kHeap
  };
  struct Slot {
    double time = kInf;
    std::uint32_t tag = 0, stamp = 0;
  };
  struct Node {  // 16 bytes, the tag in what would be padding
    double time;
    std::uint32_t id, tag = 0;
    bool operator<(const Node& o) const { return time < o.time || (time == o.time && id < o.id); }
  };

  std::int64_t bucket(double t) const {
    const double q = std::floor(t * inv_w_);
    if (q < -9.0e18) return -kFar;  // (times before the start are not expected; kept in range)
    return q < 9.0e18 ? static_cast<std::int64_t>(q) : kFar;  // +inf and beyond (NaN): far
  }
  std::uint32_t overflow() const { return n_ + nb_; }
  std::uint32_t list_of(std::int64_t b) const {  // b mod nb in [0, nb), negative times too
    const std::int64_t m = b % std::int64_t(nb_);
    return n_ + static_cast<std::uint32_t>(m < 0 ? m + nb_ : m);
  }

  void link_after(std::uint32_t i, std::uint32_t head) {
    const std::uint32_t nx = link_[head].next;
    link_[i] = Link{head, nx};
    link_[nx].prev = i;
    link_[head].next = i;
  }
  void unlink(std::uint32_t i) {
    const Link l = link_[i];
    link_[l.prev].next = l.next;
    link_[l.next].prev = l.prev;
  }
  // Slot i (time set, in no structure) goes where its bucket b says.
  void place(std::uint32_t i, std::int64_t b) {
    if (b <= cur_) heap_push(i);
    else if (b - cur_ < static_cast<std::int64_t>(nb_)) link_after(i, list_of(b));
    else link_after(i, overflow());
  }

  // Move to the next bucket; true if the turn's end re-placed any slot.
  bool advance() {
    ++cur_;
    ++passed_;
    const bool moved = cur_ % nb_ == 0 && end_of_turn();
    pour(list_of(cur_));
    ahead_ = list_of(cur_ + 1);  // the sentinel: the walk starts at its first node
    ahead_ = link_[ahead_].next;
    if (ahead_ < n_) __builtin_prefetch(&link_[ahead_]);
    return moved;
  }
  // Move every slot of list head into the heap.
  void pour(std::uint32_t head) {
    std::uint32_t i = link_[head].next;
    while (i != head) {
      const std::uint32_t nx = link_[i].next;
      heap_push(i);
      i = nx;
    }
    link_[head] = Link{head, head};
  }
  // Overflow slots whose bucket came within reach go to their lists (or the heap).
  // Returns whether any moved.
  bool rescan_overflow() {
    const std::uint32_t head = overflow();
    std::uint32_t i = link_[head].next;
    bool moved = false;
    while (i != head) {
      const std::uint32_t nx = link_[i].next;
      const std::int64_t b = bucket(slot_[i].time);
      if (b - cur_ < static_cast<std::int64_t>(nb_)) {
        unlink(i);
        place(i, b);
        moved = true;
      }
      i = nx;
    }
    return moved;
  }
  // Re-tunes the width or rescans the overflow; true if any slot was re-placed.
  bool end_of_turn() {
    const double per_bucket = double(entries_) / std::max<std::uint64_t>(passed_, 1);
    const bool judged = 2 * passed_ >= nb_;
    entries_ = passed_ = 0;
    if (judged && per_bucket > 0.0 && (per_bucket < 1.5 || per_bucket > 24.0)) {
      rebuild(width_ * kPerBucket / per_bucket);
      return true;
    }
    return rescan_overflow();
  }
  // Every slot re-placed with a new width (cur becomes the bucket of the earliest time).
  void rebuild(double width) {
    ++rebuilds_;
    since_rebuild_ = entries_ = passed_ = 0;
    double first = kInf;
    for (std::uint32_t i = 0; i < n_; ++i) first = std::min(first, slot_[i].time);
    width_ = width;
    inv_w_ = 1.0 / width;
    std::vector<Node>().swap(heap_);  // release a heap grown under a width far too large
    for (std::uint32_t s = 0; s <= nb_; ++s) link_[n_ + s] = Link{n_ + s, n_ + s};
    cur_ = first < kInf ? bucket(first) : 0;
    for (std::uint32_t i = 0; i < n_; ++i) place(i, bucket(slot_[i].time));
  }
  // The least (time, slot) of the overflow (kHeap if it is empty).
  std::uint32_t earliest_overflow() const {
    const std::uint32_t head = overflow();
    std::uint32_t best = kHeap;
    for (std::uint32_t i = link_[head].next; i != head; i = link_[i].next)
      if (best == kHeap || Node{slot_[i].time, i} < Node{slot_[best].time, best}) best = i;
    return best;
  }

  void heap_push(std::uint32_t i) {
    heap_.push_back(Node{slot_[i].time, i, slot_[i].tag});
    link_[i].next = kHeap;
    sift_up(static_cast<std::uint32_t>(heap_.size() - 1));
    ++entries_;
    ++since_rebuild_;
  }
  void heap_remove(std::uint32_t k) {
    const Node last = heap_.back();
    heap_.pop_back();
    if (k == heap_.size()) return;
    heap_[k] = last;
    link_[last.id].prev = k;
    if (k > 0 && last < heap_[(k - 1) >> 1]) sift_up(k); else sift_down(k);
  }
  void sift_up(std::uint32_t k) {
    const Node x = heap_[k];
    while (k > 0) {
      const std::uint32_t up = (k - 1) >> 1;
      if (!(x < heap_[up])) break;
      heap_[k] = heap_[up];
      link_[heap_[k].id].prev = k;
      k = up;
    }
    heap_[k] = x;
    link_[x.id].prev = k;
  }
  void sift_down(std::uint32_t k) {
    const Node x = heap_[k];
    const std::uint32_t n = static_cast<std::uint32_t>(heap_.size());
    for (;;) {
      std::uint32_t ch = 2 * k + 1;
      if (ch >= n) break;
      if (ch + 1 < n && heap_[ch + 1] < heap_[ch]) ++ch;
      if (!(heap_[ch] < x)) break;
      heap_[k] = heap_[ch];
      link_[heap_[k].id].prev = k;
      k = ch;
    }
    heap_[k] = x;
    link_[x.id].prev = k;
  }

  std::uint32_t n_ = 0, nb_ = 1;
  double width_ = 1.0, inv_w_ = 1.0;
  std::int64_t cur_ = 0;
  std::uint64_t rebuilds_ = 0, jumps_ = 0;
  std::uint64_t entries_ = 0, passed_ = 0;  // heap entries and buckets passed this turn
  std::uint64_t since_rebuild_ = 0;         // heap entries since the last rebuild
  std::uint32_t ahead_ = 0xffffffffu;       // prefetch_ahead's position in the next list
  std::vector<Slot> slot_;
  std::vector<Link> link_;
  std::vector<Node> heap_;
};

}  // namespace hb
