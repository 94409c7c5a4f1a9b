// F_s(q, t) and alpha_2 (dynhet/analysis/self_scattering.hpp): F_s equals
// the average of cos(q . dr) over explicit directions of q; for Gaussian
// displacements F_s = exp(-q^2 <dr^2> / 4) and alpha_2 = 0 within their
// sampling errors; a bimodal distribution has the alpha_2 computed by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "dynhet/analysis/self_scattering.hpp"

using namespace dynhet::analysis;

namespace {
constexpr double kPi = 3.14159265358979323846;
}

TEST(SelfScattering, EqualsTheAverageOverDirectionsOfQ) {
  std::mt19937_64 gen(4);
  std::normal_distribution<double> g(0, 0.8);
  const long n = 500;
  std::vector<double> dx(n), dy(n), d2(n);
  std::vector<std::uint8_t> sp(n);
  for (long j = 0; j < n; ++j) dx[j] = g(gen), dy[j] = 2 * g(gen), d2[j] = dx[j] * dx[j] + dy[j] * dy[j], sp[j] = j % 3 == 0;
  const std::vector<double> q{0.5, 2 * kPi / 1.0, 7.3};
  for (int which : {-1, 0, 1}) {
    const SelfScattering s = self_scattering(d2.data(), sp.data(), n, which, q);
    for (size_t k = 0; k < q.size(); ++k) {
      // 4096 directions: the trapezoid rule on a periodic integrand converges exponentially.
      double sum = 0;
      long count = 0;
      for (long j = 0; j < n; ++j) {
        if (which >= 0 && sp[j] != which) continue;
        ++count;
        for (int m = 0; m < 4096; ++m) {
          const double th = 2 * kPi * m / 4096;
          sum += std::cos(q[k] * (std::cos(th) * dx[j] + std::sin(th) * dy[j]));
        }
      }
      EXPECT_NEAR(s.fs[k], sum / (4096.0 * count), 1e-10) << "q " << q[k] << ", species " << which;
      EXPECT_EQ(s.count, count);
    }
  }
}

TEST(SelfScattering, GaussianDisplacementsAndABimodalAlpha2) {
  std::mt19937_64 gen(11);
  const double sd = 0.6; // per component
  std::normal_distribution<double> g(0, sd);
  const long n = 200000;
  std::vector<double> d2(n);
  const std::vector<std::uint8_t> sp(n, 0);
  for (long j = 0; j < n; ++j) {
    const double x = g(gen), y = g(gen);
    d2[j] = x * x + y * y;
  }
  const std::vector<double> q{1.0, 2.0};
  const SelfScattering s = self_scattering(d2.data(), sp.data(), n, -1, q);
  const double msd = 2 * sd * sd;
  EXPECT_NEAR(s.msd, msd, 5 * msd / std::sqrt(double(n)));
  for (size_t k = 0; k < q.size(); ++k)
    EXPECT_NEAR(s.fs[k], std::exp(-q[k] * q[k] * msd / 4), 5 / std::sqrt(double(n))); // |J0| <= 1: sd <= 1/sqrt(n)
  // r^2 is exponential in 2D: by the delta method the estimator's standard deviation is 1/sqrt(n).
  EXPECT_NEAR(s.alpha2, 0.0, 5 / std::sqrt(double(n)));
  // Half the particles at |dr| = 1, half at 3: <r^2> = 5, <r^4> = 41, alpha_2 = 41/50 - 1.
  std::vector<double> two(1000);
  for (int j = 0; j < 1000; ++j) two[j] = j % 2 ? 9.0 : 1.0;
  const std::vector<std::uint8_t> sp2(1000, 0);
  EXPECT_NEAR(self_scattering(two.data(), sp2.data(), 1000, -1, q).alpha2, 41.0 / 50 - 1, 1e-12);
  EXPECT_TRUE(std::isnan(self_scattering(two.data(), sp2.data(), 1000, 1, q).alpha2)); // no large particle
}
