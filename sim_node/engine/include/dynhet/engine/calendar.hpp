// The event calendar: a complete 4-ary tournament tree over one event time
// per leaf (each particle's next event, plus extra leaves such as the next
// kick). The root holds the leaf with the earliest time (ties: the lower
// leaf); changing a leaf's time costs O(log n). Each node keeps its winner's
// time next to the winner's index, and the four children of a node are one
// 64-byte cache line: a change reads one line per level, and there are half
// as many levels as in a binary tree (at N = 10^5 every event replays about
// two paths from leaf to root, most of whose lines are not in cache).
//
// Layout: a 4-ary heap shifted by 3 places (0-2 are padding) so that every
// group of siblings starts on a multiple of 4: the root is at 3, the
// children of p at 4p - 8 .. 4p - 5, the parent of p at p / 4 + 2; the
// levels follow one another without gaps and the leaves are the last.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "dynhet/engine/memory.hpp"

namespace dynhet::engine {

class Calendar {
public:
  void reset(int n_leaves, double never) {
    size_t width = 1, internal = 0;
    while (width < static_cast<size_t>(n_leaves)) internal += width, width *= 4;
    first_leaf_ = kRoot + internal;
    // Only the leaves in use are stored (rounded up to a group of four):
    // an internal node whose children would all lie beyond them stays
    // "never" and is never on a leaf's path.
    const size_t leaves = (static_cast<size_t>(n_leaves) + 3) / 4 * 4;
    node_.assign(first_leaf_ + leaves, Node{never, 0});
    for (size_t i = 0; i < leaves; ++i) node_[first_leaf_ + i].leaf = static_cast<int32_t>(i);
    for (size_t p = first_leaf_; p-- > kRoot;)
      node_[p] = 4 * p - 8 < node_.size() ? pick_children(p) : Node{never, static_cast<int32_t>(leaves)};
  }
  size_t bytes() const { return node_.capacity() * sizeof(Node); }
  int top() const { return node_[kRoot].leaf; }
  double top_time() const { return node_[kRoot].time; }
  double time(int leaf) const { return node_[first_leaf_ + leaf].time; }
  // A time that comes earlier climbs while it wins; one that comes later is
  // replayed only where the leaf was the winner. Either loop stops at the
  // first node that does not change.
  // Requests the lines of a leaf's path to the root (those a set() of it
  // will read), all at once rather than one miss after another.
  void prefetch_path(int leaf) const {
    for (size_t q = first_leaf_ + leaf; q > kRoot; q = q / 4 + 2) __builtin_prefetch(&node_[q]);
  }
  void set(int leaf, double t) {
    size_t p = first_leaf_ + leaf;
    prefetch_path(leaf);
    const double old = node_[p].time;
    node_[p].time = t;
    if (t <= old) {
      while (p != kRoot) {
        p = p / 4 + 2;
        Node& n = node_[p];
        if (n.leaf != leaf && (n.time < t || (n.time == t && n.leaf < leaf))) break;
        n.time = t;
        n.leaf = leaf;
      }
    } else {
      while (p != kRoot) {
        p = p / 4 + 2;
        if (node_[p].leaf != leaf) break;
        node_[p] = pick_children(p);
      }
    }
  }
  // Subtract dt from every time (rebasing the clock).
  void shift(double dt) {
    for (Node& n : node_) n.time -= dt;
  }

private:
  struct Node {
    double time;
    int32_t leaf;
  };
  // Earlier time wins; ties go to the lower leaf, so the order is
  // reproducible. Without branches: which child wins is unpredictable.
  static Node pick(const Node& a, const Node& b) {
    const bool second = (b.time < a.time) | ((b.time == a.time) & (b.leaf < a.leaf));
    return Node{second ? b.time : a.time, second ? b.leaf : a.leaf};
  }
  static constexpr size_t kRoot = 3;
  Node pick_children(size_t p) const {
    const Node* c = &node_[4 * p - 8];
    return pick(pick(c[0], c[1]), pick(c[2], c[3]));
  }
  size_t first_leaf_ = 0;
  std::vector<Node, BigArrayAlloc<Node>> node_;
};

} // namespace dynhet::engine
