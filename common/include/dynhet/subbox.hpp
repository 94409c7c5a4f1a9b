// Sub-box grids: which m x m grids realise a list of sub-box sizes (mean
// particles per sub-box), nested so that one pass over the particles serves
// them all. Shared by the scene (which refuses duplicates and warns of
// sizes it cannot realise) and the analysis kernels (which build the grids).
#pragma once

#include <string>
#include <vector>

namespace dynhet {

// The side m of each target's grid, in the order given: every coarser side
// is the divisor of the next finer one nearest its own ideal
// sqrt(n_total / target), and the finest is the 2^a 3^b nearest its own
// ideal among those whose chain gives no two targets the same grid, if
// any does (so [64, 256, 1024, 4096, 16384] at N = 10^5 nest as 48, 24,
// 12, 6, 3, not 36, 18, 9, 3, 3). A target >= n_total gives 1 (the whole
// box).
std::vector<int> nested_subbox_sides(long n_total, const std::vector<int>& targets);

// What the grids of `targets` realise at n_total particles: targets whose
// grid another target already has are dropped (the one nearer its own
// grid is kept), and each is named in `notes`, as is every kept target
// whose realised size n_total / m^2 lies more than 25% from it. `key`
// names the scene key in the notes. Returns the targets kept, in order.
std::vector<int> realisable_subbox_sizes(long n_total, const std::vector<int>& targets, const std::string& key,
                                         std::vector<std::string>& notes);

} // namespace dynhet
