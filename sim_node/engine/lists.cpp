// The neighbour lists and kick lists (engine.hpp, class Engine): each
// particle's list centre, the list criteria, building every list at a
// synchronisation and one particle's lists again when it leaves its skin.
#include "dynhet/engine/engine.hpp"

#include <algorithm>
#include <stdexcept>

namespace dynhet::engine {

// ---------------------------------------------------------------- lists

// Whether j is one of i's kick candidates. With the list scale at 1 (the
// run), near() implies kick_near(): the same sums with kick_reach > 0 added.
bool Engine::kick_near(int i, int j) const {
  const Centre a = centre(i), b = centre(j);
  const double dx = min_image(a.x - b.x), dy = min_image(a.y - b.y);
  const double reach = radius_[species_[i]] + radius_[species_[j]] + p_.kick_reach + skin_ + list_margin_;
  return dx * dx + dy * dy <= reach * reach;
}

bool Engine::near(int i, int j) const {
  const Centre a = centre(i), b = centre(j);
  const double dx = min_image(a.x - b.x), dy = min_image(a.y - b.y);
  const double reach = list_scale_ * (radius_[species_[i]] + radius_[species_[j]]) + skin_ + list_margin_;
  return dx * dx + dy * dy <= reach * reach;
}

bool Engine::kick_lists_apart() const {
  for (long i = 0; i < n_; ++i) {
    const int32_t *a = list(static_cast<int>(i)), *b = kick_beyond_.row(static_cast<size_t>(i));
    for (int q = 1; q <= b[0]; ++q)
      if (b[q] == i || std::find(a + 1, a + 1 + a[0], b[q]) != a + 1 + a[0]) return false;
  }
  return true;
}

void Engine::wrap(int i) {
  Particle& a = part_[i];
  // x + box rounds to box for x just below 0: such a particle is put at 0
  // (its own image), so that wrapping again changes nothing.
  if (a.x >= box_) a.x -= box_, ++image_x_[i];
  else if (a.x < 0) {
    a.x += box_, --image_x_[i];
    if (a.x >= box_) a.x = 0, ++image_x_[i];
  }
  if (a.y >= box_) a.y -= box_, ++image_y_[i];
  else if (a.y < 0) {
    a.y += box_, --image_y_[i];
    if (a.y >= box_) a.y = 0, ++image_y_[i];
  }
}

void Engine::build_lists() {
  const bool kl = kick_lists();
  kick_beyond_.reset(kl ? static_cast<size_t>(n_) : 0);
  for (long i = 0; i < n_; ++i) {
    wrap(static_cast<int>(i));
    set_centre(static_cast<int>(i), part_[i].x, part_[i].y);
    nbr_.clear(i);
  }
  build_cells(); // over the centres
  for (long il = 0; il < n_; ++il) {
    const int i = static_cast<int>(il);
    int around[9];
    cells_around(cell_x_[i], cell_y_[i], around);
    for (const int ci : around) {
      const int32_t* c = cells_.row(ci);
      for (int k = 1; k <= c[0]; ++k)
        if (c[k] > i) {
          if (near(i, c[k])) link(i, c[k]);
          else if (kl && kick_near(i, c[k])) link_kick(i, c[k]);
        }
    }
  }
}

// i (synchronised) has reached the edge of its skin: it leaves its old
// neighbours' lists, takes its position as its centre and lists everyone
// whose centre is near, in both directions.
void Engine::rebuild(int i) {
  wrap(i);
  const int cx = cell_coord(part_[i].x), cy = cell_coord(part_[i].y);
  // Every line this needs is a miss at large N: the old neighbours' lists
  // and the 9 cells are requested first, then the candidates' centres and
  // particles, each group before any of it is waited for.
  int cells[9]; // as indices: inserting i below may reallocate the cells
  cells_around(cx, cy, cells);
  for (const int ci : cells) cells_.prefetch(ci);
  {
    const int32_t* l = list(i);
    for (int k = 1; k <= l[0]; ++k) nbr_.prefetch(l[k]);
    for (int k = 1; k <= l[0]; ++k) nbr_.remove(l[k], i);
  }
  nbr_.clear(i);
  const bool kl = kick_lists();
  if (kl) {
    const int32_t* l = kick_beyond_.row(i);
    for (int k = 1; k <= l[0]; ++k) kick_beyond_.prefetch(l[k]);
    for (int k = 1; k <= l[0]; ++k) kick_beyond_.remove(l[k], i);
    kick_beyond_.clear(i);
  }
  set_centre(i, part_[i].x, part_[i].y);
  if (cx != cell_x_[i] || cy != cell_y_[i]) {
    cell_remove(i);
    cell_insert(i, cx, cy);
  }
  constexpr int kMax = 512;
  int32_t cand[kMax];
  int nc = 0;
  for (const int ci : cells) {
    const int32_t* c = cells_.row(ci);
    if (nc + c[0] > kMax) throw std::logic_error("engine: more than 512 list candidates");
    for (int k = 1; k <= c[0]; ++k) {
      const int j = c[k];
      nbr_.prefetch(j); // its centre
      cand[nc++] = j;
    }
  }
  for (int k = 0; k < nc; ++k) {
    const int j = cand[k];
    if (j == i) continue;
    if (near(i, j)) link(i, j);
    else if (kl && kick_near(i, j)) link_kick(i, j);
  }
  ++count_.rebuilds;
  predict(i);
}

} // namespace dynhet::engine
