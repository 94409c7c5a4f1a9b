// The event calendar: a bucket queue with lazy deletion (after Paul, J.
// Comput. Phys. 221, 615 (2007)). Each leaf (particle) has one current
// event time, kept by its owner and read through a `Times` source:
//   double operator()(int leaf) const  the leaf's time now (infinite: none)
//   void prefetch(int leaf) const      request the line holding it
// The calendar returns the leaf with the earliest time, ties going to the
// lower leaf: the order of a complete tournament tree, so a run does not
// depend on which calendar it uses.
//
// Time is cut into buckets of width w, 32 buckets to a coarse bucket. The
// current bucket is a sorted array of (time, leaf); the other buckets of
// the current coarse bucket are plain lists of leaf ids; the next coarse
// buckets (up to 255) are a ring of unsorted entries (leaf id and bucket
// within, packed; chains of one-line chunks), spread into the 32 lists
// when the clock reaches them; later events wait in an overflow list that
// is sorted into the ring once per turn. Changing a leaf's time appends an
// entry where the new time falls (O(1), one line written, nearly always
// one in cache) and leaves the old entry behind: an entry is
// stale when its leaf's time has moved to another bucket, or (in the sorted
// array) differs from the entry's. A bucket is read only when the clock
// reaches it: all its leaves' lines are requested at once, stale entries
// dropped and the rest sorted. The bucket width follows the events' median
// distance from now at each rebuild. The tree this replaces read and wrote a
// path of about log4(N) lines per change, most of them misses at large N,
// and could not tell which events come next; here the next events sit in
// the sorted array, their lines fetched together when the bucket was read.
//
// Usage: after a bulk change of times (all events predicted anew, the clock
// rebased), rebuild(); between rebuilds, every change of a leaf's time is
// followed by push(leaf, new time). A time may not lie before the time of
// the event last taken from top() (events never go back in time).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dynhet/engine/memory.hpp"

namespace dynhet::engine {

class Calendar {
public:
  struct Entry {
    double time;
    int32_t leaf;
  };
  static constexpr double kNever = std::numeric_limits<double>::infinity();
  // Live events per bucket aimed at, and how many mean horizons the ring covers.
  static constexpr double kPerBucket = 32;
  static constexpr double kRingHorizons = 4;
  static constexpr size_t kMaxBuckets = 8192;
  // Buckets per coarse bucket (a power of 2), and the largest leaf the
  // ring's packed entries hold.
  static constexpr int kFineBits = 5;
  static constexpr int64_t kFine = int64_t{1} << kFineBits;
  static constexpr long kMaxLeaves = long{1} << (32 - kFineBits);

  // Every leaf 0..n-1 with a finite time (none earlier than `now`) is
  // entered afresh; the bucket width follows their typical distance from now.
  template <class Times> void rebuild(long n, double now, const Times& time) {
    if (n > kMaxLeaves)
      throw std::length_error("calendar: at most " + std::to_string(kMaxLeaves) + " leaves, not " + std::to_string(n));
    suspended_ = false;
    // The typical distance of an event from now: the median over the
    // events, divided by ln 2 (the mean if they were exponential). Not the
    // mean itself: a few events very far ahead (a slow particle's rebuild)
    // would widen the buckets until most events fell into the current one.
    std::vector<double> dist; // (not kept: 8 B per particle)
    for (long i = 0; i < n; ++i) {
      const double t = time(static_cast<int>(i));
      if (t < kNever) dist.push_back(t - now);
    }
    const long finite = static_cast<long>(dist.size());
    double horizon = 0;
    if (finite > 0) {
      std::nth_element(dist.begin(), dist.begin() + finite / 2, dist.end());
      horizon = dist[static_cast<size_t>(finite / 2)] / std::log(2.0);
    }
    size_t nb = 4 * kFine;
    while (nb < kMaxBuckets && nb < kRingHorizons * finite / kPerBucket) nb *= 2;
    const double w = finite > 0 && horizon > 0 ? kRingHorizons * horizon / nb : 1.0;
    inv_w_ = 1.0 / w;
    ring_.assign(nb / kFine, Bucket{-1, -1, 0});
    chunks_.clear(); // (keeps its capacity)
    free_ = -1;
    mask_ = static_cast<int64_t>(nb) - 1;
    coarse_mask_ = static_cast<int64_t>(nb / kFine) - 1;
    overflow_.clear();
    current_.clear();
    for (auto& f : fine_) f.clear();
    pos_ = 0;
    in_ring_ = in_fine_ = 0;
    current_bucket_ = bucket(std::max(now, 0.0));
    turn_start_ = current_bucket_ & ~mask_;
    for (long i = 0; i < n; ++i) {
      const double t = time(static_cast<int>(i));
      if (t < kNever) push(static_cast<int32_t>(i), t);
    }
  }

  // Changes ignored until the next rebuild() (which reads every time anew).
  void suspend() { suspended_ = true; }

  // Leaf's time has changed to t (t infinite: it has no event; nothing to do).
  void push(int32_t leaf, double t) {
    if (suspended_ || !(t < kNever)) return;
    const int64_t b = bucket(t);
    if (b <= current_bucket_) {
      const Entry e{t, leaf};
      current_.insert(std::upper_bound(current_.begin() + static_cast<std::ptrdiff_t>(pos_), current_.end(), e, before), e);
    } else if (const int64_t ahead = (b >> kFineBits) - (current_bucket_ >> kFineBits); ahead == 0) {
      fine_[static_cast<size_t>(b & (kFine - 1))].push_back(leaf);
      ++in_fine_;
    } else if (ahead <= coarse_mask_) {
      to_ring(leaf, b);
    } else {
      overflow_.push_back(leaf);
    }
  }

  // The earliest event, ties to the lower leaf; {kNever, -1} if none. It
  // stays in the calendar until its leaf's time changes.
  template <class Times> Entry top(const Times& time) {
    for (;;) {
      while (pos_ < current_.size()) {
        const Entry& e = current_[pos_];
        if (time(e.leaf) == e.time) {
          // The next events' lines, for when they come up.
          if (pos_ + kAhead < current_.size()) time.prefetch(current_[pos_ + kAhead].leaf);
          return e;
        }
        ++pos_;
      }
      if (!advance(time)) return Entry{kNever, -1};
    }
  }

  // The leaf k places after the current top in the sorted bucket (its event
  // may be stale), or -1: for requesting lines ahead of time.
  int32_t ahead(size_t k) const { return pos_ + k < current_.size() ? current_[pos_ + k].leaf : -1; }

  size_t bytes() const {
    size_t fine = 0;
    for (const auto& f : fine_) fine += f.capacity() * sizeof(int32_t);
    return current_.capacity() * sizeof(Entry) + overflow_.capacity() * sizeof(int32_t) + fine +
           ring_.capacity() * sizeof(Bucket) + chunks_.capacity() * sizeof(Chunk) + drain_.capacity() * sizeof(int32_t);
  }

private:
  static constexpr size_t kAhead = 2;
  struct Before {
    bool operator()(const Entry& a, const Entry& b) const {
      return a.time < b.time || (a.time == b.time && a.leaf < b.leaf);
    }
  };
  static constexpr Before before{};
  int64_t bucket(double t) const {
    const double b = t * inv_w_;
    return b < 4e18 ? static_cast<int64_t>(b) : static_cast<int64_t>(4e18);
  }
  // Enters leaf, whose time falls in bucket bucket_of_leaf, into the ring:
  // in the slot of that bucket's coarse bucket, packed with its place
  // within it.
  void to_ring(int32_t leaf, int64_t bucket_of_leaf) {
    const size_t r = static_cast<size_t>((bucket_of_leaf >> kFineBits) & coarse_mask_);
    const uint32_t packed =
        static_cast<uint32_t>(leaf) << kFineBits | static_cast<uint32_t>(bucket_of_leaf & (kFine - 1));
    Bucket& b = ring_[r];
    if (b.tail < 0 || b.fill == kChunk) {
      int32_t c;
      if (free_ >= 0) {
        c = free_;
        free_ = chunks_[static_cast<size_t>(c)].next;
      } else {
        c = static_cast<int32_t>(chunks_.size());
        chunks_.emplace_back();
      }
      chunks_[static_cast<size_t>(c)].next = -1;
      if (b.tail >= 0) chunks_[static_cast<size_t>(b.tail)].next = c;
      else b.head = c;
      b.tail = c;
      b.fill = 0;
    }
    chunks_[static_cast<size_t>(b.tail)].id[b.fill++] = packed;
    ++in_ring_;
  }

  // The coarse bucket of current_bucket_ has just become current: its
  // ring entries go to the fine buckets, its chunks back to the free list.
  void spread_coarse() {
    Bucket& bk = ring_[static_cast<size_t>((current_bucket_ >> kFineBits) & coarse_mask_)];
    for (int32_t c = bk.head; c >= 0;) {
      Chunk& ch = chunks_[static_cast<size_t>(c)];
      if (ch.next >= 0) __builtin_prefetch(&chunks_[static_cast<size_t>(ch.next)]);
      const uint32_t m = c == bk.tail ? bk.fill : kChunk;
      for (uint32_t k = 0; k < m; ++k)
        fine_[ch.id[k] & (kFine - 1)].push_back(static_cast<int32_t>(ch.id[k] >> kFineBits));
      in_ring_ -= m;
      in_fine_ += m;
      const int32_t next = ch.next;
      ch.next = free_;
      free_ = c;
      c = next;
    }
    bk = Bucket{-1, -1, 0};
  }

  // The current bucket is used up: move on to the next one that holds
  // entries, and sort its live ones. False if no event is left.
  template <class Times> bool advance(const Times& time) {
    current_.clear();
    pos_ = 0;
    if (in_ring_ == 0 && in_fine_ == 0) {
      if (overflow_.empty()) return false;
      // Nothing before the overflow: jump to the turn of its earliest event.
      int64_t first = INT64_MAX;
      for (const int32_t leaf : overflow_) {
        const double t = time(leaf);
        if (t < kNever) first = std::min(first, bucket(t));
      }
      if (first == INT64_MAX) {
        overflow_.clear();
        return false;
      }
      const int64_t start = first & ~mask_; // after this turn (the overflow lies beyond it)
      if (start > current_bucket_) {
        turn_start_ = start - (mask_ + 1);
        current_bucket_ = start - 1;
      }
    }
    ++current_bucket_;
    if ((current_bucket_ & (kFine - 1)) == 0) { // a new coarse bucket
      if (current_bucket_ - turn_start_ > mask_) { // a new turn of the ring
        turn_start_ += mask_ + 1;
        size_t keep = 0;
        for (const int32_t leaf : overflow_) time.prefetch(leaf);
        for (const int32_t leaf : overflow_) {
          const double t = time(leaf);
          if (!(t < kNever)) continue;
          const int64_t b = bucket(t);
          if (b < turn_start_) continue; // stale: its leaf's entry is elsewhere
          if (b - turn_start_ <= mask_) {
            to_ring(leaf, b);
          } else {
            overflow_[keep++] = leaf;
          }
        }
        overflow_.resize(keep);
      }
      spread_coarse();
    }
    // The bucket's ids: their lines requested at once, stale ones dropped,
    // the rest sorted.
    drain_.swap(fine_[static_cast<size_t>(current_bucket_ & (kFine - 1))]);
    in_fine_ -= drain_.size();
    for (const int32_t leaf : drain_) time.prefetch(leaf);
    for (const int32_t leaf : drain_) {
      const double t = time(leaf);
      if (t < kNever && bucket(t) == current_bucket_) current_.push_back(Entry{t, leaf});
    }
    drain_.clear();
    std::sort(current_.begin(), current_.end(), before);
    // A leaf entered twice in this bucket appears twice: keep one.
    current_.erase(std::unique(current_.begin(), current_.end(),
                               [](const Entry& a, const Entry& b) { return a.time == b.time && a.leaf == b.leaf; }),
                   current_.end());
    return true;
  }

  double inv_w_ = 1;
  int64_t mask_ = 4 * kFine - 1;     // buckets in the ring, minus 1
  int64_t coarse_mask_ = 3;          // coarse buckets in the ring, minus 1
  int64_t current_bucket_ = 0, turn_start_ = 0;
  size_t in_ring_ = 0, in_fine_ = 0;
  bool suspended_ = true;
  std::vector<Entry> current_;
  size_t pos_ = 0;
  // The buckets of the current coarse bucket, as plain id lists: few, and
  // all in cache.
  std::vector<int32_t> fine_[kFine];
  // The ring of coarse buckets: each is a chain of chunks of 15 packed
  // entries (one cache line each) from a common pool, so memory follows
  // the number of entries, however unevenly they fall. The ring's heads,
  // tails and fills and its tail chunks are few enough to stay in cache: an
  // insertion far ahead writes a line that is already there (one
  // bucket per event would scatter the writes over thousands of lines).
  static constexpr uint32_t kChunk = 15;
  struct alignas(64) Chunk {
    uint32_t id[kChunk];
    int32_t next;
  };
  struct Bucket {
    int32_t head, tail;
    uint32_t fill; // ids in the tail chunk
  };
  std::vector<Bucket> ring_;
  std::vector<Chunk, BigArrayAlloc<Chunk>> chunks_;
  int32_t free_ = -1; // chain of free chunks
  std::vector<int32_t> drain_; // scratch: the ids of the bucket being read
  std::vector<int32_t> overflow_;
};

} // namespace dynhet::engine
