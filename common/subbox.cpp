#include "dynhet/subbox.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace dynhet {

namespace {

bool smooth(int m) { // 2^a 3^b
  while (m % 2 == 0) m /= 2;
  while (m % 3 == 0) m /= 3;
  return m == 1;
}

// The chain from a given finest side: every coarser target takes the
// divisor of the next finer side nearest its ideal.
std::vector<int> chain(long n_total, const std::vector<int>& targets, const std::vector<int>& order, int finest) {
  std::vector<int> sides(targets.size(), 1);
  int finer = 0;
  for (int g : order) {
    const double want = std::max(1.0, std::sqrt(double(n_total) / targets[g]));
    int best = finer ? 1 : finest;
    if (finer)
      for (int m = 1; m <= finer; ++m)
        if (finer % m == 0 && std::abs(std::log(m / want)) < std::abs(std::log(best / want))) best = m;
    finer = best;
    sides[g] = best;
  }
  return sides;
}

} // namespace

std::vector<int> nested_subbox_sides(long n_total, const std::vector<int>& targets) {
  std::vector<int> order(targets.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return targets[a] < targets[b]; });
  if (order.empty()) return {};
  // The finest side: the 2^a 3^b nearest its ideal among those whose chain
  // gives no two targets (below N) the same grid, if any chain does.
  const double want = std::max(1.0, std::sqrt(double(n_total) / targets[order[0]]));
  std::vector<int> best;
  double best_cost = 0, best_near = 0;
  for (int m = 1; m <= 4 * static_cast<int>(want) + 4; ++m) {
    if (!smooth(m)) continue;
    const std::vector<int> sides = chain(n_total, targets, order, m);
    double cost = 0; // targets that share a grid with another (below N)
    for (size_t i = 0; i < targets.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (sides[j] == sides[i] && targets[i] < n_total && targets[j] < n_total) cost += 1;
    const double near = std::abs(std::log(m / want));
    if (best.empty() || cost < best_cost - 1e-12 || (std::abs(cost - best_cost) <= 1e-12 && near < best_near))
      best = sides, best_cost = cost, best_near = near;
  }
  return best;
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
