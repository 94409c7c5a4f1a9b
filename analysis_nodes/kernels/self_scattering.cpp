// F_s(q, t) and alpha_2(t) (dynhet/analysis/self_scattering.hpp).
#include "dynhet/analysis/self_scattering.hpp"

#include <cmath>

namespace dynhet::analysis {

SelfScattering self_scattering(const double* d2, const std::uint8_t* species, long n, int which,
                               const std::vector<double>& q) {
  SelfScattering s;
  s.fs.assign(q.size(), 0.0);
  double sum2 = 0, sum4 = 0;
  for (long j = 0; j < n; ++j) {
    if (which >= 0 && species[j] != which) continue;
    const double r2 = d2[j], r = std::sqrt(r2);
    sum2 += r2, sum4 += r2 * r2, ++s.count;
    for (size_t k = 0; k < q.size(); ++k) s.fs[k] += std::cyl_bessel_j(0.0, q[k] * r);
  }
  if (s.count == 0) {
    s.fs.assign(q.size(), std::nan(""));
    s.msd = s.alpha2 = std::nan("");
    return s;
  }
  for (double& f : s.fs) f /= double(s.count);
  s.msd = sum2 / double(s.count);
  s.alpha2 = s.msd > 0 ? (sum4 / double(s.count)) / (2 * s.msd * s.msd) - 1 : std::nan("");
  return s;
}

} // namespace dynhet::analysis
