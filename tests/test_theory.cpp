// The engine against liquid-state theory: the pressure and collision
// frequency of equilibrium hard disks (Henderson, Enskog) and of the
// bidisperse mixture (Santos, Yuste and Lopez de Haro).
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "dynhet/engine/engine.hpp"
#include "dynhet/model.hpp"
#include "engine_test_params.hpp"

using dynhet::engine::Engine;
using dynhet::engine::Params;

// ---------------------------------------------------------------- theory
//
// Elastic, undriven, monodisperse hard disks against liquid-state theory.
// Henderson's equation of state Z = (1 + phi^2/8)/(1 - phi)^2 agrees with
// simulations of hard disks to better than 0.5% up to phi = 0.5 (Henderson,
// Mol. Phys. 30, 971 (1975); Mulero et al., J. Chem. Phys. 111, 8468 (1999)).
// The collision frequency of an equilibrium hard-disk fluid is exactly
// omega = 2 n sigma g(sigma) sqrt(pi T / m) (Enskog's expression is exact in
// equilibrium, given the true contact value), and 2D virial theory gives
// g(sigma) = (Z - 1)/(2 phi); with Henderson's g = (1 - 7phi/16)/(1 - phi)^2
// it holds to the same 0.5%. Tolerance: 1% (theory) plus 3 standard errors
// from block averages (statistics).
namespace {

// The mean of block values and its standard error.
void mean_err(const std::vector<double>& v, double& mean, double& err) {
  mean = 0;
  for (double x : v) mean += x / v.size();
  double s2 = 0;
  for (double x : v) s2 += (x - mean) * (x - mean);
  err = std::sqrt(s2 / (v.size() - 1) / v.size());
}

struct Measured {
  double z, z_err, omega, omega_err;
};

Measured measure_monodisperse(double phi, long n, int blocks, double block_time) {
  Params p = params(n, phi, 1.0, false);
  p.radius_ratio = 1.0;
  Engine e(p);
  e.prepare();
  e.run_until(20.0); // equilibrate
  std::vector<double> z, om;
  for (int b = 0; b < blocks; ++b) {
    const auto c0 = e.counters();
    const double t0 = e.time();
    e.run_until(t0 + block_time);
    const auto c1 = e.counters();
    const double T = e.kinetic_energy_per_particle(); // conserved exactly
    z.push_back(dynhet::engine::reduced_pressure(c1.virial - c0.virial, block_time, n, T));
    om.push_back(2.0 * (c1.collisions - c0.collisions) / (n * block_time)); // per particle
  }
  Measured m{};
  mean_err(z, m.z, m.z_err);
  mean_err(om, m.omega, m.omega_err);
  return m;
}

double henderson_z(double phi) { return (1 + phi * phi / 8) / ((1 - phi) * (1 - phi)); }
double henderson_g(double phi) { return (1 - 7 * phi / 16) / ((1 - phi) * (1 - phi)); }
// r = 1 (sigma = 2), m = 1, T = 1: n = phi / pi.
double enskog_omega(double phi) { return 2 * (phi / M_PI) * 2.0 * henderson_g(phi) * std::sqrt(M_PI); }

} // namespace

TEST(Theory, PressureOfMonodisperseDisksFollowsHenderson) {
  for (double phi : {0.3, 0.5}) {
    const auto m = measure_monodisperse(phi, 2000, 10, 20.0);
    const double z = henderson_z(phi);
    std::printf("phi %.2f: Z = %.4f +- %.4f, Henderson %.4f (%.2f%%)\n", phi, m.z, m.z_err, z,
                100 * (m.z / z - 1));
    EXPECT_NEAR(m.z, z, 0.01 * z + 3 * m.z_err);
    EXPECT_LT(m.z_err, 0.005 * z); // the statistics can resolve the 1%
  }
}

TEST(Theory, CollisionFrequencyFollowsEnskog) {
  for (double phi : {0.1, 0.3}) {
    const auto m = measure_monodisperse(phi, 2000, 20, 40.0);
    const double w = enskog_omega(phi);
    std::printf("phi %.2f: omega = %.4f +- %.4f, Enskog-Henderson %.4f (%.2f%%)\n", phi, m.omega,
                m.omega_err, w, 100 * (m.omega / w - 1));
    EXPECT_NEAR(m.omega, w, 0.01 * w + 3 * m.omega_err);
    EXPECT_LT(m.omega_err, 0.005 * w);
  }
}

// Bidisperse (r2/r1 = 1.43, 50:50) against the mixture recipe of Santos,
// Yuste and Lopez de Haro (Mol. Phys. 96, 1 (1999)) for d = 2:
//   g_ij = 1/(1-phi) + [g_H(phi) - 1/(1-phi)] z_ij,  z_ij = (s_i s_j / s_ij) <s>/<s^2>,
// s the diameters, s_ij = (s_i + s_j)/2, g_H Henderson's monodisperse value;
//   Z = 1 + 2 phi sum_ij x_i x_j s_ij^2 g_ij / <s^2>.
// The recipe is good to about 1% for moderately dense disk mixtures (ibid.);
// tolerance 2% plus 3 standard errors.
TEST(Theory, BidispersePressureFollowsSantosYusteLopezDeHaro) {
  const double phi = 0.5, ratio = 1.43;
  Params p = params(2000, phi, 1.0, false);
  p.radius_ratio = ratio;
  Engine e(p);
  e.prepare();
  e.run_until(20.0);
  std::vector<double> z, om;
  for (int b = 0; b < 10; ++b) {
    const auto c0 = e.counters();
    const double t0 = e.time();
    e.run_until(t0 + 10.0);
    z.push_back(dynhet::engine::reduced_pressure(e.counters().virial - c0.virial, 10.0, e.size(),
                                                 e.kinetic_energy_per_particle()));
    om.push_back(2.0 * double(e.counters().collisions - c0.collisions) / (10.0 * e.size()));
  }
  double mean, err, om_mean, om_err;
  mean_err(z, mean, err);
  mean_err(om, om_mean, om_err);

  const double s[2] = {2.0, 2.0 * ratio}, x[2] = {0.5, 0.5};
  const double m1 = x[0] * s[0] + x[1] * s[1], m2 = x[0] * s[0] * s[0] + x[1] * s[1] * s[1];
  // The Enskog collision frequency of the mixture with the same g_ij, per
  // particle at T = 1: omega = sum_ij x_i x_j n s_ij g_ij 2 sqrt(pi T / (2 mu_ij)).
  const double mass[2] = {1.0, ratio * ratio}, n = e.size() / (e.box_length() * e.box_length());
  double sum = 0, omega = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const double sij = 0.5 * (s[i] + s[j]);
      const double zij = s[i] * s[j] / sij * m1 / m2;
      const double gij = 1 / (1 - phi) + (henderson_g(phi) - 1 / (1 - phi)) * zij;
      EXPECT_NEAR(dynhet::mixture_pair_contact_value(phi, ratio, i, j), gij, 1e-12 * gij); // model.hpp's recipe
      sum += x[i] * x[j] * sij * sij * gij;
      const double mu = mass[i] * mass[j] / (mass[i] + mass[j]);
      omega += x[i] * x[j] * n * sij * gij * 2 * std::sqrt(M_PI / (2 * mu));
    }
  const double z_syl = 1 + 2 * phi * sum / m2;
  std::printf("bidisperse phi %.2f: Z = %.4f +- %.4f, SYL %.4f (%.2f%%); omega = %.4f +- %.4f, Enskog-SYL %.4f "
              "(%.2f%%)\n",
              phi, mean, err, z_syl, 100 * (mean / z_syl - 1), om_mean, om_err, omega, 100 * (om_mean / omega - 1));
  EXPECT_NEAR(mean, z_syl, 0.02 * z_syl + 3 * err);
  // The collision frequency of an elastic fluid is the Enskog one with the
  // true contact values: the recipe's 1-2% again.
  EXPECT_NEAR(om_mean, omega, 0.02 * omega + 3 * om_err);
  // G_c of the kick rate is a weighted mean of the three g_ij.
  const double gc = dynhet::mixture_contact_value(phi, ratio);
  EXPECT_GT(gc, dynhet::mixture_pair_contact_value(phi, ratio, 0, 0));
  EXPECT_LT(gc, dynhet::mixture_pair_contact_value(phi, ratio, 1, 1));
  // A monodisperse "mixture" is Henderson's fluid.
  EXPECT_NEAR(dynhet::mixture_contact_value(phi, 1.0), henderson_g(phi), 1e-12);
}
