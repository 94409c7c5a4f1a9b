// The collision rule and the collision time of two disks: pure functions.
#pragma once

#include <cmath>
#include <limits>

namespace dynhet::engine {

inline constexpr double kNever = std::numeric_limits<double>::infinity();

// Nearest periodic image of a separation component d in a box of side
// `box` (half_box = box / 2), for |d| below 1.5 box.
inline double nearest_image(double d, double box, double half_box) {
  return d > half_box ? d - box : (d < -half_box ? d + box : d);
}

// Time from now until disks at separation (dx, dy) (r_i - r_j) with relative
// velocity (gx, gy) (v_i - v_j) touch, their contact distance being sigma now
// and growing at rate `growth` (0 except while compressing). Root of
// |dr + g t|^2 = (sigma + growth t)^2 in the cancellation-free form
// t = C / (-B + sqrt(B^2 - A C)), A = g^2 - growth^2, B = dr.g - sigma growth,
// C = dr^2 - sigma^2. A pair that is not approaching (B >= 0) never collides
// unless the growth outruns it (A < 0); an approaching pair that overlaps by
// roundoff (C <= 0) collides at once. Every case is computed and the answer
// picked by selects, without a branch: the engine calls this for a block of
// neighbours at once, as vector code (half the pairs recede, at random, and
// a branch per pair cost more in mispredictions than the arithmetic).
inline double pair_collision_time(double dx, double dy, double gx, double gy, double sigma,
                                  double growth = 0.0) {
  const double B = dx * gx + dy * gy - sigma * growth;
  const double A = gx * gx + gy * gy - growth * growth;
  const double C = dx * dx + dy * dy - sigma * sigma;
  const double disc = B * B - A * C;
  const double root = C / (-B + std::sqrt(disc));
  double t = disc > 0 ? root : kNever;
  t = C <= 0 ? (B < 0 ? 0.0 : kNever) : t;
  return B >= 0 && A >= 0 ? kNever : t;
}

// Paper eq. (1)-(3): (g.n)' = -eps (g.n) with n = (r_i - r_j)/|r_i - r_j|,
//   m_i v_i' = m_i v_i - mu (1 + eps) (g.n) n,   m_j v_j' = m_j v_j + mu (1 + eps) (g.n) n,
// mu = m_i m_j / (m_i + m_j). While compressing, the surfaces move apart at
// `growth` and the rule holds in their frame: (g.n - growth)' = -eps (g.n - growth).
// Changes the velocities in place and returns the normal momentum transfer
// mu (1 + eps) |g.n - growth| (for the collision virial), or 0 if the pair
// is not approaching (then nothing changes).
inline double collide_pair(double dx, double dy, double mi, double mj, double eps, double& vix,
                           double& viy, double& vjx, double& vjy, double growth = 0.0) {
  const double d = std::sqrt(dx * dx + dy * dy);
  const double nx = dx / d, ny = dy / d;
  const double gn = (vix - vjx) * nx + (viy - vjy) * ny - growth;
  if (gn >= 0) return 0.0;
  const double mu = mi * mj / (mi + mj);
  const double impulse = mu * (1.0 + eps) * gn; // negative
  vix -= impulse / mi * nx;
  viy -= impulse / mi * ny;
  vjx += impulse / mj * nx;
  vjy += impulse / mj * ny;
  return -impulse;
}

} // namespace dynhet::engine
