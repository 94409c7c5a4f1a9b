// Rows of int32 members in one flat array: row r is data[r * stride ...],
// first its count, then its members. At the starting stride of 16 a row is
// one cache line (a count and up to 15 members), so reading a row is one
// miss and its members can all be requested at once. A full row doubles the
// stride of every row, contents and their order kept. Removal swaps the last
// member into the gap: the order within a row depends only on the sequence
// of pushes and removals, not on the capacity. The engine's cells and
// neighbour lists are both such rows. A row may start with a head of
// `head_words` int32 words of the owner's own data, before its count: the
// neighbour lists keep their list centre there, so that a prediction reads
// its list and its centre in one line (and a row of stride 16 then holds
// up to 11 members before the stride doubles).
#pragma once

#include <algorithm>
#include <cassert>
#include <cstring>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "dynhet/engine/memory.hpp"

namespace dynhet::engine {

class Rows {
public:
  explicit Rows(int head_words = 0) : head_(head_words) {}
  // n empty rows at the current stride (their heads zero).
  void reset(size_t n) {
    rows_ = n;
    data_.assign(n * stride_, 0);
  }
  int32_t* row(size_t r) { return &data_[r * stride_ + head_]; }
  const int32_t* row(size_t r) const { return &data_[r * stride_ + head_]; }
  // The head of row r as a T (trivially copyable, at most head_words words;
  // the width is the owner's choice at run time, so debug builds check it).
  template <class T> T head(size_t r) const {
    static_assert(std::is_trivially_copyable_v<T>);
    assert(sizeof(T) <= sizeof(int32_t) * static_cast<size_t>(head_));
    T v;
    std::memcpy(&v, &data_[r * stride_], sizeof v);
    return v;
  }
  template <class T> void set_head(size_t r, const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    assert(sizeof(T) <= sizeof(int32_t) * static_cast<size_t>(head_));
    std::memcpy(&data_[r * stride_], &v, sizeof v);
  }
  int head_words() const { return head_; }
  void prefetch(size_t r) const { __builtin_prefetch(&data_[r * stride_]); }
  void clear(size_t r) { row(r)[0] = 0; }
  void push(size_t r, int32_t v) {
    if (row(r)[0] == stride_ - head_ - 1) grow();
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
  // The same rows packed, for the checkpoint of a run stopped between
  // synchronised times (its size is what a stop waits for): each row's
  // count, then each member as the difference from a base, zigzag-coded
  // (small of either sign: small unsigned) in 7-bit groups, low first, the
  // high bit set on every byte but a number's last. The base is the row's
  // own index (`from_row`: neighbour and kick lists, whose members are
  // slots near their own, slots being sorted by cell) or the member before
  // it, across rows (cells: rows of slots in cell order). About 2 bytes a
  // member at N = 10^6 where save() takes 4; the order within each row is
  // kept exactly.
  void save_packed(std::vector<uint8_t>& out, bool from_row) const {
    out.clear();
    out.reserve(rows_ * 4);
    int64_t prev = 0;
    for (size_t r = 0; r < rows_; ++r) {
      const int32_t* c = row(r);
      put_varint(out, static_cast<uint64_t>(c[0]));
      if (from_row) prev = static_cast<int64_t>(r);
      for (int32_t k = 1; k <= c[0]; ++k) {
        const int64_t d = static_cast<int64_t>(c[k]) - prev;
        put_varint(out, (static_cast<uint64_t>(d) << 1) ^ static_cast<uint64_t>(d >> 63));
        if (!from_row) prev = c[k];
      }
    }
  }
  // n rows as save_packed() wrote them (the same `from_row`); false (the
  // rows then unusable) if `in` is not exactly n such rows of members in
  // [0, limit).
  bool load_packed(size_t n, const std::vector<uint8_t>& in, int32_t limit, bool from_row) {
    reset(n);
    const uint8_t* p = in.data();
    const uint8_t* const end = p + in.size();
    int64_t prev = 0;
    for (size_t r = 0; r < n; ++r) {
      uint64_t m = 0;
      if (!get_varint(p, end, m) || m > static_cast<uint64_t>(limit)) return false;
      if (from_row) prev = static_cast<int64_t>(r);
      for (uint64_t q = 0; q < m; ++q) {
        uint64_t z = 0;
        if (!get_varint(p, end, z)) return false;
        const int64_t d = static_cast<int64_t>(z >> 1) ^ -static_cast<int64_t>(z & 1);
        if (d > int64_t{1} << 33 || d < -(int64_t{1} << 33)) return false;
        const int64_t v = prev + d;
        if (v < 0 || v >= limit) return false;
        push(r, static_cast<int32_t>(v));
        if (!from_row) prev = v;
      }
    }
    return p == end;
  }
  static void put_varint(std::vector<uint8_t>& out, uint64_t v) {
    while (v >= 0x80) {
      out.push_back(static_cast<uint8_t>(v | 0x80));
      v >>= 7;
    }
    out.push_back(static_cast<uint8_t>(v));
  }
  // false: the bytes end inside a number, or it is longer than 64 bits.
  static bool get_varint(const uint8_t*& p, const uint8_t* end, uint64_t& v) {
    v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (p == end) return false;
      const uint8_t b = *p++;
      v |= static_cast<uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) return true;
    }
    return false;
  }

private:
  [[gnu::noinline, gnu::cold]] void grow() {
    const int old = stride_;
    stride_ *= 2;
    std::vector<int32_t, BigArrayAlloc<int32_t>> bigger(rows_ * stride_, 0);
    for (size_t r = 0; r < rows_; ++r)
      std::copy(&data_[r * old], &data_[r * old] + head_ + data_[r * old + head_] + 1, &bigger[r * stride_]);
    data_.swap(bigger);
  }
  int head_ = 0;
  size_t rows_ = 0;
  int stride_ = 16;
  std::vector<int32_t, BigArrayAlloc<int32_t>> data_;
};

} // namespace dynhet::engine
