// What a random memory access costs on this machine against the size of the
// memory it lands in: the ceiling on how well an engine whose events land
// anywhere in the box can keep its rate as N grows.
//
// A buffer of S MiB is cut into 64-byte lines linked in one random cycle
// (each line holds the address of the next). Following the links is a chain
// of dependent loads: with one chain, each load waits for the one before
// (the latency); with K chains followed side by side, K loads are in flight
// at once, as the engine's requests ahead of its events are (the cost per
// load when the memory system overlaps them). Each case is measured on 4 KiB
// pages and on the transparent huge pages the engine advises its big arrays
// to (dynhet/engine/memory.hpp; the kernel must be in madvise or always
// mode), --reps times, and the median is printed with the ratio to the
// size --ref (the footprint of N = 10^5: 21 to 26 MB). The last column,
// "paged", follows one chain on huge pages that takes every line of a 4 KiB
// page (in random order) before it moves to the next (pages in random
// order): the same lines missed, a new translation once every 64 loads. Where
// it is fast and the random chain is slow, the random chain's cost is the
// address translation, not the cache.
//
//   bench_memory                       # 1 to 1024 MiB, 1 and 8 chains
//   bench_memory --mib 24 --mib 256 --chains 16 --reps 5
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace {

struct Buffer {
  char* p = nullptr;
  std::size_t bytes = 0;
  Buffer(std::size_t b, bool huge) : bytes(b) {
    void* m = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) throw std::runtime_error("mmap of " + std::to_string(bytes >> 20) + " MiB failed");
    p = static_cast<char*>(m);
    madvise(p, bytes, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
    std::memset(p, 0, bytes); // touch every page before timing
  }
  ~Buffer() { munmap(p, bytes); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
};

struct Xorshift {
  uint64_t s;
  uint64_t operator()() { return s ^= s << 13, s ^= s >> 7, s ^= s << 17; }
};

// One cycle through every line, written as links: in random order
// (Sattolo's shuffle), or, grouped, the 4 KiB pages in random order and the
// 64 lines of each page in random order before the next page: the same
// cache misses, but a new page (a translation) once every 64 loads.
void link_cycle(Buffer& b, uint64_t seed, bool grouped) {
  const std::size_t n = b.bytes / 64;
  std::vector<uint32_t> order(n);
  Xorshift rnd{seed | 1};
  if (!grouped) {
    for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
    for (std::size_t i = n - 1; i > 0; --i) std::swap(order[i], order[rnd() % i]);
  } else {
    std::vector<uint32_t> pages(n / 64);
    for (std::size_t k = 0; k < pages.size(); ++k) pages[k] = static_cast<uint32_t>(k);
    for (std::size_t k = pages.size() - 1; k > 0; --k) std::swap(pages[k], pages[rnd() % (k + 1)]);
    for (std::size_t k = 0; k < pages.size(); ++k) {
      uint32_t* line = &order[k * 64];
      for (uint32_t l = 0; l < 64; ++l) line[l] = pages[k] * 64 + l;
      for (int l = 63; l > 0; --l) std::swap(line[l], line[rnd() % (l + 1)]);
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    *reinterpret_cast<char**>(b.p + std::size_t{order[i]} * 64) = b.p + std::size_t{order[(i + 1) % n]} * 64;
}

// ns per load, following `chains` links side by side, `loads` loads in all.
double chase(const Buffer& b, int chains, std::size_t loads) {
  const std::size_t n = b.bytes / 64;
  std::vector<char*> at(chains);
  for (int c = 0; c < chains; ++c) at[c] = b.p + (n / chains) * c * 64; // starts spread along the cycle's storage
  const std::size_t rounds = loads / chains;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t r = 0; r < rounds; ++r)
    for (int c = 0; c < chains; ++c) at[c] = *reinterpret_cast<char**>(at[c]);
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  uintptr_t sink = 0;
  for (char* a : at) sink ^= reinterpret_cast<uintptr_t>(a);
  if (sink == 1) std::puts(""); // keeps the loads
  return dt / static_cast<double>(rounds * chains) * 1e9;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"the cost of a random load against the memory it lands in (4 KiB and huge pages)"};
  std::vector<std::size_t> mib{1, 2, 4, 8, 16, 24, 64, 256, 1024};
  std::vector<int> chains{1, 8};
  std::size_t ref = 24, loads = 4000000;
  int reps = 3;
  app.add_option("--mib", mib, "buffer sizes in MiB")->check(CLI::Range(std::size_t{1}, std::size_t{16384}));
  app.add_option("--chains", chains, "loads in flight at once (independent chains)")->check(CLI::Range(1, 64));
  app.add_option("--ref", ref, "the size (MiB) the ratios are taken against")->check(CLI::Range(std::size_t{1}, std::size_t{16384}));
  app.add_option("--loads", loads, "loads timed per measurement")->check(CLI::Range(std::size_t{1000}, std::size_t{1} << 34));
  app.add_option("--reps", reps, "measurements per case (the median is printed)")->check(CLI::Range(1, 99));
  CLI11_PARSE(app, argc, argv);
  if (std::find(mib.begin(), mib.end(), ref) == mib.end()) mib.push_back(ref);
  std::sort(mib.begin(), mib.end());
  mib.erase(std::unique(mib.begin(), mib.end()), mib.end());

  std::vector<double> grouped(mib.size()); // huge pages, one chain, a page's lines together
  // ns[size][pages][chains]
  std::vector<std::vector<std::vector<double>>> ns(mib.size(), std::vector<std::vector<double>>(2, std::vector<double>(chains.size())));
  for (std::size_t s = 0; s < mib.size(); ++s)
    for (int huge = 0; huge < 2; ++huge) {
      Buffer b(mib[s] << 20, huge == 1);
      link_cycle(b, 0x9e3779b97f4a7c15ULL + mib[s], false);
      for (std::size_t c = 0; c < chains.size(); ++c) {
        chase(b, chains[c], std::max<std::size_t>(loads / 8, 1000)); // warm the caches and the TLB
        std::vector<double> v;
        for (int r = 0; r < reps; ++r) v.push_back(chase(b, chains[c], loads));
        ns[s][huge][c] = median(v);
      }
      if (huge == 1) { // the same misses, a page change once every 64 loads
        link_cycle(b, 0x9e3779b97f4a7c15ULL + mib[s], true);
        chase(b, 1, std::max<std::size_t>(loads / 8, 1000));
        std::vector<double> v;
        for (int r = 0; r < reps; ++r) v.push_back(chase(b, 1, loads));
        grouped[s] = median(v);
      }
      std::fprintf(stderr, "  %zu MiB, %s pages: done\n", mib[s], huge ? "huge" : "4 KiB");
    }
  const std::size_t r = std::find(mib.begin(), mib.end(), ref) - mib.begin();
  std::printf("ns per load, median of %d; 4kxK / hugexK: 4 KiB or huge pages, K chains in flight; ref/x: the rate against %zu MiB's (the same pages and chains); paged: huge pages, one chain, a page's lines together\n", reps, ref);
  std::printf("%8s", "MiB");
  for (const char* pg : {"4k", "huge"})
    for (int k : chains) std::printf(" %9s %7s", (std::string(pg) + "x" + std::to_string(k)).c_str(), "ref/x");
  std::printf(" %9s\n", "paged");
  for (std::size_t s = 0; s < mib.size(); ++s) {
    std::printf("%8zu", mib[s]);
    for (int huge = 0; huge < 2; ++huge)
      for (std::size_t c = 0; c < chains.size(); ++c) std::printf(" %9.1f %7.2f", ns[s][huge][c], ns[r][huge][c] / ns[s][huge][c]);
    std::printf(" %9.1f\n", grouped[s]);
  }
  return 0;
}
