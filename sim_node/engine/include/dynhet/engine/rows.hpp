// Rows of int32 members in one flat array: row r is data[r * stride ...],
// first its count, then its members. At the starting stride of 16 a row is
// one cache line (a count and up to 15 members), so reading a row is one
// miss and its members can all be requested at once. A full row doubles the
// stride of every row, contents and their order kept. Removal swaps the last
// member into the gap: the order within a row depends only on the sequence
// of pushes and removals, not on the capacity. The engine's cells and
// neighbour lists are both such rows.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dynhet/engine/memory.hpp"

namespace dynhet::engine {

class Rows {
public:
  // n empty rows at the current stride.
  void reset(size_t n) {
    rows_ = n;
    data_.assign(n * stride_, 0);
  }
  int32_t* row(size_t r) { return &data_[r * stride_]; }
  const int32_t* row(size_t r) const { return &data_[r * stride_]; }
  void prefetch(size_t r) const { __builtin_prefetch(&data_[r * stride_]); }
  void clear(size_t r) { data_[r * stride_] = 0; }
  void push(size_t r, int32_t v) {
    if (data_[r * stride_] == stride_ - 1) grow();
    int32_t* c = row(r);
    c[++c[0]] = v;
  }
  void remove(size_t r, int32_t v) {
    int32_t* c = row(r);
    int k = 1;
    while (c[k] != v) ++k;
    c[k] = c[c[0]--];
  }
  size_t bytes() const { return data_.capacity() * sizeof(int32_t); }
  // Every row as its count and then its members, in order (checkpoints
  // between synchronised times: the order of a row decides later ones).
  void save(std::vector<int32_t>& out) const {
    out.clear();
    for (size_t r = 0; r < rows_; ++r) {
      const int32_t* c = row(r);
      out.insert(out.end(), c, c + c[0] + 1);
    }
  }
  // n rows as save() wrote them; false (the rows then unusable) if `in` is
  // not n such rows of members in [0, limit).
  bool load(size_t n, const std::vector<int32_t>& in, int32_t limit) {
    reset(n);
    size_t k = 0;
    for (size_t r = 0; r < n; ++r) {
      if (k >= in.size()) return false;
      const int32_t m = in[k++];
      if (m < 0 || in.size() - k < static_cast<size_t>(m)) return false;
      for (int32_t q = 0; q < m; ++q, ++k) {
        if (in[k] < 0 || in[k] >= limit) return false;
        push(r, in[k]);
      }
    }
    return k == in.size();
  }

private:
  [[gnu::noinline, gnu::cold]] void grow() {
    const int old = stride_;
    stride_ *= 2;
    std::vector<int32_t, BigArrayAlloc<int32_t>> bigger(rows_ * stride_, 0);
    for (size_t r = 0; r < rows_; ++r)
      std::copy(&data_[r * old], &data_[r * old] + data_[r * old] + 1, &bigger[r * stride_]);
    data_.swap(bigger);
  }
  size_t rows_ = 0;
  int stride_ = 16;
  std::vector<int32_t, BigArrayAlloc<int32_t>> data_;
};

} // namespace dynhet::engine
