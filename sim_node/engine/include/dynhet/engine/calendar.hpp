// The event calendar: a complete binary tournament tree over one event time
// per leaf (each particle's next event, plus extra leaves such as the next
// kick). The root holds the leaf with the earliest time; changing a leaf's
// time costs O(log n).
#pragma once

#include <cstdint>
#include <vector>

namespace dynhet::engine {

class Calendar {
public:
  void reset(int n_leaves, double never) {
    n_ = n_leaves;
    size_ = 1;
    while (size_ < n_) size_ *= 2;
    time_.assign(size_, never);
    tree_.assign(2 * size_, 0);
    for (int i = 0; i < size_; ++i) tree_[size_ + i] = i;
    for (int v = size_ - 1; v >= 1; --v) tree_[v] = pick(tree_[2 * v], tree_[2 * v + 1]);
  }
  int top() const { return tree_[1]; }
  double top_time() const { return time_[tree_[1]]; }
  double time(int leaf) const { return time_[leaf]; }
  void set(int leaf, double t) {
    time_[leaf] = t;
    for (int v = (size_ + leaf) / 2; v >= 1; v /= 2) {
      const int m = pick(tree_[2 * v], tree_[2 * v + 1]);
      if (tree_[v] == m && m != leaf) break; // same winner, same time: nothing above changes
      tree_[v] = m;
    }
  }
  // Subtract dt from every time (rebasing the clock).
  void shift(double dt) {
    for (double& t : time_) t -= dt;
  }

private:
  // Earlier time wins; ties go to the lower leaf, so the order is reproducible.
  int pick(int a, int b) const { return time_[b] < time_[a] ? b : a; }
  int n_ = 0, size_ = 1;
  std::vector<double> time_;
  std::vector<int32_t> tree_;
};

} // namespace dynhet::engine
