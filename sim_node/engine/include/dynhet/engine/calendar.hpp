// The event calendar: a complete binary tournament tree over one event time
// per leaf (each particle's next event, plus extra leaves such as the next
// kick). The root holds the leaf with the earliest time; changing a leaf's
// time costs O(log n). Each node keeps its winner's time next to the
// winner's index, so a change reads one cache line per level (siblings
// share it) instead of jumping to the leaves' times.
#pragma once

#include <cstdint>
#include <vector>

#include "dynhet/engine/memory.hpp"

namespace dynhet::engine {

class Calendar {
public:
  void reset(int n_leaves, double never) {
    size_ = 1;
    while (size_ < n_leaves) size_ *= 2;
    node_.assign(2 * static_cast<size_t>(size_), Node{never, 0});
    for (int i = 0; i < size_; ++i) node_[size_ + i].leaf = i;
    for (int v = size_ - 1; v >= 1; --v) node_[v] = pick(node_[2 * v], node_[2 * v + 1]);
  }
  size_t bytes() const { return node_.capacity() * sizeof(Node); }
  int top() const { return node_[1].leaf; }
  double top_time() const { return node_[1].time; }
  double time(int leaf) const { return node_[size_ + leaf].time; }
  // A time that comes earlier climbs while it wins; one that comes later is
  // replayed only where the leaf was the winner. Either loop stops at the
  // first node that does not change.
  void set(int leaf, double t) {
    int v = size_ + leaf;
    const double old = node_[v].time;
    node_[v].time = t;
    if (t <= old) {
      for (v /= 2; v >= 1; v /= 2) {
        Node& n = node_[v];
        if (n.leaf != leaf && (n.time < t || (n.time == t && n.leaf < leaf))) break;
        n.time = t;
        n.leaf = leaf;
      }
    } else {
      for (v /= 2; v >= 1 && node_[v].leaf == leaf; v /= 2) node_[v] = pick(node_[2 * v], node_[2 * v + 1]);
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
  // Earlier time wins; ties go to the lower leaf, so the order is reproducible.
  // Without branches: which child wins is unpredictable.
  static Node pick(const Node& a, const Node& b) {
    const bool second = (b.time < a.time) | ((b.time == a.time) & (b.leaf < a.leaf));
    return Node{second ? b.time : a.time, second ? b.leaf : a.leaf};
  }
  int size_ = 1;
  std::vector<Node, BigArrayAlloc<Node>> node_;
};

} // namespace dynhet::engine
