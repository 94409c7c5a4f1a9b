#pragma once
// The engine's parameters the engine and theory tests start from.
#include "dynhet/engine/engine.hpp"

inline dynhet::engine::Params params(long n, double phi, double eps, bool driving) {
  dynhet::engine::Params p;
  p.n_particles = n;
  p.packing_fraction = phi;
  p.restitution = eps;
  p.driving = driving;
  p.kick_rate = 8.0;
  p.seed = 42;
  return p;
}
