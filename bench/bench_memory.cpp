// What a random memory access costs on this machine against the size of the
// memory it lands in: the ceiling on how well an engine whose events land
// anywhere in the box can keep its rate as N grows.
//
// A walk through a buffer of S MiB reads one 64-byte line after another,
// each drawn at random from the word read before (a chain of dependent
// loads, each landing anywhere, as an event's particle does: where a share
// of the buffer is in the cache, about that share of the loads hits it).
// With one walk, each load waits for the one before (the latency); with K
// walks side by side, K loads are in flight at once, as the engine's
// requests ahead of its events are (the cost per load when the memory
// system overlaps them). Each case is measured on 4 KiB pages and on the
// transparent huge pages the engine advises its big arrays to
// (dynhet/engine/memory.hpp; the kernel must be in madvise or always mode;
// the last column says how much of the buffer it gave them), --reps times
// from other starts, and the median is printed with the ratio to the size
// --ref (the footprint of N = 10^5: 21 to 26 MB). The hash adds a few ns to
// every load, at every size.
//
//   bench_memory                       # 1 to 1024 MiB, 1 and 8 walks
//   bench_memory --mib 24 --mib 256 --walks 4 --walks 8 --walks 16 --reps 5
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
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
    madvise(p, bytes, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE); // fill_random() then touches every page
  }
  ~Buffer() { munmap(p, bytes); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
};

// Each line's first word is random. A walk reads the word of its line and
// takes its next line from it (a hash of the word and the step), so each
// load waits for the one before and lands on a line drawn at random anew,
// as an event's particle is: where the buffer is C / S in the cache, about
// that share of the loads hit it (a fixed cycle through every line would
// hit nothing once the buffer outgrows the cache).
void fill_random(Buffer& b, uint64_t seed) {
  uint64_t s = seed | 1;
  for (std::size_t i = 0; i < b.bytes / 64; ++i) {
    s ^= s << 13, s ^= s >> 7, s ^= s << 17;
    *reinterpret_cast<uint64_t*>(b.p + i * 64) = s;
  }
}

inline uint64_t mix(uint64_t v) { // a 64-bit finaliser (splitmix64's)
  v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ULL;
  v = (v ^ (v >> 27)) * 0x94d049bb133111ebULL;
  return v ^ (v >> 31);
}
inline std::size_t below(uint64_t h, std::size_t n) { // h scaled to [0, n) without a division
  return static_cast<std::size_t>((static_cast<unsigned __int128>(h) * n) >> 64);
}

// ns per load, `walks` walks side by side, `loads` loads in all. Each
// step hashes the word read with the walk's own step number, so two walks
// that meet on a line part again at once (the loads in flight stay
// `walks`); `seed` places the starts, so that repetitions take other paths.
double walk(const Buffer& b, int walks, std::size_t loads, uint64_t seed) {
  const std::size_t n = b.bytes / 64;
  std::vector<std::size_t> at(walks);
  for (int c = 0; c < walks; ++c) at[c] = below(mix(seed * 0x9e3779b97f4a7c15ULL + c), n);
  const std::size_t rounds = loads / walks;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t r = 0; r < rounds; ++r)
    for (int c = 0; c < walks; ++c)
      at[c] = below(mix(*reinterpret_cast<const uint64_t*>(b.p + at[c] * 64) + r * walks + c), n);
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::size_t sink = 0;
  for (const std::size_t a : at) sink ^= a;
  if (sink == n) std::puts(""); // keeps the loads
  return dt / static_cast<double>(rounds * walks) * 1e9;
}

// The process's memory on transparent huge pages (AnonHugePages of
// /proc/self/smaps_rollup), in MiB; -1 where it cannot be read.
long huge_mib() {
  std::FILE* f = std::fopen("/proc/self/smaps_rollup", "r");
  if (!f) return -1;
  char line[256];
  long kb = -1;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "AnonHugePages: %ld kB", &kb) == 1) break;
  std::fclose(f);
  return kb < 0 ? -1 : kb / 1024;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"the cost of a random load against the memory it lands in (4 KiB and huge pages)"};
  std::vector<std::size_t> mib{1, 4, 8, 12, 16, 24, 32, 64, 256, 1024};
  std::vector<int> walks{1, 8};
  std::size_t ref = 24, loads = 4000000;
  int reps = 3;
  app.add_option("--mib", mib, "buffer sizes in MiB")->check(CLI::Range(std::size_t{1}, std::size_t{16384}));
  app.add_option("--walks", walks, "loads in flight at once (independent walks)")->check(CLI::Range(1, 64));
  app.add_option("--ref", ref, "the size (MiB) the ratios are taken against")->check(CLI::Range(std::size_t{1}, std::size_t{16384}));
  app.add_option("--loads", loads, "loads timed per measurement")->check(CLI::Range(std::size_t{1000}, std::size_t{1} << 34));
  app.add_option("--reps", reps, "measurements per case (the median is printed)")->check(CLI::Range(1, 99));
  CLI11_PARSE(app, argc, argv);
  if (std::find(mib.begin(), mib.end(), ref) == mib.end()) mib.push_back(ref);
  std::sort(mib.begin(), mib.end());
  mib.erase(std::unique(mib.begin(), mib.end()), mib.end());

  // ns[size][pages][walks]; granted[size]: MiB of the huge-page buffer the kernel gave huge pages
  std::vector<std::vector<std::vector<double>>> ns(mib.size(), std::vector<std::vector<double>>(2, std::vector<double>(walks.size())));
  std::vector<long> granted(mib.size(), -1);
  for (std::size_t s = 0; s < mib.size(); ++s)
    for (int huge = 0; huge < 2; ++huge) {
      Buffer b(mib[s] << 20, huge == 1);
      fill_random(b, 0x9e3779b97f4a7c15ULL + mib[s]);
      if (huge == 1) granted[s] = huge_mib();
      for (std::size_t c = 0; c < walks.size(); ++c) {
        walk(b, walks[c], std::max<std::size_t>(loads / 8, 1000), 0); // warm the caches and the TLB
        std::vector<double> v;
        for (int r = 0; r < reps; ++r) v.push_back(walk(b, walks[c], loads, r + 1));
        ns[s][huge][c] = median(v);
      }
      std::fprintf(stderr, "  %zu MiB, %s pages: done\n", mib[s], huge ? "huge" : "4 KiB");
    }
  const std::size_t r = std::find(mib.begin(), mib.end(), ref) - mib.begin();
  std::printf("ns per load, median of %d; 4kxK / hugexK: 4 KiB or huge pages, K walks (loads in flight); "
              "ref/x: %zu MiB's time over this one (the same pages and walks); on huge: MiB of the buffer the kernel "
              "gave huge pages\n", reps, ref);
  std::printf("%8s", "MiB");
  for (const char* pg : {"4k", "huge"})
    for (int k : walks) std::printf(" %9s %7s", (std::string(pg) + "x" + std::to_string(k)).c_str(), "ref/x");
  std::printf(" %8s\n", "on huge");
  for (std::size_t s = 0; s < mib.size(); ++s) {
    std::printf("%8zu", mib[s]);
    for (int huge = 0; huge < 2; ++huge)
      for (std::size_t c = 0; c < walks.size(); ++c) std::printf(" %9.1f %7.2f", ns[s][huge][c], ns[r][huge][c] / ns[s][huge][c]);
    std::printf(" %8ld\n", granted[s]);
  }
  return 0;
}
