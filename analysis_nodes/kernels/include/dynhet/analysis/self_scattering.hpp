#pragma once
// Self part of the intermediate scattering function and the non-Gaussian
// parameter from one (origin, lag) pair's squared displacements, for all
// particles or one species:
//   F_s(q, t)  = < exp(i q . dr_j) > averaged over the directions of q
//              = < J0(q |dr_j|) >                       (two dimensions),
//   alpha_2(t) = < dr^4 > / (2 < dr^2 >^2) - 1          (two dimensions:
//              zero for a Gaussian displacement distribution).
// d2: |dr_j|^2 per particle (unwrapped displacements, or cage-relative
// ones); species: 0 small, 1 large; which: -1 all, else that species.
#include <cstdint>
#include <vector>

namespace dynhet::analysis {

struct SelfScattering {
  std::vector<double> fs; // per q
  double msd = 0, m4 = 0, alpha2 = 0; // <dr^2>, <dr^4>, alpha_2
  long count = 0;
};

SelfScattering self_scattering(const double* d2, const std::uint8_t* species, long n, int which,
                               const std::vector<double>& q);

// All particles and the small ones (species 0) in one pass: each
// particle's J0 (glibc's j0, some 70-100 ns a call) counts for both.
struct SelfScatteringAllSmall {
  SelfScattering all, small;
};
SelfScatteringAllSmall self_scattering_all_small(const double* d2, const std::uint8_t* species, long n,
                                                 const std::vector<double>& q);

} // namespace dynhet::analysis
