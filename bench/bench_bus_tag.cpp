// What the authenticated bus costs (docs/bus.md): the time to tag
// a message and to check a tag, per message size, and per frame of N
// particles (16 bytes a particle, in chunks as the sim sends them), on one
// core. A sim at N = 10^6 tags each frame once; each node and the recorder
// checks it once.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "dynhet/bus_auth.hpp"

namespace {
double seconds_of(const std::function<void()>& f, int reps) {
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}
} // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynhet bus tags: cost of tagging and checking messages"};
  std::vector<long> sizes{1000, 65536, 1 << 20, 16 << 20};
  std::vector<long> ns{100000, 1000000, 4000000};
  long chunk = 65536;
  int reps = 9;
  app.add_option("--bytes", sizes, "message sizes");
  app.add_option("--n", ns, "particle numbers (frames)");
  app.add_option("--chunk-particles", chunk, "particles per chunk (the scene's run.chunk_particles)");
  app.add_option("--reps", reps, "repetitions (the median is printed)");
  CLI11_PARSE(app, argc, argv);
  std::array<unsigned char, dynhet::BusKey::kBytes> k{};
  std::mt19937 g(1);
  for (auto& c : k) c = static_cast<unsigned char>(g());
  auto key = std::make_shared<const dynhet::BusKey>(k);
  dynhet::BusSigner signer(key, 0);
  std::printf("# one core, median of %d; tag: BusSigner::tag, check: BusVerifier::verify (a fresh window each time)\n",
              reps);
  std::printf("%12s %12s %12s %12s\n", "bytes", "tag_ms", "check_ms", "MB/s_check");
  for (long n : sizes) {
    std::vector<std::uint8_t> m(n + dynhet::kBusTagBytes);
    for (long i = 0; i < n; ++i) m[i] = static_cast<std::uint8_t>(g());
    const double ts = seconds_of([&] { signer.tag("DYNHET_FRAME", m.data(), n); }, reps);
    const double tv = seconds_of(
        [&] {
          dynhet::BusVerifier v(key, 0);
          std::size_t payload;
          if (v.verify("DYNHET_FRAME", m.data(), m.size(), payload) != dynhet::BusVerifier::Verdict::ok) std::abort();
        },
        reps);
    std::printf("%12ld %12.3f %12.3f %12.0f\n", n, 1e3 * ts, 1e3 * tv, n / tv / 1e6);
  }
  std::printf("\n%12s %12s %12s %12s\n", "N", "chunks", "tag_ms", "check_ms");
  for (long n : ns) {
    const long chunks = (n + chunk - 1) / chunk;
    const long bytes = 16 * chunk + 60; // positions and the chunk header
    std::vector<std::uint8_t> m(bytes + dynhet::kBusTagBytes, 7);
    const double ts = seconds_of([&] { for (long c = 0; c < chunks; ++c) signer.tag("DYNHET_FRAME", m.data(), bytes); }, reps);
    const double tv = seconds_of(
        [&] {
          dynhet::BusVerifier v(key, 0);
          std::size_t payload;
          for (long c = 0; c < chunks; ++c) {
            signer.tag("DYNHET_FRAME", m.data(), bytes);
            v.verify("DYNHET_FRAME", m.data(), m.size(), payload);
          }
        },
        reps) - ts;
    std::printf("%12ld %12ld %12.1f %12.1f\n", n, chunks, 1e3 * ts, 1e3 * tv);
  }
  return 0;
}
