// xoshiro256** with splitmix64 seeding: small, fast, and its whole state is
// four integers (easy to checkpoint). Same seed, same sequence, any build.
#pragma once

#include <cmath>
#include <cstdint>

namespace dynhet::engine {

// A stateless 64-bit mix (splitmix64's finaliser): hash(k) for counters k
// is a good uniform sequence.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Rng {
public:
  explicit Rng(uint64_t seed = 1) {
    for (auto& w : s_) {
      seed += 0x9e3779b97f4a7c15ULL;
      w = mix64(seed);
    }
  }
  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  // Uniform in [0, 1).
  double uniform() { return (next() >> 11) * 0x1.0p-53; }
  // Uniform integer in [0, n).
  uint64_t below(uint64_t n) { return static_cast<uint64_t>(uniform() * n); }
  // Two independent standard normals (Box-Muller).
  void normal_pair(double& a, double& b) {
    const double u = 1.0 - uniform(); // (0, 1]
    const double r = std::sqrt(-2.0 * std::log(u)), phi = 2.0 * M_PI * uniform();
    a = r * std::cos(phi);
    b = r * std::sin(phi);
  }
  // Exponential with rate `rate`.
  double exponential(double rate) { return -std::log(1.0 - uniform()) / rate; }

  const uint64_t* state() const { return s_; }
  void set_state(const uint64_t* s) {
    for (int i = 0; i < 4; ++i) s_[i] = s[i];
  }

private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
};

} // namespace dynhet::engine
