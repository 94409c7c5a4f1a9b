#include "dynhet/subbox.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace dynhet {

std::vector<int> nested_subbox_sides(long n_total, const std::vector<int>& targets) {
  std::vector<int> order(targets.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return targets[a] < targets[b]; });
  std::vector<int> sides(targets.size(), 1);
  int finer = 0; // side of the next finer grid (0: none yet)
  for (int g : order) {
    const double want = std::max(1.0, std::sqrt(double(n_total) / targets[g]));
    int best = 1;
    // Candidates: the 2^a 3^b for the finest grid, divisors of the finer side after.
    for (int m = 1; m <= (finer ? finer : 4 * static_cast<int>(want) + 4); ++m) {
      int k = m;
      while (k % 2 == 0) k /= 2;
      while (k % 3 == 0) k /= 3;
      const bool ok = finer ? finer % m == 0 : k == 1;
      if (ok && std::abs(std::log(m / want)) < std::abs(std::log(best / want))) best = m;
    }
    finer = best;
    sides[g] = best;
  }
  return sides;
}

std::vector<int> realisable_subbox_sizes(long n_total, const std::vector<int>& targets, const std::string& key,
                                         std::vector<std::string>& notes) {
  const std::vector<int> sides = nested_subbox_sides(n_total, targets);
  auto realised = [&](int m) { return double(n_total) / (double(m) * m); };
  // How far a target lies from what its grid holds (a target >= N asks for
  // the whole box and lies nowhere).
  auto miss = [&](size_t i) {
    return targets[i] >= n_total ? 0.0 : std::abs(std::log(realised(sides[i]) / targets[i]));
  };
  std::vector<int> kept;
  char buf[400];
  for (size_t i = 0; i < targets.size(); ++i) {
    size_t best = i;
    for (size_t j = 0; j < targets.size(); ++j)
      if (sides[j] == sides[i] && (miss(j) < miss(best) || (miss(j) == miss(best) && j < best))) best = j;
    if (best != i) {
      std::snprintf(buf, sizeof buf,
                    "%s: %d particles per sub-box is not realised at N = %ld: its nearest grid (%d x %d, %.1f "
                    "particles) is the one of %d already; dropped",
                    key.c_str(), targets[i], n_total, sides[i], sides[i], realised(sides[i]), targets[best]);
      notes.push_back(buf);
      continue;
    }
    if (targets[i] < n_total && miss(i) > std::log(1.25)) {
      std::snprintf(buf, sizeof buf,
                    "%s: %d particles per sub-box is realised as %.1f (a %d x %d grid nested in the finer ones) at "
                    "N = %ld",
                    key.c_str(), targets[i], realised(sides[i]), sides[i], sides[i], n_total);
      notes.push_back(buf);
    }
    kept.push_back(targets[i]);
  }
  return kept;
}

} // namespace dynhet
