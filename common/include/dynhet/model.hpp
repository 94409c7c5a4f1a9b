// The paper's model in reduced units: r1 = 1, m1 = 1, m ~ r^2, 50:50.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace dynhet {

// The paper's mixture: the large radius over the small one (the scene's
// default system.radius_ratio, and the engine's Params).
inline constexpr double kPaperRadiusRatio = 1.43;

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

// Contact value g_ij(sigma_ij) of pair type (i, j) in a binary hard-disk
// mixture at packing fraction phi, diameters 2 and 2 r2/r1, mole fractions
// 1/2: Jenkins and Mancini, J. Appl. Mech. 54, 27 (1987), the d = 2 case of
// Santos, Yuste and Lopez de Haro, Mol. Phys. 96, 1 (1999) on Henderson's g:
//   g_ij = 1/(1-phi) + (9/16) phi/(1-phi)^2 z_ij,
//   z_ij = (s_i s_j / s_ij) <s>/<s^2>,  s_ij = (s_i + s_j)/2.
// A monodisperse fluid (r2/r1 = 1, z = 1) gets Henderson's value.
inline double mixture_pair_contact_value(double phi, double radius_ratio, int a, int b) {
  const double s[2] = {2.0, 2.0 * radius_ratio};
  const double m1 = 0.5 * (s[0] + s[1]), m2 = 0.5 * (s[0] * s[0] + s[1] * s[1]);
  const double sab = 0.5 * (s[a] + s[b]);
  const double z = s[a] * s[b] / sab * m1 / m2;
  return 1.0 / (1.0 - phi) + 9.0 / 16.0 * phi / ((1.0 - phi) * (1.0 - phi)) * z;
}

// The one G_c of the mixture that the paper's omega_coll needs: the g_ij
// averaged with the weights of the pair types in the Enskog collision
// rate, x_i x_j s_ij sqrt(1/mu_ij) (mu_ij the reduced mass), so that
// omega_coll grows with phi as the mixture's Enskog frequency does.
inline double mixture_contact_value(double phi, double radius_ratio) {
  const double s[2] = {2.0, 2.0 * radius_ratio}, m[2] = {1.0, radius_ratio * radius_ratio};
  double num = 0, den = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      const double w = 0.25 * 0.5 * (s[a] + s[b]) * std::sqrt((m[a] + m[b]) / (m[a] * m[b]));
      num += w * mixture_pair_contact_value(phi, radius_ratio, a, b);
      den += w;
    }
  return num / den;
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
