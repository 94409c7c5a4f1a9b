// The paper's model in reduced units: r1 = 1, m1 = 1, m ~ r^2, 50:50.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace dynhet {

struct Model {
  double radius[2];
  double mass[2];
  double box_length;
};

// Box side for n disks (half small, half large; the odd one is small) at
// packing fraction phi.
inline Model make_model(long n, double phi, double radius_ratio) {
  Model m{};
  m.radius[0] = 1.0;
  m.radius[1] = radius_ratio;
  m.mass[0] = 1.0;
  m.mass[1] = radius_ratio * radius_ratio; // m2/m1 = (r2/r1)^2
  const long n_large = n / 2, n_small = n - n_large;
  const double area = M_PI * (n_small * m.radius[0] * m.radius[0] +
                              n_large * m.radius[1] * m.radius[1]);
  m.box_length = std::sqrt(area / phi);
  return m;
}

// Species of particle i: first half small (0), second half large (1).
inline int species_of(long i, long n) { return i < n - n / 2 ? 0 : 1; }
inline long small_count(long n) { return n - n / 2; }
// Species by particle id for particles 0 .. n_small-1 small, the rest large.
inline std::vector<std::uint8_t> species_by_rule(long n, long n_small) {
  std::vector<std::uint8_t> s(static_cast<size_t>(n), 1);
  std::fill(s.begin(), s.begin() + std::min(n, n_small), 0);
  return s;
}

// Henderson's contact value for hard disks, g(sigma) = (1 - 7phi/16)/(1-phi)^2.
inline double henderson_contact_value(double phi) {
  return (1.0 - 7.0 * phi / 16.0) / ((1.0 - phi) * (1.0 - phi));
}

// Paper, section 2: omega_coll = 2.59 phi G_c sqrt(1/pi).
inline double enskog_frequency(double phi, double contact_value) {
  return 2.59 * phi * contact_value * std::sqrt(1.0 / M_PI);
}

// Paper, section 2: p_Dr^2 = (1 - eps^2) m1 m2 / (m1 + m2).
inline double kick_amplitude(double eps, double m1, double m2) {
  return std::sqrt((1.0 - eps * eps) * m1 * m2 / (m1 + m2));
}

} // namespace dynhet
