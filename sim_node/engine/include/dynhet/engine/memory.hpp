// Allocation for the engine's big arrays: cache-line aligned, and for arrays
// of 2 MiB or more backed by transparent huge pages where the kernel offers
// them (madvise mode). Every event touches particles, lists and cells
// at random places of arrays of several MB; with 4 KiB pages most of
// those accesses also miss the TLB.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>

namespace dynhet::engine {

template <class T> struct BigArrayAlloc {
  using value_type = T;
  static constexpr std::size_t kHuge = std::size_t{2} << 20;
  BigArrayAlloc() = default;
  template <class U> BigArrayAlloc(const BigArrayAlloc<U>&) {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHuge) return static_cast<T*>(::operator new(bytes, std::align_val_t(64)));
    const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
    void* p = ::operator new(rounded, std::align_val_t(kHuge));
    static const bool no_huge = std::getenv("DYNHET_NO_HUGEPAGES") != nullptr;
    if (!no_huge) madvise(p, rounded, MADV_HUGEPAGE); // advice only: without huge pages it still works
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) {
    ::operator delete(p, n * sizeof(T) < kHuge ? std::align_val_t(64) : std::align_val_t(kHuge));
  }
  template <class U> bool operator==(const BigArrayAlloc<U>&) const { return true; }
  template <class U> bool operator!=(const BigArrayAlloc<U>&) const { return false; }
};

} // namespace dynhet::engine
