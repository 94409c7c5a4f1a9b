// F_s(q, t) and alpha_2(t) (dynhet/analysis/self_scattering.hpp).
#include "dynhet/analysis/self_scattering.hpp"

#include <cmath>

namespace dynhet::analysis {

namespace {

// Sums of J0(q r) per q, r^2 and r^4 over a set, into s; then the means.
struct Sums {
  std::vector<double> j;
  double r2 = 0, r4 = 0;
  long count = 0;
  explicit Sums(size_t nq) : j(nq, 0.0) {}
  SelfScattering result() const {
    SelfScattering s;
    s.count = count;
    if (count == 0) {
      s.fs.assign(j.size(), std::nan(""));
      s.msd = s.m4 = s.alpha2 = std::nan("");
      return s;
    }
    s.fs = j;
    for (double& f : s.fs) f /= double(count);
    s.msd = r2 / double(count), s.m4 = r4 / double(count);
    s.alpha2 = s.msd > 0 ? s.m4 / (2 * s.msd * s.msd) - 1 : std::nan("");
    return s;
  }
};

} // namespace

SelfScattering self_scattering(const double* d2, const std::uint8_t* species, long n, int which,
                               const std::vector<double>& q) {
  Sums s(q.size());
  for (long i = 0; i < n; ++i) {
    if (which >= 0 && species[i] != which) continue;
    const double r2 = d2[i], r = std::sqrt(r2);
    s.r2 += r2, s.r4 += r2 * r2, ++s.count;
    for (size_t k = 0; k < q.size(); ++k) s.j[k] += ::j0(q[k] * r);
  }
  return s.result();
}

SelfScatteringAllSmall self_scattering_all_small(const double* d2, const std::uint8_t* species, long n,
                                                 const std::vector<double>& q) {
  Sums all(q.size()), small(q.size());
  for (long i = 0; i < n; ++i) {
    const double r2 = d2[i], r4 = r2 * r2, r = std::sqrt(r2);
    const bool is_small = species[i] == 0;
    all.r2 += r2, all.r4 += r4, ++all.count;
    if (is_small) small.r2 += r2, small.r4 += r4, ++small.count;
    for (size_t k = 0; k < q.size(); ++k) {
      const double j = ::j0(q[k] * r);
      all.j[k] += j;
      if (is_small) small.j[k] += j;
    }
  }
  return {all.result(), small.result()};
}

} // namespace dynhet::analysis
